// Generated families of parallel parking spots (issue 12): the vehicle 0.15-0.5 m from the kerb
// between two parked cars with a total slack of 3.0 down to 0.8 m (split evenly ahead and
// behind); one road lane (a one-way street) or two (an opposite lane beyond); right-hand traffic
// (parking lane on the right) and left-hand (on the left); a straight street and streets curving
// left with centerline radius 30, 100 and 200 m (the parking lane on the outside of the bend for
// right-hand traffic, on the inside for left-hand). Per family and per planner: spots solved,
// direction changes of the paths, planning time p50 / p95. Every path found is checked by the
// independent oracles (tests/planners/path_oracles.hpp): the bare body inside the raw lane
// polygons and clear of both cars at poses every 5 cm, velocity 0 at each change of direction, one
// pair per partial path; a path that fails them counts as not solved (and is reported). The
// spots come from tests/planners/street_spots.hpp (shared with the shunting tests): "kerb" and
// "slack" are the body's closest distances to the kerb and to the two cars, also on a bend.
//
//   build/bench/bench_street_spots
//
// Planners: shift alone, geometric alone (each with the backward search, freespace off) and the
// shipped search (shift, geometric, freespace fallback; freespace_planner.time_limit 1000 ms to
// bound the run). collision_check_margin_from_front_object is 0 for all (Autoware's 5 m skips
// every backward candidate in a parallel spot). Results in bench/RESULTS.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "path_oracles.hpp"
#include "percentiles.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "street_spots.hpp"

namespace {

using namespace pullout;  // NOLINT: a benchmark's main file

using street::Spot;
using street::Street;

// Empty when the path passes the oracles.
std::string check(const PullOutPath& path, const Street& st, const VehicleInfo& v) {
  if (path.pairs_terminal_velocity_and_accel.size() != path.partial_paths.size()) return "pairs";
  const Footprint body = vehicle_footprint(v);
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    const auto& seg = path.partial_paths[k];
    if (seg.points.size() < 2) return "short segment";
    const double dir = oracle::direction_of(seg);
    if (k + 1 < path.partial_paths.size() && oracle::direction_of(path.partial_paths[k + 1]) != dir &&
        seg.points.back().longitudinal_velocity_mps != 0.0) {
      return "no stop at a direction change";
    }
    bool beyond_end = false;
    for (const Pose2& q : oracle::poses_along(seg, 0.05)) {
      if (!beyond_end && !oracle::footprint_in_lanes(body, q, st.lanes)) return "leaves the lanes";
      for (const Polygon& c : st.cars) {
        if (oracle::polygons_overlap(oracle::rectangle_at(body, q), c)) return "touches a car";
      }
      // Beyond the end pose the path is the road centerline (checked up to there).
      if (k + 1 == path.partial_paths.size() && std::hypot(q.x - path.end_pose.x, q.y - path.end_pose.y) < 0.05) {
        beyond_end = true;
      }
    }
  }
  return "";
}

struct Tally {
  int solved{0};
  int total{0};
  int cusps{0};  // changes of direction (forward <-> reverse) of the paths found
  int stops{0};  // stops between partial paths (direction changes and stops to re-steer)
  int max_cusps{0};
  std::vector<double> ms;
  std::map<std::string, int> by_planner;  // paths found per planner type
};

// This thread's CPU time [ms]: less disturbed by a loaded machine than the wall clock.
double thread_cpu_ms() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

int direction_changes(const PullOutPath& path) {
  int n = 0;
  for (std::size_t k = 0; k + 1 < path.partial_paths.size(); ++k) {
    if (oracle::direction_of(path.partial_paths[k]) != oracle::direction_of(path.partial_paths[k + 1])) ++n;
  }
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  // --why: the evaluation table's last row of every spot the shunting planner leaves unsolved.
  // --shunts: as --why, with the shunting planner alone (a quick run while working on it).
  const bool shunts_only = argc > 1 && std::string(argv[1]) == "--shunts";
  // PULLOUT_BENCH_CPU=1: the tables' times are this thread's CPU time, not wall-clock time (on a
  // machine loaded by other work).
  const bool cpu_times = std::getenv("PULLOUT_BENCH_CPU") != nullptr;
  const bool why = shunts_only || (argc > 1 && std::string(argv[1]) == "--why");
  // --spots: one line per spot for the shipped search (time, thread CPU time, outcome, its
  // evaluation table's freespace rows).
  // --one right|left LANES RADIUS KERB SLACK: that spot alone, shipped search, with --spots' line.
  const bool one = argc == 7 && std::string(argv[1]) == "--one";
  const bool spots = one || (argc > 1 && std::string(argv[1]) == "--spots");
  const VehicleInfo v;
  struct Planner {
    const char* name;
    StartPlannerParameters params;
  };
  std::vector<Planner> planners;
  for (int k = 0; k < 4; ++k) {
    StartPlannerParameters p;
    p.collision_check_margin_from_front_object = 0.0;
    p.freespace_planner.time_limit = 1000.0;
    // PULLOUT_BENCH_FS_MS=N: the freespace budget N ms instead (does the fallback find a path with
    // more time?).
    if (const char* ms = std::getenv("PULLOUT_BENCH_FS_MS")) p.freespace_planner.time_limit = std::atof(ms);
    if (k == 0) p.search_priority = {PlannerType::kShift};
    if (k == 1 || k == 2) p.search_priority = {PlannerType::kGeometric};
    if (k == 1) p.geometric_pull_out_max_shunts = 0;
    if (k < 3) p.freespace_planner.enable_freespace_planner = false;
    planners.push_back({k == 0   ? "shift"
                        : k == 1 ? "geometric S only"
                        : k == 2 ? "geometric with shunts"
                                 : "default search",
                        p});
  }
  std::map<std::string, std::map<std::string, Tally>> by_family;  // family -> planner -> tally
  std::map<std::string, std::map<double, Tally>> by_slack;        // planner -> slack -> tally
  std::vector<std::string> oracle_failures;
  for (bool right_hand : {true, false}) {
    for (int road_lanes : {1, 2}) {
      for (double radius : {0.0, 30.0, 100.0, 200.0}) {
        const std::string family = std::string(right_hand ? "right-hand" : "left-hand") + ", " +
                                   std::to_string(road_lanes) + " lane" + (road_lanes > 1 ? "s" : "") + ", " +
                                   (radius > 0 ? "R " + std::to_string(static_cast<int>(radius)) + " m" : "straight");
        for (double kerb : {0.15, 0.3, 0.5}) {
          for (double slack : {3.0, 2.0, 1.5, 1.0, 0.8}) {
            if (one && (right_hand != (std::string(argv[2]) == "right") || road_lanes != std::atoi(argv[3]) ||
                        std::abs(radius - std::atof(argv[4])) > 1e-9 || std::abs(kerb - std::atof(argv[5])) > 1e-9 ||
                        std::abs(slack - std::atof(argv[6])) > 1e-9)) {
              continue;
            }
            const Spot sp{right_hand, road_lanes, kerb, slack, radius};
            const Street st = street::make_street(sp, v);
            for (const Planner& pl : planners) {
              if (spots && std::string(pl.name) != "default search") continue;
              if (shunts_only && std::string(pl.name) != "geometric with shunts") continue;
              const StartPlanner planner(v, pl.params);
              const double cpu0 = thread_cpu_ms();
              const auto t0 = std::chrono::steady_clock::now();
              const PlanningResult r = planner.plan(st.request, StopCondition());
              const double ms =
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
              const double cpu = thread_cpu_ms() - cpu0;
              bool ok = r.outcome == PlanningResult::Outcome::kFound;
              if (ok) {
                const std::string why = check(r.path, st, v);
                if (!why.empty()) {
                  ok = false;
                  oracle_failures.push_back(std::string(pl.name) + " " + family + " kerb " + std::to_string(kerb) +
                                            " slack " + std::to_string(slack) + ": " + why);
                }
              }
              if (spots && std::string(pl.name) == "default search") {
                std::string rows;
                for (const auto& row : r.evaluation_table) {
                  if (row.planner == PlannerType::kFreespace) rows += " | " + describe(row);
                }
                std::printf("spot: %s kerb %.2f slack %.1f: %s %s %.1f ms (cpu %.1f ms)%s\n", family.c_str(), kerb,
                            slack, ok ? "solved" : "unsolved", ok ? to_string(r.path.planner_type) : "-", ms, cpu,
                            rows.c_str());
                // --one: the path's partial paths (direction, length, heading from and to, start).
                for (std::size_t k = 0; one && ok && k < r.path.partial_paths.size(); ++k) {
                  const auto& pts = r.path.partial_paths[k].points;
                  double len = 0.0;
                  for (std::size_t i = 1; i < pts.size(); ++i) {
                    len += std::hypot(pts[i].pose.x - pts[i - 1].pose.x, pts[i].pose.y - pts[i - 1].pose.y);
                  }
                  std::printf("  partial path %zu: %s %.2f m, yaw %.1f -> %.1f deg, from (%.2f, %.2f)\n", k,
                              oracle::direction_of(r.path.partial_paths[k]) > 0.0 ? "forward" : "reverse", len,
                              pts.front().pose.yaw * 180.0 / M_PI, pts.back().pose.yaw * 180.0 / M_PI,
                              pts.front().pose.x, pts.front().pose.y);
                }
              }
              if (why && !ok && std::string(pl.name) == "geometric with shunts" && !r.evaluation_table.empty()) {
                std::printf("unsolved: %s kerb %.2f slack %.1f: %s\n", family.c_str(), kerb, slack,
                            describe(r.evaluation_table.back()).c_str());
              }
              for (Tally* t : {&by_family[family][pl.name], &by_slack[pl.name][slack]}) {
                ++t->total;
                t->ms.push_back(cpu_times ? cpu : ms);
                if (ok) {
                  ++t->solved;
                  t->cusps += direction_changes(r.path);
                  t->max_cusps = std::max(t->max_cusps, direction_changes(r.path));
                  t->stops += static_cast<int>(r.path.partial_paths.size()) - 1;
                  const bool shunted = r.path.planner_type == PlannerType::kGeometric && !r.evaluation_table.empty() &&
                                       r.evaluation_table.back().detail == "shunting";
                  ++t->by_planner[std::string(to_string(r.path.planner_type)) + (shunted ? " (shunts)" : "")];
                }
              }
            }
          }
        }
      }
    }
  }
  double load[3] = {0, 0, 0};
  if (::getloadavg(load, 3) != 3) load[0] = -1;
  std::printf("load average %.2f %.2f %.2f; times: %s\n\n", load[0], load[1], load[2],
              cpu_times ? "thread CPU" : "wall clock");
  const auto mean = [](int sum, int n) { return n ? static_cast<double>(sum) / n : 0.0; };
  const auto found_by = [](const Tally& t) {
    std::string out;
    for (const auto& [name, n] : t.by_planner) out += (out.empty() ? "" : ", ") + name + " " + std::to_string(n);
    return out;
  };
  std::printf(
      "| family | planner | solved | mean direction changes | mean stops | p50 [ms] | p95 [ms] | found by |\n"
      "|---|---|---|---|---|---|---|---|\n");
  for (auto& [family, rows] : by_family) {
    for (const Planner& pl : planners) {
      Tally& t = rows[pl.name];
      const auto s = pullout::bench::summarize(t.ms);
      std::printf("| %s | %s | %d/%d | %.2f | %.2f | %.2f | %.2f | %s |\n", family.c_str(), pl.name, t.solved, t.total,
                  mean(t.cusps, t.solved), mean(t.stops, t.solved), s.p50, s.p95, found_by(t).c_str());
    }
  }
  std::printf(
      "\n| planner | slack [m] | solved | mean direction changes | max direction changes | p50 [ms] | p95 [ms] | "
      "found by |\n|---|---|---|---|---|---|---|---|\n");
  for (const Planner& pl : planners) {
    for (auto& [slack, t] : by_slack[pl.name]) {
      const auto s = pullout::bench::summarize(t.ms);
      std::printf("| %s | %.1f | %d/%d | %.2f | %d | %.2f | %.2f | %s |\n", pl.name, slack, t.solved, t.total,
                  mean(t.cusps, t.solved), t.max_cusps, s.p50, s.p95, found_by(t).c_str());
    }
  }
  std::printf("\n| planner | spots | solved | p50 [ms] | p95 [ms] |\n|---|---|---|---|---|\n");
  for (const Planner& pl : planners) {
    for (double from : {0.8, 1.0}) {
      std::vector<double> ms;
      int solved = 0;
      int total = 0;
      for (auto& [slack, t] : by_slack[pl.name]) {
        if (slack < from - 1e-9) continue;
        ms.insert(ms.end(), t.ms.begin(), t.ms.end());
        solved += t.solved;
        total += t.total;
      }
      const auto s = pullout::bench::summarize(ms);
      std::printf("| %s | slack >= %.1f m | %d/%d | %.2f | %.2f |\n", pl.name, from, solved, total, s.p50, s.p95);
    }
  }
  std::printf("\noracle failures: %zu\n", oracle_failures.size());
  for (const auto& f : oracle_failures) std::printf("  %s\n", f.c_str());
  return 0;
}
