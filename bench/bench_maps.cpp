// Lanelet2 map benchmarks: loading Autoware's 740 KB intersection map (../shared/maps, beside the
// checkout; the benchmarks needing it report an error when it is absent), the spatial queries
// around a pose, and planning a route request on the project's own map.
//
//   build/bench/bench_maps --benchmark_repetitions=20 --benchmark_report_aggregates_only=true
//
// Targets: loading < 100 ms, lanelets around a pose < 10 us. Results in bench/RESULTS.md.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "pullout/config/scenario.hpp"
#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace {

const std::string kIntersection =
    std::string(PULLOUT_SOURCE_DIR) + "/../shared/maps/autoware_intersection/lanelet2_map.osm";

bool have_intersection(benchmark::State& state) {
  if (std::filesystem::exists(kIntersection)) return true;
  state.SkipWithError(("absent: " + kIntersection).c_str());
  return false;
}

// Query points: the middle of every lanelet's left bound, nudged inwards, so that each query has
// lanelets around it (as a vehicle on the map has).
std::vector<pullout::Point2> query_points(const pullout::LaneletMap& map) {
  std::vector<pullout::Point2> points;
  for (const pullout::Lanelet& ll : map.lanelets()) {
    const auto& l = ll.left.points[ll.left.points.size() / 2];
    const auto& r = ll.right.points[ll.right.points.size() / 2];
    points.push_back({0.7 * l.x + 0.3 * r.x, 0.7 * l.y + 0.3 * r.y});
  }
  return points;
}

void BM_LoadIntersectionMap(benchmark::State& state) {
  if (!have_intersection(state)) return;
  std::size_t lanelets = 0;
  for (auto _ : state) {
    const auto map = pullout::load_lanelet_map(kIntersection);
    lanelets = map->lanelets().size();
    benchmark::DoNotOptimize(map.get());
  }
  state.counters["lanelets"] = static_cast<double>(lanelets);
  state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(kIntersection));
}

// Time per query, cycling over the query points.
template <typename Query>
void query_bench(benchmark::State& state, Query query) {
  if (!have_intersection(state)) return;
  const auto map = pullout::load_lanelet_map(kIntersection);
  const std::vector<pullout::Point2> points = query_points(*map);
  std::size_t i = 0;
  std::size_t found = 0;
  for (auto _ : state) {
    const std::vector<std::size_t> result = query(*map, points[i]);
    found += result.size();
    benchmark::DoNotOptimize(result.data());
    i = (i + 1) % points.size();
  }
  state.counters["lanelets_per_query"] =
      benchmark::Counter(static_cast<double>(found), benchmark::Counter::kAvgIterations);
}

void BM_LaneletsContaining(benchmark::State& state) {
  query_bench(state, [](const pullout::LaneletMap& m, const pullout::Point2& p) { return m.lanelets_containing(p); });
}
// The lanelets within the vehicle's half width (what a request's start check asks) and within
// 10 m (a wider neighbourhood).
void BM_LaneletsNear(benchmark::State& state) {
  const double radius = static_cast<double>(state.range(0)) / 100.0;
  query_bench(state,
              [radius](const pullout::LaneletMap& m, const pullout::Point2& p) { return m.lanelets_near(p, radius); });
}

// A whole route request on the own map (lane selection, world, search): compare with
// bench_planning's BM_Plan_* on inline lanes.
void BM_PlanRouteOnMap(benchmark::State& state) {
  const pullout::Scenario sc =
      pullout::load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/map_shoulder.yaml");
  const pullout::StartPlanner planner(sc.vehicle, sc.parameters, {}, sc.map);
  for (auto _ : state) {
    const pullout::PlanningResult r = planner.plan(sc.request, pullout::StopCondition());
    benchmark::DoNotOptimize(r.path.partial_paths.data());
  }
}

BENCHMARK(BM_LoadIntersectionMap)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LaneletsContaining)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LaneletsNear)->Arg(96)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PlanRouteOnMap)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
