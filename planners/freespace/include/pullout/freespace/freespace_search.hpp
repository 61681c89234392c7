// The freespace search behind freespace_planner.freespace_planner_algorithm (Autoware's key):
// "astar" is hybrid A* (hybrid_astar.hpp, this module); "rrtstar" is OMPL's RRT*, seeded and retried, that lives
// in its own module (freespace_ompl: OMPL stays out of this one) and is handed in as a
// FreespaceSearch by whoever builds the planner (the pipeline). Both answer with the same result
// (waypoints with their driving direction), so everything after the search is shared.
#pragma once

#include <functional>
#include <string>

#include "pullout/freespace/hybrid_astar.hpp"

namespace pullout {

// Plans from start to goal on the checker's costmap with the search settings (turning radius,
// waypoint interval, goal ranges), within `stop`.
using FreespaceSearch =
    std::function<HybridAStarResult(const GridCollisionChecker& checker, const HybridAStarConfig& config,
                                    const Pose2& start, const Pose2& goal, const StopCondition& stop)>;

// The names of freespace_planner_algorithm.
constexpr const char* kAstarAlgorithm = "astar";
constexpr const char* kRrtStarAlgorithm = "rrtstar";

}  // namespace pullout
