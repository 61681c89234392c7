// Hybrid A*: a search over continuous vehicle poses (x, y, heading) bucketed into a lattice.
//
// D. Dolgov, S. Thrun, M. Montemerlo, J. Diebel, "Path Planning for Autonomous Vehicles in
// Unknown Semi-structured Environments", IJRR 29(5), 2010.
//
// Each expansion drives a motion primitive from a node's exact pose: an arc of `primitive_length`
// forwards (and, with use_back, backwards) at each of 2 * turning_steps + 1 curvatures between
// -1/turning_radius and +1/turning_radius. A node keeps its exact pose; the lattice cell
// (xy_resolution, 2 pi / theta_size) only decides which of two nodes survives. The default cell
// is one primitive long: on the freespace benchmark (bench/RESULTS.md) it halves the median time
// of a cell of primitive_length / sqrt(2) at the same success rate and path length. From time to time
// (more often near the goal) a Reeds-Shepp path is shot from the node to the exact goal
// ("analytic expansion"); the first collision-free one ends the search. Reaching the goal region
// (goal tolerances, in the goal frame) ends it too.
//
// Cost of a primitive of length l: l * (1 + curve_weight * |steer| / turning_steps) *
// (1 + reverse_weight when reversing), plus direction_change_weight [m] when it changes the
// direction of travel. Heuristic: distance_heuristic_weight * max(Reeds-Shepp distance to the goal
// without obstacles, 8-connected Dijkstra distance from the goal over the cells the rear axle can
// occupy, on a grid of lattice cells). Weights above 1 trade optimality for speed: the default 2.0
// is Autoware's; the heuristic ignores the cost weights, so with 1.0 the search floods every state
// whose detour is below the true cost's excess (bench/RESULTS.md has the figures). The Dijkstra
// distance also charges extra for narrow places (narrow_heuristic_penalty): gaps the rear axle
// fits through but the vehicle cannot turn into otherwise draw the search in.
// With turning_heuristic_weight > 0 (off by default) the heuristic also charges, beyond the
// Reeds-Shepp range and where the pose has room to turn, the turning still ahead on the Dijkstra
// distance's way to the goal pulled taut (from the pose's heading of travel to the way's
// direction, then the way's corners) at curve_weight x turning_radius per radian, times the
// reverse factor when the pose faces the way backwards: the corners a reversing path still has to
// turn, which the distance alone does not see. bench/RESULTS.md: 3.6x fewer expansions over the
// generated lots (12x on the slow one) and 1.3x on TPCAP, cheaper paths with as many direction
// changes on average, but other paths, per lot not always better.
//
// The pose the search expands from is known to be free, with a clearance bound kept in its node:
// the primitives from it are only checked beyond it.
//
// Collision: the poses the search stops at (nodes, the goal) are tested exactly against the
// costmap (GridCollisionChecker). The motion between them is covered completely, conservatively:
// the footprint grown by half a cell, tested at poses spaced so that the body cannot leave the
// grown rectangle in between (see arc_free in search_support.hpp), and where that refuses, grown
// by an eighth of a cell in four times as many tests; the clearance bound of a test skips the
// stretch it proves free. So a returned path is collision-free at every point, not only at its
// samples, and a motion is refused only if it passes within an eighth of a cell of an obstacle.
//
// Stuck searches. A car wriggles out of a tight spot (a parallel slot, a maze's pocket) with short
// moves between cusps, which 0.5 m primitives on a 0.5 m lattice cannot make. The search starts
// plain; when it is stuck (its open list is empty, or it has come within two lattice cells of the
// goal and made no progress for stall_expansions expansions), rescue searches join it, taking
// turns: from the goal, when the goal is in a tight spot and search_from_goal is set (getting out
// of a tight spot is found where a search begins; getting into one from afar means hitting a small
// target), and, once the plain search's open list is empty, from the start again. They expand a
// constrained node (fewer than 3 of its primitives reach a new cell) with its collided primitives
// too, driven until contact when that is at least min_primitive_length, and give its children a
// fine lattice cell (fine_xy_resolution, theta_size * fine_theta_factor headings). A search from
// the goal grows the path backwards in time and ends with a Reeds-Shepp shot to the exact start.
// Where the plain search is not stuck, it runs alone and the rescue costs nothing
// (bench/RESULTS.md, TPCAP cases 7 and 20).
//
// Failure modes are values (Status), never exceptions. The stop condition is checked before the
// first expansion and every few expansions after it, and inside the obstacle heuristic's flood of
// the grid (every 1024 cells); the search returns kTimeout (deadline or budget) or kCancelled
// promptly once it says stop. More than max_nodes nodes give kNodeLimit.
//
// Thread safety: plan() is const and may run concurrently (all search state is local).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/model/types.hpp"
#include "pullout/search/stop_condition.hpp"

namespace pullout {

constexpr int kMaxTurningSteps = 10;  // HybridAStarConfig::turning_steps at most (clamped to 1..this)

struct HybridAStarConfig {
  double turning_radius{5.0};    // [m] radius of the sharpest primitive and of the shots, > 0
  int turning_steps{1};          // curvatures per side: steer index -turning_steps..turning_steps
  int theta_size{120};           // heading bins of the lattice
  double primitive_length{0.5};  // [m] arc length of one motion primitive
  double xy_resolution{0.0};     // [m] lattice cell; 0 = primitive_length (see the note above)
  // The lattice of the children of constrained nodes (see the note above): cell [m] and heading
  // bins (theta_size times this).
  double fine_xy_resolution{0.02};
  int fine_theta_factor{4};
  // [m] in the rescue searches (see the note above), a primitive that would collide is cut to its
  // free part when that is at least this long ("drive until contact") at constrained nodes, whose
  // children also get the fine lattice; 0 = no rescue searches (the plain search alone).
  double min_primitive_length{0.1};
  bool use_back{true};  // expand reverse primitives
  // The rescue search from the goal when it lies in a tight spot (see the note above); needs
  // use_back and min_primitive_length > 0.
  bool search_from_goal{true};
  // [expansions] the plain search may go without progress near the goal (its least obstacle-aware
  // distance to the goal within two lattice cells, not falling by a further 0.25 m) before it
  // counts as stuck; 0 = stuck from the outset (the rescue searches run from the first turn).
  std::size_t stall_expansions{1000};
  double curve_weight{0.5};
  double reverse_weight{1.0};
  double direction_change_weight{1.5};    // [m] added per change of driving direction
  double distance_heuristic_weight{2.0};  // Autoware start planner default
  // The obstacle-aware distance charges up to (1 + this) per metre in places with less room than
  // half the footprint's diagonal (see the note above); 0 = the plain distance.
  double narrow_heuristic_penalty{3.0};
  // The heuristic also charges the turning still ahead (see the note above) at this times its
  // least curve cost: curve_weight x turning_radius per radian turned, at the cost factor of the
  // direction the pose faces the way in (and direction_change_weight when that is not the
  // direction it came in); 0 = off.
  double turning_heuristic_weight{0.0};
  // Goal region, in the goal frame: |longitudinal| <= longitudinal_goal_range / 2, ...
  double longitudinal_goal_range{2.0};  // [m]
  double lateral_goal_range{0.5};       // [m]
  double angle_goal_range{0.10472};     // [rad] (6 deg)
  std::size_t max_nodes{4000000};       // memory bound: Status::kNodeLimit when exceeded
  double waypoint_interval{0.25};       // [m] spacing of the returned waypoints (at most)
  // Debugging aid: when set, every expanded pose is appended here, in expansion order (a picture
  // of where the search spent its time). Not thread safe: one plan() per vector.
  std::vector<Pose2>* expanded_poses{nullptr};
};

struct Waypoint {
  Pose2 pose;
  // Direction of travel on the way to this waypoint (+1 forward, -1 reverse); the first waypoint
  // carries the direction of the first motion.
  int direction{1};
};

struct HybridAStarResult {
  enum class Status { kSuccess, kStartOccupied, kGoalOccupied, kTimeout, kCancelled, kNodeLimit, kNoPath };
  Status status{Status::kNoPath};
  StopReason stopped{StopReason::kNone};  // kTimeout / kCancelled: the reason the stop condition gave
  std::vector<Waypoint> waypoints;        // start ... goal (or the pose in the goal region)
  double length{0.0};                     // [m] driven, both directions
  std::size_t expansions{0};
  std::size_t nodes{0};
  std::size_t shots{0};            // Reeds-Shepp analytic expansions tried
  bool reached_exact_goal{false};  // by a Reeds-Shepp shot (else: inside the goal region)
  bool found_from_goal{false};     // by the search from the goal (then the goal is exact)
};

const char* to_string(HybridAStarResult::Status status);

class HybridAStar {
 public:
  // The checker (and its costmap) must outlive the planner.
  HybridAStar(const GridCollisionChecker& checker, const HybridAStarConfig& config);

  HybridAStarResult plan(const Pose2& start, const Pose2& goal, const StopCondition& stop) const;

  const HybridAStarConfig& config() const { return config_; }

 private:
  const GridCollisionChecker& checker_;
  HybridAStarConfig config_;
};

}  // namespace pullout
