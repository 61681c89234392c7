// Pull-out from every road_shoulder lanelet of Autoware's start-planner test map
// (../shared/maps/autoware_road_shoulder, beside the checkout): per planner (each alone, from the
// current pose, as Autoware's planner tests run them) how many of the 95 shoulders pass at the three
// start yaws (along the lane, +-10 degrees), and the planning time per request; beside it, in the
// same run, the default search (shift then geometric, with the backward search) as the baseline.
// A pass is a found path of 1 segment (shift) or 2 (geometric, divided); the path properties are
// checked by tests/planners/test_autoware_shoulder_map.cpp.
//
//   build/bench/bench_shoulder_map [--rounds 3]
//
// Results in bench/RESULTS.md.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "map_cases.hpp"
#include "percentiles.hpp"
#include "pullout/config/config.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace {

using pullout::PlannerType;

const std::string kMap = std::string(PULLOUT_SOURCE_DIR) + "/../shared/maps/autoware_road_shoulder/lanelet2_map.osm";

std::string load_average() {
  double load[3];
  if (::getloadavg(load, 3) != 3) return "?";
  char text[64];
  std::snprintf(text, sizeof text, "%.2f %.2f %.2f", load[0], load[1], load[2]);
  return text;
}

struct Row {
  std::string name;
  std::vector<PlannerType> priority;
  bool alone{true};                  // current pose only, no freespace; else the shipped configuration
  std::size_t expected_segments{0};  // 0: any
  std::size_t lanelets_passed{0};
  std::size_t cases_passed{0};
  std::size_t cases{0};
  std::vector<double> times_ms;
};

}  // namespace

int main(int argc, char** argv) {
  int rounds = 3;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--rounds") rounds = std::max(1, std::atoi(argv[i + 1]));
  }
  if (!std::filesystem::exists(kMap)) {
    std::cerr << "bench_shoulder_map: absent: " << kMap << "\n";
    return 1;
  }
  const auto map = pullout::load_lanelet_map(kMap);
  const pullout::Config config = pullout::load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  std::vector<pullout::ShoulderCase> cases;
  for (const pullout::Lanelet& ll : map->lanelets()) {
    if (ll.subtype != pullout::LaneletSubtype::kRoadShoulder) continue;
    if (auto c = pullout::shoulder_case(*map, ll)) cases.push_back(*c);
  }
  std::vector<Row> rows{{"shift alone", {PlannerType::kShift}, true, 1},
                        {"geometric alone", {PlannerType::kGeometric}, true, 2},
                        {"default search (baseline)", {PlannerType::kShift, PlannerType::kGeometric}, false, 0}};
  const double yaws[] = {0.0, 10.0 * pullout::kDegToRad, -10.0 * pullout::kDegToRad};
  for (Row& row : rows) {
    pullout::StartPlannerParameters params = config.start_planner;
    params.search_priority = row.priority;
    if (row.alone) {
      params.enable_back = false;
      params.freespace_planner.enable_freespace_planner = false;
    }
    params.divide_pull_out_path = true;
    const pullout::StartPlanner planner(config.vehicle, params, config.service.limits, map);
    for (const auto& c : cases) {
      bool all = true;
      for (double yaw : yaws) {
        pullout::PullOutRequest r;
        r.vehicle_id = "bench";
        r.request_id = 1;
        r.route_lanelet_ids = c.route;
        r.ego_pose = c.ego;
        r.ego_pose.yaw = pullout::normalize_angle(c.ego.yaw + yaw);
        r.goal_pose = c.goal;
        bool ok = false;
        for (int k = 0; k < rounds; ++k) {
          const auto t0 = std::chrono::steady_clock::now();
          const pullout::PlanningResult result = planner.plan(r, pullout::StopCondition());
          row.times_ms.push_back(
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
          ok = result.outcome == pullout::PlanningResult::Outcome::kFound &&
               (row.expected_segments == 0 || result.path.partial_paths.size() == row.expected_segments);
        }
        ++row.cases;
        if (ok) ++row.cases_passed;
        all = all && ok;
      }
      if (all) ++row.lanelets_passed;
    }
  }
  std::printf("autoware_road_shoulder: %zu shoulder lanelets x 3 start yaws, %d rounds; load average %s\n",
              cases.size(), rounds, load_average().c_str());
  std::printf("| search | shoulders passing (all 3 yaws) | cases passing | plan p50 [ms] | p95 [ms] | max [ms] |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (Row& row : rows) {
    const pullout::bench::Summary t = pullout::bench::summarize(row.times_ms);
    std::printf("| %s | %zu / %zu | %zu / %zu | %.2f | %.2f | %.2f |\n", row.name.c_str(), row.lanelets_passed,
                cases.size(), row.cases_passed, row.cases, t.p50, t.p95, t.max);
  }
  return 0;
}
