// Informed RRT* (OMPL) as a freespace search: freespace_planner_algorithm: rrtstar.
//
// J. D. Gammell, S. S. Srinivasa, T. D. Barfoot, "Informed RRT*: Optimal sampling-based path
// planning focused via direct sampling of an admissible ellipsoidal heuristic", IROS 2014;
// OMPL's ompl::geometric::InformedRRTstar over ompl::base::ReedsSheppStateSpace with the search's
// turning radius, bounded by the costmap. States are valid when OUR GridCollisionChecker says
// the footprint is free; motions are checked every 5 cm. It stops at its first exact solution
// (within 5 cm of the goal in the Reeds-Shepp metric) or when `stop` says so.
//
// The solution's Reeds-Shepp pieces are sampled (our ReedsShepp, the same radius) every
// config.waypoint_interval at most into waypoints with their direction, each sample tested with
// the checker again (a sample in collision gives kNoPath): the same result as HybridAStar::plan,
// with reached_exact_goal false (the last waypoint is within 5 cm of the goal, not on it).
// Start or goal in collision: kStartOccupied / kGoalOccupied. Stopped: kTimeout / kCancelled
// with the reason.
//
// Thread safety: a call owns its OMPL objects; OMPL's random generator is seeded per call from
// its process-wide seed. OMPL's console output is switched off.
#pragma once

#include "pullout/freespace/freespace_search.hpp"

namespace pullout {

HybridAStarResult plan_rrt_star(const GridCollisionChecker& checker, const HybridAStarConfig& config,
                                const Pose2& start, const Pose2& goal, const StopCondition& stop);

}  // namespace pullout
