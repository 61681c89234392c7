// In-process planning benchmarks: the full search of StartPlanner::plan on the bundled scenarios
// (validation, world building, every planner x margin attempt, path output).
//
//   build/bench/bench_planning --benchmark_repetitions=20 --benchmark_report_aggregates_only=true
//
// Results are recorded in bench/RESULTS.md.
#include <benchmark/benchmark.h>

#include <string>

#include "pullout/config/scenario.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace {

pullout::Scenario load(const std::string& name) {
  return pullout::load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + name + ".yaml");
}

// deadline_ms < 0: no deadline.
void plan_scenario(benchmark::State& state, const std::string& name, double deadline_ms = -1.0) {
  const pullout::Scenario scenario = load(name);
  const pullout::StartPlanner planner(scenario.vehicle, scenario.parameters);
  std::size_t attempts = 0;
  for (auto _ : state) {
    const pullout::PlanningResult r = planner.plan(
        scenario.request, deadline_ms < 0.0 ? pullout::StopCondition() : pullout::StopCondition::after_ms(deadline_ms));
    attempts = r.evaluation_table.size();
    benchmark::DoNotOptimize(r.path.partial_paths.data());
  }
  state.counters["attempts"] = static_cast<double>(attempts);
}

// Nothing in the way: the first (gentlest) candidate at the first margin wins.
void BM_Plan_StraightShoulder(benchmark::State& state) { plan_scenario(state, "straight_shoulder"); }
// Straight shoulder with every margin of the ladder run (shift only, no reversing): 4 margins x
// 4 shift candidates, the last one succeeding (the car parked ahead only clears at 0.1 m).
void BM_Plan_StraightShoulder_AllMargins(benchmark::State& state) { plan_scenario(state, "parked_car_ahead"); }
// Boxed in: no start candidate survives the backward search, stop path.
void BM_Plan_BoxedIn(benchmark::State& state) { plan_scenario(state, "boxed_in"); }
void BM_Plan_CurvedRoad(benchmark::State& state) { plan_scenario(state, "curved_road"); }
// The worst case of the lane-based search: 4 margins x 11 start candidates x {shift, geometric,
// clothoid}, every attempt failing (132 evaluation rows).
void BM_Plan_FullSearch(benchmark::State& state) { plan_scenario(state, "full_search"); }
void BM_Plan_ParallelSpot(benchmark::State& state) { plan_scenario(state, "parallel_spot"); }
void BM_Plan_PerpendicularBay(benchmark::State& state) { plan_scenario(state, "perpendicular_bay"); }
void BM_Plan_CarCloseAhead(benchmark::State& state) { plan_scenario(state, "car_close_ahead"); }
// One road lane, no opposite lane: geometric from the spot (shift fails first at every margin).
void BM_Plan_SingleLaneStreet(benchmark::State& state) { plan_scenario(state, "single_lane_street"); }
// The same in left-hand traffic, 0.3 m from the kerb: reverse to just clear of the car behind first.
void BM_Plan_SingleLaneStreetLeftHand(benchmark::State& state) { plan_scenario(state, "single_lane_street_left_hand"); }
// The freespace fallback, whole pipeline: the lane-based search fails, then the costmap is built
// from the lanes and objects, end poses are searched on the lane ahead, and hybrid A* runs.
void BM_Plan_FreespaceBoxedIn(benchmark::State& state) { plan_scenario(state, "freespace_boxed_in"); }
void BM_Plan_FreespacePerpendicularBay(benchmark::State& state) { plan_scenario(state, "freespace_perpendicular_bay"); }
// How promptly a search stops at its deadline: 1 ms for the freespace bay (costmap set-up plus the
// search's check interval on top of it; the unit test only checks that it times out).
void BM_Plan_FreespaceTinyDeadline(benchmark::State& state) {
  plan_scenario(state, "freespace_perpendicular_bay", 1.0);
}
// A pure freespace problem: a grid and a goal pose, no lanes.
void BM_Plan_FreespaceParkingLot(benchmark::State& state) { plan_scenario(state, "freespace_parking_lot"); }

BENCHMARK(BM_Plan_StraightShoulder)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_StraightShoulder_AllMargins)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_BoxedIn)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_CurvedRoad)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_FullSearch)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_ParallelSpot)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_PerpendicularBay)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_CarCloseAhead)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_SingleLaneStreet)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_SingleLaneStreetLeftHand)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_FreespaceBoxedIn)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_FreespacePerpendicularBay)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_FreespaceTinyDeadline)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_FreespaceParkingLot)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
