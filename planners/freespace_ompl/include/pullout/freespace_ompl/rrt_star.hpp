// RRT* (OMPL) as a freespace search: freespace_planner_algorithm: rrtstar.
//
// S. Karaman, E. Frazzoli, "Sampling-based algorithms for optimal motion planning", IJRR 30(7),
// 2011; OMPL's ompl::geometric::RRTstar over ompl::base::ReedsSheppStateSpace with the search's
// turning radius, bounded by the costmap. It stops at its first exact solution (within 5 cm of the
// goal in the Reeds-Shepp metric), so the informed sampling of Autoware's informed RRT*
// (ompl::geometric::InformedRRTstar), which only narrows the samples once a solution exists, would
// change nothing and is not used.
//
// Collision: a state is valid when OUR GridCollisionChecker says the footprint is free; a motion of
// the tree is valid when the whole Reeds-Shepp path between its states is free by the sweep test
// of motion_check.hpp (the motion between samples included, never optimistic). The answer is made
// of exactly those paths, tested again, then joined to the exact goal when that last Reeds-Shepp
// path is free too (reached_exact_goal; else the path ends within 5 cm of the goal).
//
// Deterministic: every random number of a search comes from generators seeded here, per search
// (ompl::RNG::setLocalSeed on the planner's and the sampler's own generators; OMPL's process-wide
// seed, ompl::RNG::setSeed, is neither used nor needed), and the nearest-neighbour structure is
// one without randomness (OMPL's default GNAT draws its pivots from a generator that takes its seed from the
// process-wide sequence). Each
// attempt is bounded by a number of iterations, not by time: the same request gives the same
// path whatever ran before it in the process, in any thread, and however loaded the machine is,
// as long as `stop` does not cut the search short.
//
// Retries: attempt k (0-based) runs with seed `seed + k` and `first_iterations * 2^k` iterations
// on a new tree, until one finds a solution, `max_attempts` attempts failed (kNoPath: RRT* cannot
// prove that there is no path; the bound keeps an unsolvable goal from taking the whole budget
// from the next end pose), or `stop` says stop (kTimeout / kCancelled with the reason).
//
// Path: RRT*'s first solution zigzags between the samples it drew; its states are shortened
// deterministically (from each kept state, the farthest later one that a free motion reaches).
// Like every shortest path it runs along obstacles: FreespacePullOut gives this search a costmap
// with the objects grown (freespace_pull_out.hpp), so that the pipeline's clearance test passes.
//
// Output: the same as HybridAStar::plan (waypoints with their direction, at most
// config.waypoint_interval apart, every cusp a waypoint; length). Start or goal in collision:
// kStartOccupied / kGoalOccupied.
//
// Cost: motions of at most two turning radii; an iteration costs more as the tree grows (the
// k-nearest query of OMPL's SqrtApprox is linear in it): hundreds of milliseconds to seconds
// where hybrid A* takes milliseconds (bench/RESULTS.md).
//
// Thread safety: a call owns all its OMPL objects. OMPL's console output is switched off (once).
#pragma once

#include <cstddef>
#include <cstdint>

#include "pullout/freespace/freespace_search.hpp"

namespace pullout {

// The seed of the first attempt of every search (documented in the README).
constexpr std::uint32_t kRrtStarSeed = 1;

struct RrtStarConfig {
  std::uint32_t seed{kRrtStarSeed};    // attempt k uses seed + k
  std::size_t first_iterations{4000};  // iterations of attempt 0; doubled for each retry
  int max_attempts{5};                 // 4000 + 8000 + ... + 64000 = 124000 iterations at most
  double goal_bias{0.05};              // share of the samples that are the goal (OMPL's default)
};

struct RrtStarResult {
  HybridAStarResult search;   // expansions: iterations over all attempts; nodes: the solving tree's states
  int attempts{0};            // attempts run (the solving one included)
  std::uint32_t seed{0};      // seed of the last attempt run
  std::size_t iterations{0};  // iterations of the last attempt run
};

RrtStarResult run_rrt_star(const GridCollisionChecker& checker, const HybridAStarConfig& config,
                           const RrtStarConfig& rrt, const Pose2& start, const Pose2& goal, const StopCondition& stop);

// run_rrt_star with RrtStarConfig{}: the FreespaceSearch of freespace_planner_algorithm rrtstar.
HybridAStarResult plan_rrt_star(const GridCollisionChecker& checker, const HybridAStarConfig& config,
                                const Pose2& start, const Pose2& goal, const StopCondition& stop);

}  // namespace pullout
