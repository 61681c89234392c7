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

void plan_scenario(benchmark::State& state, const std::string& name) {
  const pullout::Scenario scenario = load(name);
  const pullout::StartPlanner planner(scenario.vehicle, scenario.parameters);
  std::size_t attempts = 0;
  for (auto _ : state) {
    const pullout::PlanningResult r = planner.plan(scenario.request, pullout::Deadline());
    attempts = r.evaluation_table.size();
    benchmark::DoNotOptimize(r.path.partial_paths.data());
  }
  state.counters["attempts"] = static_cast<double>(attempts);
}

// Nothing in the way: the first (gentlest) candidate at the first margin wins.
void BM_Plan_StraightShoulder(benchmark::State& state) { plan_scenario(state, "straight_shoulder"); }
// Straight shoulder with every margin of the ladder run: 4 margins x 4 shift candidates, the
// last one succeeding (the car parked ahead only clears at 0.1 m).
void BM_Plan_StraightShoulder_AllMargins(benchmark::State& state) { plan_scenario(state, "parked_car_ahead"); }
// Everything fails: 4 margins x 4 candidates, then the stop path.
void BM_Plan_BoxedIn(benchmark::State& state) { plan_scenario(state, "boxed_in"); }
void BM_Plan_CurvedRoad(benchmark::State& state) { plan_scenario(state, "curved_road"); }

BENCHMARK(BM_Plan_StraightShoulder)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_StraightShoulder_AllMargins)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_BoxedIn)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Plan_CurvedRoad)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
