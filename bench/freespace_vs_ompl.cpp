// Freespace benchmark: our hybrid A* against OMPL's RRT* and BIT* on the same problems, in the
// same run, with the same collision test and the same time budget.
//
//   build/bench/bench_freespace [--problems 24] [--budget-ms 2000] [--seed 5] [--heuristic-weight 2.0]
//                               [--theta-size N] [--xy-resolution M] [--narrow-penalty P] [--turning-steps S]
//                               [--turning-heuristic W] [--ours-only] [--no-peers] [--case N]
//
//   build/bench/bench_freespace --tpcap ../shared/benchmarks/tpcap [--resolution 0.1] [--budget-ms 10000]
//                               [--case N] [--min-primitive M] [--search-from-goal] [--stall-expansions N]
//
// --min-primitive, --search-from-goal and --stall-expansions set the rescue of a stuck search
// (HybridAStarConfig: min_primitive_length, default 0.1, 0 = the plain search alone;
// search_from_goal, default on; stall_expansions, default 1000).
//
// --tpcap runs the 20 TPCAP cases (bench/tpcap.hpp; read at run time, never committed) instead of
// the generated lots: the organisers' vehicle (no shape margin), turning radius from wheelbase
// 2.8 m and steering 0.75 rad, the map the organisers' demo draws (start and goal box +-15 m),
// the obstacle polygons exact (Costmap::from_polygons).
// Ours twice: freespace_planner_algorithm astar (hybrid A*) and rrtstar (freespace_ompl's seeded,
// retried RRT*, run_rrt_star). --no-peers skips the OMPL RRT*/BIT* peers (plain OMPL, seeded by
// the process-wide ompl::RNG::setSeed).
// --ours-only skips OMPL and prints, per problem, the expansions of the search, the costmap's build
// time (wall clock; thread CPU time next to the search's: steadier on a loaded machine) and the
// share of the distance field's row segments the search filled (Costmap builds its tables
// lazily), then the medians and p95 of build, search and both. With the environment variable
// PULLOUT_DUMP_EXPANSIONS=<dir>, each problem's costmap (<i>.pgm) and the poses our search expanded
// (<i>.txt: "E x y yaw" lines) are written there, to see where a search spends its time.
//
// Problems: parking lots 30-100 m across, 0.1 or 0.2 m cells, walls around, rows of
// perpendicular bays with parked cars (each bay taken with probability 0.7), generated from a
// fixed seed. The start is an empty bay entered nose-in; the goal is either the lot's exit
// (in the aisle at the far corner) or another empty bay, reversed into.
//
// Peers: OMPL RRT* and BIT* over ompl::base::ReedsSheppStateSpace (the same turning radius as our
// primitives), with OUR GridCollisionChecker as the state validity checker, motions checked
// every 5 cm. Each stops at its first exact solution or at the budget (time to first solution,
// like ours). Reported: success rate, median and p95 time to the first solution (successes),
// mean path length, mean number of direction changes. OMPL is a benchmark-only dependency.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <ompl/base/ScopedState.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/ReedsSheppStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "load_average.hpp"
#include "lot_shapes.hpp"
#include "pullout/freespace/costmap.hpp"
#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/freespace/hybrid_astar.hpp"
#include "pullout/freespace/path_smoother.hpp"
#include "pullout/freespace/reeds_shepp.hpp"
#include "pullout/freespace_ompl/rrt_star.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/vehicle/vehicle_info.hpp"
#include "tpcap.hpp"

namespace {

namespace ob = ompl::base;

// CPU time of the calling thread [ms]: steadier than wall-clock time on a loaded machine.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}
namespace og = ompl::geometric;
using pullout::Pose2;

using pullout::kPi;
constexpr double kBayWidth = 2.7;  // [m]
constexpr double kBayDepth = 5.5;  // [m]
constexpr double kAisle = 7.0;     // [m]
constexpr double kWall = 0.4;      // [m]
constexpr double kMargin = 0.1;    // [m] footprint growth on each side

struct Problem {
  std::string name;
  double size{30.0};
  double resolution{0.2};
  pullout::Costmap costmap;
  Pose2 start;
  Pose2 goal;
  double build_ms{0.0};  // the costmap's construction from the obstacles (rasterisation and tables)
  double build_cpu_ms{0.0};
};

using pullout::bench::box;

// A bay: its centre and the direction its opening faces (+1: the aisle is above, -1: below).
struct Bay {
  double x{0.0};
  double y_open{0.0};  // y of the bay's open side
  int faces{1};
};

Problem make_problem(int index, std::mt19937& rng, const pullout::Footprint& fp) {
  Problem p;
  const double sizes[] = {30.0, 50.0, 75.0, 100.0};
  p.size = sizes[index % 4];
  p.resolution = (index / 4) % 2 == 0 ? 0.2 : 0.1;
  const int cells = static_cast<int>(std::round(p.size / p.resolution));
  std::vector<pullout::Polygon> obstacles{box(p.size / 2, kWall / 2, 0, p.size, kWall),
                                          box(p.size / 2, p.size - kWall / 2, 0, p.size, kWall),
                                          box(kWall / 2, p.size / 2, 0, kWall, p.size)};
  // The east wall, with the exit (8 m) at its top end.
  obstacles.push_back(box(p.size - kWall / 2, (p.size - 8.0) / 2, 0, kWall, p.size - 8.0));
  // Rows of bays: a single row along the south wall, then double rows, each followed by an aisle.
  std::vector<Bay> bays;
  double y = kWall;
  bool single = true;
  while (true) {
    const double depth = single ? kBayDepth : 2 * kBayDepth;
    if (y + depth + kAisle > p.size - kWall - 1e-9) break;
    for (double x = 7.0; x + kBayWidth <= p.size - 7.0; x += kBayWidth) {
      if (single) {
        bays.push_back({x + kBayWidth / 2, y + kBayDepth, 1});
      } else {
        bays.push_back({x + kBayWidth / 2, y, -1});
        bays.push_back({x + kBayWidth / 2, y + 2 * kBayDepth, 1});
      }
    }
    y += depth + kAisle;
    single = false;
  }
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Two bays are kept free whatever the draw (the start's and one more).
  std::uniform_int_distribution<std::size_t> pick(0, bays.size() - 1);
  const std::size_t keep_a = pick(rng);
  std::size_t keep_b = pick(rng);
  while (keep_b == keep_a) keep_b = pick(rng);
  std::vector<std::size_t> empty;
  for (std::size_t i = 0; i < bays.size(); ++i) {
    const Bay& b = bays[i];
    if (i != keep_a && i != keep_b && u(rng) < 0.7) {
      const double cy = b.y_open - b.faces * (kBayDepth / 2);
      obstacles.push_back(box(b.x + (u(rng) - 0.5) * 0.3, cy, kPi / 2 + (u(rng) - 0.5) * 0.1, 4.6, 1.9));
    } else {
      empty.push_back(i);
    }
  }
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(cells) * cells, 0);
  p.costmap = pullout::Costmap({0, 0, 0}, p.resolution, cells, cells, std::move(occ));
  const auto b0 = std::chrono::steady_clock::now();
  const double c0 = thread_cpu_ms();
  p.costmap.add_obstacles(obstacles);
  p.build_cpu_ms = thread_cpu_ms() - c0;
  p.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - b0).count();
  // Parked in a bay: rear bumper 0.3 m inside the opening. Nose-in faces away from the aisle.
  const auto parked = [&](const Bay& b, bool nose_in) {
    const double inward = -b.faces;  // +y or -y into the bay
    const double yaw = inward > 0 ? kPi / 2 : -kPi / 2;
    if (nose_in) return Pose2{b.x, b.y_open + inward * (0.3 + fp.rear), yaw};
    return Pose2{b.x, b.y_open + inward * (0.3 + fp.front), pullout::normalize_angle(yaw + kPi)};
  };
  std::shuffle(empty.begin(), empty.end(), rng);
  p.start = parked(bays[empty[0]], true);
  if (index % 2 == 0) {
    p.goal = {p.size - 4.0, p.size - kWall - kAisle / 2, 0.0};  // at the exit, heading out
    p.name = "exit";
  } else {
    // The empty bay farthest from the start, reversed into.
    std::size_t far = empty[1];
    for (std::size_t k = 1; k < empty.size(); ++k) {
      const double d = std::hypot(bays[empty[k]].x - bays[empty[0]].x, bays[empty[k]].y_open - bays[empty[0]].y_open);
      if (d > std::hypot(bays[far].x - bays[empty[0]].x, bays[far].y_open - bays[empty[0]].y_open)) far = empty[k];
    }
    p.goal = parked(bays[far], false);
    p.name = "bay";
  }
  p.name = std::to_string(static_cast<int>(p.size)) + "m/" + (p.resolution < 0.15 ? "0.1" : "0.2") + "/" + p.name;
  return p;
}

// Search settings from the command line (0: the planner's default).
struct SearchOverrides {
  int theta_size{0};
  double xy_resolution{0.0};
  double narrow_penalty{-1.0};  // < 0: the default
  int turning_steps{0};
  double min_primitive{-1.0};  // < 0: the default
  bool from_goal{false};
  long stall_expansions{-1};       // < 0: the default
  double turning_heuristic{-1.0};  // < 0: the default
} g_search;

struct Run {
  bool success{false};
  double time_ms{0.0};
  double length{0.0};
  int direction_changes{0};
  std::size_t expansions{0};
  int status{0};  // ours: HybridAStarResult::Status
  bool from_goal{false};
  // Ours: the path's shape before and after path_smoother, and the smoothing time.
  pullout::PathShape raw;
  pullout::PathShape smooth;
  double smooth_ms{0.0};
  double cpu_ms{0.0};  // the search's thread CPU time
  double cost{0.0};    // ours: the path's cost by the search's own weights (path_cost)
  int segments{0};
  int refused{0};
};

// A path's cost by the search's weights (hybrid_astar.hpp): a step between waypoints on an arc at
// the least turning radius costs its arc length x (1 + curve_weight), a straight step its length,
// either times (1 + reverse_weight) in reverse, plus direction_change_weight per change. (The
// primitives and the Reeds-Shepp shots are straight or at full steer: turning_steps 1.)
double path_cost(const std::vector<pullout::Waypoint>& w, const pullout::HybridAStarConfig& config) {
  double cost = 0.0;
  for (std::size_t i = 1; i < w.size(); ++i) {
    const double chord = std::hypot(w[i].pose.x - w[i - 1].pose.x, w[i].pose.y - w[i - 1].pose.y);
    const double arc = std::abs(pullout::normalize_angle(w[i].pose.yaw - w[i - 1].pose.yaw)) * config.turning_radius;
    const bool curve = arc > 0.5 * chord;
    double step = curve ? arc * (1.0 + config.curve_weight) : chord;
    if (w[i].direction < 0) step *= 1.0 + config.reverse_weight;
    cost += step;
    if (w[i].direction != w[i - 1].direction) cost += config.direction_change_weight;
  }
  return cost;
}

Run run_ours(const Problem& p, const pullout::GridCollisionChecker& checker, double radius, double budget_ms,
             double heuristic_weight) {
  pullout::HybridAStarConfig config;
  config.theta_size = g_search.theta_size > 0 ? g_search.theta_size : config.theta_size;
  config.xy_resolution = g_search.xy_resolution;
  if (g_search.turning_steps > 0) config.turning_steps = g_search.turning_steps;
  if (g_search.narrow_penalty >= 0.0) config.narrow_heuristic_penalty = g_search.narrow_penalty;
  if (g_search.turning_heuristic >= 0.0) config.turning_heuristic_weight = g_search.turning_heuristic;
  if (g_search.min_primitive >= 0.0) config.min_primitive_length = g_search.min_primitive;
  if (g_search.from_goal) config.search_from_goal = true;
  if (g_search.stall_expansions >= 0) config.stall_expansions = static_cast<std::size_t>(g_search.stall_expansions);
  std::vector<Pose2> expanded;
  const char* dump = std::getenv("PULLOUT_DUMP_EXPANSIONS");  // directory: <problem index>.pgm / .txt
  if (dump != nullptr) config.expanded_poses = &expanded;
  config.turning_radius = radius;
  config.distance_heuristic_weight = heuristic_weight;
  const pullout::HybridAStar planner(checker, config);
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = thread_cpu_ms();
  const pullout::HybridAStarResult r = planner.plan(p.start, p.goal, pullout::StopCondition::after_ms(budget_ms));
  Run run;
  run.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  run.cpu_ms = thread_cpu_ms() - cpu0;
  run.success = r.status == pullout::HybridAStarResult::Status::kSuccess;
  run.length = r.length;
  run.expansions = r.expansions;
  run.from_goal = r.found_from_goal;
  run.status = static_cast<int>(r.status);
  if (dump != nullptr) {
    // A picture of the search: the costmap as a PGM (north up) and the expanded poses as text.
    static int index = 0;
    const std::string base = std::string(dump) + "/" + std::to_string(index++);
    if (FILE* f = std::fopen((base + ".pgm").c_str(), "w")) {
      std::fprintf(f, "P5 %d %d 255\n", p.costmap.width(), p.costmap.height());
      for (int y = p.costmap.height() - 1; y >= 0; --y) {
        for (int x = 0; x < p.costmap.width(); ++x) std::fputc(p.costmap.occupied(x, y) ? 0 : 255, f);
      }
      std::fclose(f);
    }
    if (FILE* f = std::fopen((base + ".txt").c_str(), "w")) {
      std::fprintf(f, "# resolution %g start %g %g %g goal %g %g %g\n", p.resolution, p.start.x, p.start.y, p.start.yaw,
                   p.goal.x, p.goal.y, p.goal.yaw);
      for (const Pose2& e : expanded) std::fprintf(f, "E %g %g %g 0 0\n", e.x, e.y, e.yaw);
      std::fclose(f);
    }
  }
  for (std::size_t i = 1; i < r.waypoints.size(); ++i) {
    run.direction_changes += r.waypoints[i].direction != r.waypoints[i - 1].direction ? 1 : 0;
  }
  if (run.success) run.cost = path_cost(r.waypoints, config);
  if (run.success) {
    pullout::PathSmootherConfig smoother;
    smoother.max_curvature = 1.0 / radius;
    const auto s0 = std::chrono::steady_clock::now();
    const pullout::SmoothedPath smoothed = pullout::smooth_path(r.waypoints, checker, smoother);
    run.smooth_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - s0).count();
    run.raw = pullout::path_shape(r.waypoints);
    run.smooth = pullout::path_shape(smoothed.waypoints);
    run.segments = smoothed.segments;
    run.refused = smoothed.refused;
  }
  return run;
}

// Ours with freespace_planner_algorithm rrtstar (freespace_ompl/rrt_star.hpp: seeded, retried),
// the same checker and budget; no smoothing (time to the search's answer, as for the others).
Run run_rrtstar(const Problem& p, const pullout::GridCollisionChecker& checker, double radius, double budget_ms) {
  pullout::HybridAStarConfig config;
  config.turning_radius = radius;
  const auto t0 = std::chrono::steady_clock::now();
  const pullout::RrtStarResult r = pullout::run_rrt_star(checker, config, pullout::RrtStarConfig{}, p.start, p.goal,
                                                         pullout::StopCondition::after_ms(budget_ms));
  Run run;
  run.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  run.success = r.search.status == pullout::HybridAStarResult::Status::kSuccess;
  run.length = r.search.length;
  run.expansions = r.search.expansions;
  run.status = static_cast<int>(r.search.status);
  const auto& w = r.search.waypoints;
  for (std::size_t i = 1; i < w.size(); ++i) run.direction_changes += w[i].direction != w[i - 1].direction ? 1 : 0;
  return run;
}

// Ours before and after smoothing (path_smoother.hpp), over the solved problems.
void print_smoothing(const std::vector<Run>& runs) {
  std::vector<double> times;
  double n = 0.0, segments = 0.0, refused = 0.0;
  pullout::PathShape raw, smooth;
  double raw_kmax = 0.0, smooth_kmax = 0.0;
  for (const Run& r : runs) {
    if (!r.success) continue;
    n += 1.0;
    times.push_back(r.smooth_ms);
    segments += r.segments;
    refused += r.refused;
    raw.length += r.raw.length;
    smooth.length += r.smooth.length;
    raw.curvature_variation += r.raw.curvature_variation;
    smooth.curvature_variation += r.smooth.curvature_variation;
    raw.max_curvature_rate += r.raw.max_curvature_rate;
    smooth.max_curvature_rate += r.smooth.max_curvature_rate;
    raw.curvature_energy += r.raw.curvature_energy;
    smooth.curvature_energy += r.smooth.curvature_energy;
    raw_kmax = std::max(raw_kmax, r.raw.max_curvature);
    smooth_kmax = std::max(smooth_kmax, r.smooth.max_curvature);
  }
  if (n == 0.0) return;
  std::sort(times.begin(), times.end());
  std::printf("\nsmoothing (hybrid A*, %.0f solved problems; means per path unless noted)\n", n);
  std::printf(
      "| path | length [m] | max curvature, all paths [1/m] | sum abs(dk) [1/m] | max abs(dk/ds) [1/m^2] | sum dk^2/ds "
      "[1/m^3] |\n|---|---|---|---|---|---|\n");
  std::printf("| search output | %.2f | %.4f | %.3f | %.3f | %.4f |\n", raw.length / n, raw_kmax,
              raw.curvature_variation / n, raw.max_curvature_rate / n, raw.curvature_energy / n);
  std::printf("| smoothed | %.2f | %.4f | %.3f | %.3f | %.4f |\n", smooth.length / n, smooth_kmax,
              smooth.curvature_variation / n, smooth.max_curvature_rate / n, smooth.curvature_energy / n);
  std::printf("smoothing time: median %.2f ms, max %.2f ms; segments %.0f, refused (kept as searched) %.0f\n",
              times[times.size() / 2], times.back(), segments, refused);
}

Run run_ompl(const Problem& p, const pullout::GridCollisionChecker& checker, double radius, double budget_ms,
             bool bit_star) {
  auto space = std::make_shared<ob::ReedsSheppStateSpace>(radius);
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0.0);
  bounds.setHigh(p.size);
  space->setBounds(bounds);
  og::SimpleSetup ss(space);
  ss.setStateValidityChecker([&checker](const ob::State* s) {
    const auto* st = s->as<ob::SE2StateSpace::StateType>();
    return !checker.collides({st->getX(), st->getY(), st->getYaw()});
  });
  ss.getSpaceInformation()->setStateValidityCheckingResolution(0.05 / space->getMaximumExtent());
  ob::ScopedState<> start(space), goal(space);
  start[0] = p.start.x;
  start[1] = p.start.y;
  start[2] = p.start.yaw;
  goal[0] = p.goal.x;
  goal[1] = p.goal.y;
  goal[2] = p.goal.yaw;
  ss.setStartAndGoalStates(start, goal, 0.05);
  // An objective that any solution satisfies: RRT* and BIT* return their first solution (else
  // they would refine it until the budget runs out).
  auto objective = std::make_shared<ob::PathLengthOptimizationObjective>(ss.getSpaceInformation());
  objective->setCostThreshold(ob::Cost(std::numeric_limits<double>::infinity()));
  ss.setOptimizationObjective(objective);
  if (bit_star) {
    ss.setPlanner(std::make_shared<og::BITstar>(ss.getSpaceInformation()));
  } else {
    ss.setPlanner(std::make_shared<og::RRTstar>(ss.getSpaceInformation()));
  }
  ss.setup();
  const auto t0 = std::chrono::steady_clock::now();
  const ob::PlannerTerminationCondition ptc =
      ob::plannerOrTerminationCondition(ob::timedPlannerTerminationCondition(budget_ms / 1000.0),
                                        ob::exactSolnPlannerTerminationCondition(ss.getProblemDefinition()));
  const ob::PlannerStatus status = ss.solve(ptc);
  Run run;
  run.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  run.success = status == ob::PlannerStatus::EXACT_SOLUTION;
  if (!run.success) return run;
  const og::PathGeometric& path = ss.getSolutionPath();
  run.length = path.length();
  // Direction changes: the Reeds-Shepp segments between consecutive states, in order.
  const pullout::ReedsShepp rs(radius);
  int last = 0;
  for (std::size_t i = 1; i < path.getStateCount(); ++i) {
    const auto* a = path.getState(i - 1)->as<ob::SE2StateSpace::StateType>();
    const auto* b = path.getState(i)->as<ob::SE2StateSpace::StateType>();
    const pullout::ReedsSheppPath piece =
        rs.shortest({a->getX(), a->getY(), a->getYaw()}, {b->getX(), b->getY(), b->getYaw()});
    for (int k = 0; k < piece.count; ++k) {
      const double l = piece.segments[static_cast<std::size_t>(k)].length;
      if (std::abs(l) < 1e-9) continue;
      const int dir = l > 0 ? 1 : -1;
      if (last != 0 && dir != last) ++run.direction_changes;
      last = dir;
    }
  }
  return run;
}

// TPCAP case `number` (1-based) as a Problem: grid origin at the map box's min corner.
bool make_tpcap(const std::string& dir, int number, double resolution, Problem& out) {
  pullout::bench::TpcapCase c;
  std::string error;
  if (!pullout::bench::load_tpcap(dir + "/Case" + std::to_string(number) + ".csv", c, error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return false;
  }
  constexpr double kBox = 15.0;  // [m] the organisers' demo map around start and goal
  const pullout::Vec2 lo(std::min(c.start.x, c.goal.x) - kBox, std::min(c.start.y, c.goal.y) - kBox);
  const pullout::Vec2 hi(std::max(c.start.x, c.goal.x) + kBox, std::max(c.start.y, c.goal.y) + kBox);
  pullout::Aabb extent;
  extent.extend({0.0, 0.0});
  extent.extend(hi - lo);
  for (auto& poly : c.obstacles) {
    for (auto& v : poly) v -= lo;
  }
  const pullout::Polygon all{
      {0.0, 0.0}, {hi.x() - lo.x(), 0.0}, {hi.x() - lo.x(), hi.y() - lo.y()}, {0.0, hi.y() - lo.y()}};
  out.name = "tpcap " + std::to_string(number);
  out.size = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  out.resolution = resolution;
  const auto b0 = std::chrono::steady_clock::now();
  const double c0 = thread_cpu_ms();
  out.costmap = pullout::Costmap::from_polygons(extent, resolution, {all}, {}, c.obstacles);
  out.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - b0).count();
  out.build_cpu_ms = thread_cpu_ms() - c0;
  out.start = {c.start.x - lo.x(), c.start.y - lo.y(), c.start.yaw};
  out.goal = {c.goal.x - lo.x(), c.goal.y - lo.y(), c.goal.yaw};
  return true;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(v.size() - 1, lo + 1);
  const double frac = pos - static_cast<double>(lo);
  if (frac == 0.0 || std::isinf(v[lo])) return v[lo];
  if (std::isinf(v[hi])) return v[hi];  // between a success and a failure: unknown, above the budget
  return v[lo] + frac * (v[hi] - v[lo]);
}

}  // namespace

int main(int argc, char** argv) {
  int problems = 24;
  double budget_ms = 2000.0;
  unsigned seed = 5;
  double heuristic_weight = 2.0;  // astar.distance_heuristic_weight (its default)
  bool ours_only = false;         // --ours-only: skip OMPL, print search statistics
  bool no_peers = false;          // --no-peers: hybrid A* and rrtstar only (no OMPL RRT*/BIT* peers)
  std::string tpcap;              // --tpcap DIR: the TPCAP cases instead of generated lots
  double tpcap_resolution = 0.1;  // [m]
  int only_case = 0;              // --case N: this TPCAP case or lot only (1-based)
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (std::strcmp(argv[i], "--ours-only") == 0) {
      ours_only = true;
    } else if (std::strcmp(argv[i], "--no-peers") == 0) {
      no_peers = true;
    } else if (has_value && std::strcmp(argv[i], "--tpcap") == 0) {
      tpcap = argv[++i];
    } else if (std::strcmp(argv[i], "--search-from-goal") == 0) {
      g_search.from_goal = true;
    } else if (has_value && std::strcmp(argv[i], "--min-primitive") == 0) {
      g_search.min_primitive = std::atof(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--stall-expansions") == 0) {
      g_search.stall_expansions = std::atol(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--case") == 0) {
      only_case = std::atoi(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--resolution") == 0) {
      tpcap_resolution = std::atof(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--problems") == 0) {
      problems = std::atoi(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--budget-ms") == 0) {
      budget_ms = std::atof(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--seed") == 0) {
      seed = static_cast<unsigned>(std::atoi(argv[++i]));
    } else if (has_value && std::strcmp(argv[i], "--theta-size") == 0) {
      g_search.theta_size = std::atoi(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--xy-resolution") == 0) {
      g_search.xy_resolution = std::atof(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--turning-steps") == 0) {
      g_search.turning_steps = std::atoi(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--narrow-penalty") == 0) {
      g_search.narrow_penalty = std::atof(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--turning-heuristic") == 0) {
      g_search.turning_heuristic = std::atof(argv[++i]);
    } else if (has_value && std::strcmp(argv[i], "--heuristic-weight") == 0) {
      heuristic_weight = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "unknown argument: %s\n", argv[i]);
      return 2;
    }
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  ompl::RNG::setSeed(seed);  // before any OMPL sampler exists: the peers' runs are reproducible too
  const pullout::VehicleInfo vehicle;
  double radius = vehicle.wheel_base_m / std::tan(vehicle.max_steer_angle_rad * 0.7);  // max_turning_ratio 0.7
  pullout::Footprint fp = pullout::vehicle_footprint(vehicle, kMargin);
  if (!tpcap.empty()) {
    problems = 20;
    radius = pullout::bench::kTpcapWheelbase / std::tan(pullout::bench::kTpcapMaxSteer);
    fp = {pullout::bench::kTpcapFront, pullout::bench::kTpcapRear, pullout::bench::kTpcapHalfWidth,
          pullout::bench::kTpcapHalfWidth};
  }
  std::mt19937 rng(seed);
  constexpr int kPlanners = 4;
  const char* names[kPlanners] = {"astar (pullout)", "rrtstar (pullout)", "OMPL RRT*", "OMPL BIT*"};
  std::vector<Run> runs[kPlanners];
  std::vector<double> small_ours;                            // 30 m at 0.2 m
  std::vector<double> cpu_builds, cpu_searches, cpu_totals;  // the same in thread CPU time
  std::vector<double> builds, totals;  // --ours-only: costmap build [ms], build + search (failures +inf)
  std::printf("%-18s %28s %28s %28s %28s\n", "problem", names[0], names[1], names[2], names[3]);
  for (int i = 0; i < problems; ++i) {
    Problem p;
    if (!tpcap.empty() && only_case > 0 && i + 1 != only_case) continue;
    if (tpcap.empty()) {
      p = make_problem(i, rng, fp);  // (every lot: each one draws from the generator)
      if (only_case > 0 && i + 1 != only_case) continue;
    } else if (!make_tpcap(tpcap, i + 1, tpcap_resolution, p)) {
      return 1;
    }
    const pullout::GridCollisionChecker checker(p.costmap, fp);
    if (checker.collides(p.start) || checker.collides(p.goal)) {
      if (!tpcap.empty()) {
        std::printf("%-18s start or goal in collision\n", p.name.c_str());
        for (auto& r : runs) r.push_back({});
        continue;
      }
      std::printf("%-18s invalid start or goal (generator bug)\n", p.name.c_str());
      return 1;
    }
    if (ours_only) {
      const Run r = run_ours(p, checker, radius, budget_ms, heuristic_weight);
      runs[0].push_back(r);
      builds.push_back(p.build_ms);
      cpu_builds.push_back(p.build_cpu_ms);
      cpu_searches.push_back(r.cpu_ms);
      cpu_totals.push_back(r.success ? p.build_cpu_ms + r.cpu_ms : std::numeric_limits<double>::infinity());
      totals.push_back(r.success ? p.build_ms + r.time_ms : std::numeric_limits<double>::infinity());
      const pullout::DistanceField& field = p.costmap.distance_field();
      const double filled = field.empty() ? 0.0
                                          : 100.0 * static_cast<double>(field.filled_segments()) /
                                                (static_cast<double>(field.height()) *
                                                 ((field.width() + pullout::DistanceField::kSegmentCells - 1) /
                                                  pullout::DistanceField::kSegmentCells));
      std::printf(
          "%-18s %8.1f ms %6.1f m %2d cusps %8zu expansions  build %5.1f ms  cpu %5.1f + %5.1f ms %5.1f %% "
          "filled  cost %6.1f%s%s\n",
          p.name.c_str(), r.time_ms, r.length, r.direction_changes, r.expansions, p.build_ms, p.build_cpu_ms, r.cpu_ms,
          filled, r.cost, r.success ? "" : "  (no solution)", r.from_goal ? "  (from the goal)" : "");
      if (!r.success) std::printf("%-18s   status %d (HybridAStarResult::Status)\n", "", r.status);
      if (p.size == 30.0 && p.resolution > 0.15 && r.success) small_ours.push_back(r.time_ms);
      continue;
    }
    Run r[kPlanners] = {run_ours(p, checker, radius, budget_ms, heuristic_weight),
                        run_rrtstar(p, checker, radius, budget_ms), Run{}, Run{}};
    if (!no_peers) {
      r[2] = run_ompl(p, checker, radius, budget_ms, false);
      r[3] = run_ompl(p, checker, radius, budget_ms, true);
    }
    std::printf("%-18s", p.name.c_str());
    for (int k = 0; k < (no_peers ? 2 : kPlanners); ++k) {
      runs[k].push_back(r[k]);
      if (r[k].success) {
        std::printf("   %8.1f ms %6.1f m %2d cusps", r[k].time_ms, r[k].length, r[k].direction_changes);
      } else {
        std::printf("   %8.1f ms     (no solution)", r[k].time_ms);
      }
    }
    std::printf("\n");
    if (p.size == 30.0 && p.resolution > 0.15 && r[0].success) small_ours.push_back(r[0].time_ms);
  }
  // Time to first solution of a failed run is unknown but above the budget: it counts as +inf in the
  // medians and p95 over all problems (a censored sample; ">budget" when the quantile falls there).
  // The median over successes only is printed too (it flatters a planner that fails often).
  const auto fmt = [budget_ms](double v) {
    char buf[32];
    if (std::isinf(v)) {
      std::snprintf(buf, sizeof buf, ">%.0f", budget_ms);
    } else {
      std::snprintf(buf, sizeof buf, "%.1f", v);
    }
    return std::string(buf);
  };
  std::printf(
      "\n| planner | success | median time to first solution [ms] | p95 [ms] | median over successes [ms] | mean "
      "length [m] | mean direction changes |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (int k = 0; k < (ours_only ? 1 : no_peers ? 2 : kPlanners); ++k) {
    std::vector<double> all, solved;
    double len = 0.0, changes = 0.0;
    for (const Run& r : runs[k]) {
      all.push_back(r.success ? r.time_ms : std::numeric_limits<double>::infinity());
      if (!r.success) continue;
      solved.push_back(r.time_ms);
      len += r.length;
      changes += r.direction_changes;
    }
    const double n = std::max<double>(1.0, static_cast<double>(solved.size()));
    std::printf("| %s | %zu/%zu | %s | %s | %s | %.1f | %.2f |\n", names[k], solved.size(), runs[k].size(),
                fmt(percentile(all, 0.5)).c_str(), fmt(percentile(all, 0.95)).c_str(),
                fmt(percentile(solved, 0.5)).c_str(), len / n, changes / n);
  }
  if (ours_only) {
    double cost = 0.0, solved = 0.0, expansions = 0.0;
    for (const Run& r : runs[0]) {
      if (!r.success) continue;
      cost += r.cost;
      expansions += static_cast<double>(r.expansions);
      solved += 1.0;
    }
    std::printf("\nmean path cost (the search's weights) %.1f, mean expansions %.0f over %.0f solved\n",
                cost / std::max(1.0, solved), expansions / std::max(1.0, solved), solved);
    std::printf("\ncostmap build: median %.2f ms, p95 %.2f ms, max %.2f ms; build + search: median %s ms, p95 %s ms\n",
                percentile(builds, 0.5), percentile(builds, 0.95), percentile(builds, 1.0),
                fmt(percentile(totals, 0.5)).c_str(), fmt(percentile(totals, 0.95)).c_str());
    std::printf(
        "CPU time: build median %.2f ms, p95 %.2f; search median %.2f, p95 %.2f; build + search median %s, p95 %s\n",
        percentile(cpu_builds, 0.5), percentile(cpu_builds, 0.95), percentile(cpu_searches, 0.5),
        percentile(cpu_searches, 0.95), fmt(percentile(cpu_totals, 0.5)).c_str(),
        fmt(percentile(cpu_totals, 0.95)).c_str());
  }
  std::printf("\nload average at the end: %s\n", pullout::bench::load_text().c_str());
  std::printf("\nhybrid A* median on 30 m x 30 m at 0.2 m: %.1f ms (%zu problems)\n", percentile(small_ours, 0.5),
              small_ours.size());
  print_smoothing(runs[0]);
  return 0;
}
