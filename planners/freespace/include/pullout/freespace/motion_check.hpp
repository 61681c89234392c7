// Reeds-Shepp motions on the costmap: the collision test of a whole motion and its waypoints,
// shared by the freespace searches (hybrid A*'s shots to the goal test their paths the same way;
// the RRT* of freespace_ompl tests every motion of its tree and its answer with these).
//
// Collision: as in hybrid_astar.hpp, the motion between the tested poses is covered completely
// and conservatively (hull tests of the footprint's places, grown by the sagitta of the turn
// between them): a path accepted here is free at every point, not only at samples, and a path is
// refused only if it passes within about 1.5 cm of an occupied cell.
//
// Poses along a path are driven segment by segment from `from` (each segment an arc of curvature
// +-1/turning_radius or a straight line), the same arithmetic in the test and in the waypoints.
#pragma once

#include <vector>

#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/freespace/hybrid_astar.hpp"
#include "pullout/freespace/reeds_shepp.hpp"

namespace pullout {

// True when the footprint at `from` and along the whole of `path` (driven from `from` with arcs
// of `turning_radius` [m]) touches no occupied cell and stays on the grid.
bool reeds_shepp_path_free(const GridCollisionChecker& checker, double turning_radius, const Pose2& from,
                           const ReedsSheppPath& path);

// Appends the poses of `path` driven from `from` (excluding `from`, including the path's end) at
// most `interval` [m] apart and with each segment's end among them (so every cusp is a waypoint),
// each with the direction of travel on the way to it. Returns the end pose.
Pose2 append_reeds_shepp_waypoints(double turning_radius, const Pose2& from, const ReedsSheppPath& path,
                                   double interval, std::vector<Waypoint>& out);

}  // namespace pullout
