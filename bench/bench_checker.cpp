// GridCollisionChecker micro-benchmarks: per-call cost of collides() and clearance_lower_bound()
// on random poses in generated parking lots (walls around, rows of bays, parked cars).
//
//   build/bench/bench_checker --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Poses are drawn once per lot from a fixed seed and classified with the costmap's distance
// transform only (not with the checker under test, so the sets stay the same when the checker
// changes):
//  - "near": an occupied cell centre lies inside the footprint's circumscribed disc (but not
//    deeper than 1.5 m), so the clearance bound is mostly 0 and collides() runs its exact test;
//  - "open": the circumscribed disc is clear by more than 0.6 m: the bound answers alone.
// Results are recorded in bench/RESULTS.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "lot_shapes.hpp"
#include "pullout/freespace/costmap.hpp"
#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace {

using pullout::Pose2;

using pullout::kPi;

using pullout::bench::box;

// The obstacles of a square lot `size` m across: 0.4 m walls, rows of 2.7 m x 5.5 m bays (double
// rows between 7 m aisles), 70 % of the bays holding a 4.6 m x 1.9 m car (as bench_freespace's lots).
std::vector<pullout::Polygon> lot_obstacles(double size, std::mt19937& rng) {
  constexpr double kWall = 0.4, kBayW = 2.7, kBayD = 5.5, kAisle = 7.0;
  std::vector<pullout::Polygon> obstacles{
      box(size / 2, kWall / 2, 0, size, kWall), box(size / 2, size - kWall / 2, 0, size, kWall),
      box(kWall / 2, size / 2, 0, kWall, size), box(size - kWall / 2, (size - 8.0) / 2, 0, kWall, size - 8.0)};
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double y = kWall;
  bool single = true;
  while (true) {
    const double depth = single ? kBayD : 2 * kBayD;
    if (y + depth + kAisle > size - kWall) break;
    for (double x = 7.0; x + kBayW <= size - 7.0; x += kBayW) {
      for (int side = 0; side < (single ? 1 : 2); ++side) {
        if (u(rng) >= 0.7) continue;
        const double cy = y + (side + 0.5) * kBayD;
        obstacles.push_back(box(x + kBayW / 2 + (u(rng) - 0.5) * 0.3, cy, kPi / 2 + (u(rng) - 0.5) * 0.1, 4.6, 1.9));
      }
    }
    y += depth + kAisle;
    single = false;
  }
  return obstacles;
}

// An empty costmap of the lot's size.
pullout::Costmap empty_lot(double size, double resolution) {
  const int cells = static_cast<int>(std::round(size / resolution));
  return {{0, 0, 0}, resolution, cells, cells, std::vector<std::uint8_t>(static_cast<std::size_t>(cells) * cells, 0)};
}

pullout::Costmap parking_lot(double size, double resolution, std::mt19937& rng) {
  pullout::Costmap map = empty_lot(size, resolution);
  map.add_obstacles(lot_obstacles(size, rng));
  return map;
}

struct Lot {
  pullout::Costmap costmap;
  pullout::Footprint footprint;
  std::unique_ptr<pullout::GridCollisionChecker> checker;
  std::vector<Pose2> near;
  std::vector<Pose2> open;
};

// One lot per (size, resolution), built on first use.
const Lot& lot(int size_m, int resolution_cm) {
  static std::map<std::pair<int, int>, std::unique_ptr<Lot>> lots;
  auto& slot = lots[{size_m, resolution_cm}];
  if (slot) return *slot;
  slot = std::make_unique<Lot>();
  Lot& l = *slot;
  std::mt19937 rng(static_cast<unsigned>(size_m * 100 + resolution_cm));
  l.costmap = parking_lot(size_m, resolution_cm * 0.01, rng);
  l.footprint = pullout::vehicle_footprint(pullout::VehicleInfo{}, 0.1);
  l.checker = std::make_unique<pullout::GridCollisionChecker>(l.costmap, l.footprint);
  const pullout::Footprint& f = l.footprint;
  const double half_diag = 0.5 * std::hypot(f.length(), f.width());
  std::uniform_real_distribution<double> x(1.0, size_m - 1.0), yaw(-kPi, kPi);
  constexpr std::size_t kPoses = 4096;
  while (l.near.size() < kPoses || l.open.size() < kPoses) {
    const Pose2 pose{x(rng), x(rng), yaw(rng)};
    // Clearance of the footprint's circumscribed disc (centred at the rectangle's centre).
    const double cx = 0.5 * (f.front - f.rear), cy = 0.5 * (f.left - f.right);
    const pullout::Vec2 centre{pose.x + std::cos(pose.yaw) * cx - std::sin(pose.yaw) * cy,
                               pose.y + std::sin(pose.yaw) * cx + std::cos(pose.yaw) * cy};
    int i = 0, j = 0;
    l.costmap.cell_of(centre, i, j);
    if (!l.costmap.inside(i, j)) continue;
    const double d = l.costmap.occupied(i, j) ? 0.0 : l.costmap.centre_distance(i, j);
    if (d < half_diag && d > half_diag - 1.5 && l.near.size() < kPoses) l.near.push_back(pose);
    if (d > half_diag + 0.6 && l.open.size() < kPoses) l.open.push_back(pose);
  }
  return l;
}

void BM_Collides(benchmark::State& state, bool near) {
  const Lot& l = lot(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const std::vector<Pose2>& poses = near ? l.near : l.open;
  std::size_t k = 0, hits = 0;
  for (auto _ : state) {
    const bool c = l.checker->collides(poses[k]);
    hits += c ? 1 : 0;
    benchmark::DoNotOptimize(c);
    k = (k + 1) & (poses.size() - 1);
  }
  state.counters["colliding"] = static_cast<double>(hits) / static_cast<double>(state.iterations());
}

void BM_ClearanceBound(benchmark::State& state, bool near) {
  const Lot& l = lot(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const std::vector<Pose2>& poses = near ? l.near : l.open;
  std::size_t k = 0, positive = 0;
  for (auto _ : state) {
    const double b = l.checker->clearance_lower_bound(poses[k]);
    positive += b > 0.0 ? 1 : 0;
    benchmark::DoNotOptimize(b);
    k = (k + 1) & (poses.size() - 1);
  }
  state.counters["positive"] = static_cast<double>(positive) / static_cast<double>(state.iterations());
}

// The costmap's precomputation (distance transform, summed-area table) for one lot: the price
// paid once per planning request.
void BM_CostmapBuild(benchmark::State& state) {
  const Lot& l = lot(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const pullout::Costmap& m = l.costmap;
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(m.width()) * m.height());
  for (int j = 0; j < m.height(); ++j) {
    for (int i = 0; i < m.width(); ++i) occ[static_cast<std::size_t>(j) * m.width() + i] = m.occupied(i, j) ? 1 : 0;
  }
  for (auto _ : state) {
    const pullout::Costmap built(m.origin(), m.resolution(), m.width(), m.height(), occ);
    benchmark::DoNotOptimize(built.centre_distance(0, 0));
  }
}

// The whole costmap build of a lot from its obstacle polygons (what a planning request pays):
// the polygons rasterised with their exact layer (Costmap::add_obstacles: hard and partial cells),
// then the tables. The empty map it starts from is made outside the timing.
void BM_CostmapAddObstacles(benchmark::State& state) {
  const double size = static_cast<double>(state.range(0));
  const double resolution = static_cast<double>(state.range(1)) * 0.01;
  std::mt19937 rng(static_cast<unsigned>(state.range(0) * 100 + state.range(1)));
  const std::vector<pullout::Polygon> obstacles = lot_obstacles(size, rng);
  for (auto _ : state) {
    state.PauseTiming();
    pullout::Costmap map = empty_lot(size, resolution);
    state.ResumeTiming();
    map.add_obstacles(obstacles);
    benchmark::DoNotOptimize(map.centre_distance(0, 0));
  }
  state.counters["polygons"] = static_cast<double>(obstacles.size());
}

// Lot size [m] x resolution [cm].
void lots(benchmark::internal::Benchmark* b) {
  for (const int size : {30, 100}) {
    for (const int res : {10, 20}) b->Args({size, res});
  }
}

BENCHMARK_CAPTURE(BM_Collides, near, true)->Apply(lots);
BENCHMARK_CAPTURE(BM_Collides, open, false)->Apply(lots);
BENCHMARK_CAPTURE(BM_ClearanceBound, near, true)->Apply(lots);
BENCHMARK_CAPTURE(BM_ClearanceBound, open, false)->Apply(lots);
BENCHMARK(BM_CostmapBuild)->Apply(lots)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CostmapAddObstacles)->Apply(lots)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
