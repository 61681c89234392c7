// Smoothing of a freespace path that keeps its cusps.
//
// Hybrid A* returns a chain of motion primitives (arcs at full steer and straights), so the
// curvature jumps between -k_max, 0 and +k_max every half metre. The smoother treats each
// direction segment (start or cusp to the next cusp or the goal) on its own, so every cusp keeps
// its pose and the vehicle still stops where the search said. Instead of moving points (Nav2
// Smac's gradient smoother) and then repairing the curvature, it smooths the curvature itself,
// which keeps it within the limit by construction:
//  - the segment is read as a chain of arcs (one between consecutive waypoints);
//  - the heading becomes its mean over +-window waypoints, the window shrinking towards the ends
//    so that both end headings stay; each arc's curvature follows from it (with a fixed window it
//    is the mean of the arcs' curvatures, so within +-max_curvature; steps become ramps);
//  - the end position that moved (a little: only where the heading changed) is brought back
//    exactly (Gauss-Newton) by a correction that is, at every arc, a fraction of the room left
//    below max_curvature there (Apollo's FEM smoother likewise keeps the curvature a hard
//    constraint);
//  - the poses follow by integrating the arcs from the segment's first pose.
// Afterwards the segment is checked, and one that fails is tried with half the window (down to
// one arc) or, if none passes, keeps its input waypoints unchanged (counted in `refused`):
//  - curvature: the curvature of the circle through every three consecutive points (exact on a
//    circle) at most max_curvature (1e-6 relative tolerance);
//  - collision: the motion between consecutive waypoints, position and heading interpolated
//    linearly, is collision-free with the checker's footprint everywhere (not only at samples):
//    samples are tested with the footprint grown by sweep_margin, spaced so that no point of the
//    body moves farther than allowed by the clearance bound of the sample before plus twice the
//    margin (the same argument as the search's arc_free).
//
// The result has the same number of waypoints and the same directions as the input; the
// stop condition is checked between segments (a segment not reached stays as it was).
//
// Thread safety: a free function on const inputs.
#pragma once

#include <vector>

#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/freespace/hybrid_astar.hpp"
#include "pullout/search/stop_condition.hpp"

namespace pullout {

struct PathSmootherConfig {
  double max_curvature{0.2};  // [1/m] the vehicle's, 1 / turning radius
  int window{8};              // [arcs] half width of the curvature mean (2 m at 0.25 m waypoints)
  double sweep_margin{0.0};   // [m] footprint growth of the sampled check; 0 = an eighth of a cell
};

struct SmoothedPath {
  std::vector<Waypoint> waypoints;  // as many as the input, same directions
  int segments{0};                  // direction segments of the input
  int smoothed{0};                  // segments that changed and passed the checks
  int refused{0};                   // segments kept as they were: no smoothed version passed the checks
};

SmoothedPath smooth_path(const std::vector<Waypoint>& waypoints, const GridCollisionChecker& checker,
                         const PathSmootherConfig& config, const StopCondition& stop = {});

// Shape figures of a path (for the benchmarks and the tests), from the curvature k of the circle
// through every three consecutive points of a direction segment: the length [m] (both
// directions), max |k| [1/m], the sum of |dk| between neighbours [1/m] (how much the steering
// swings back and forth), max |dk/ds| [1/m^2] (how fast the steering must turn) and the sum of
// dk^2 / ds [1/m^3] (the discrete integral of (dk/ds)^2: the usual smoothness energy, which a
// step in curvature makes large and a ramp small), and the number of cusps.
struct PathShape {
  double length{0.0};
  double max_curvature{0.0};
  double curvature_variation{0.0};
  double max_curvature_rate{0.0};
  double curvature_energy{0.0};
  int cusps{0};
};
PathShape path_shape(const std::vector<Waypoint>& waypoints);

// Signed curvature [1/m] of the circle through a, b, c (0 when they are collinear or coincide).
double three_point_curvature(const Vec2& a, const Vec2& b, const Vec2& c);

}  // namespace pullout
