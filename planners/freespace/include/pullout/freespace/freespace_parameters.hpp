// Parameters of the freespace pull-out (hybrid A*), Autoware's `freespace_planner.` group (see
// config/pullout.yaml); StartPlannerParameters::freespace_planner holds them. Unlike Autoware,
// every key here is used. Validated by validate_parameters().
#pragma once

#include <string>

namespace pullout {

struct FreespaceParameters {
  bool enable_freespace_planner{true};               // fallback when the lane-based search finds nothing
  std::string freespace_planner_algorithm{"astar"};  // "astar" (hybrid A*) or "rrtstar" (RRT*, freespace_ompl)
  double end_pose_search_start_distance{20.0};       // [m] end poses on the road centerline from s(ego) + this ...
  double end_pose_search_end_distance{30.0};         // [m] ... to s(ego) + this
  double end_pose_search_interval{2.0};              // [m] spacing of the end poses
  double velocity{1.0};                              // [m/s] speed on the freespace path
  double vehicle_shape_margin{1.0};                  // [m] added to the vehicle's length and width (half each side)
  double time_limit{3000.0};                         // [ms] search budget (the request deadline may cut it shorter)
  double max_turning_ratio{0.7};                     // x max_steer_angle for the primitives (0, 1]
  int turning_steps{1};                              // steering angles per side
  // Not in Autoware: smooth each direction segment of the path, cusps kept (path_smoother.hpp).
  bool smooth_path{true};
  struct SearchConfigs {
    int theta_size{120};                  // heading bins of the lattice
    double angle_goal_range{6.0};         // [deg] goal region width in heading
    double lateral_goal_range{0.5};       // [m]
    double longitudinal_goal_range{2.0};  // [m]
    double curve_weight{0.5};             // extra cost per metre at full steer
    double reverse_weight{1.0};           // extra cost per metre reversing
    double direction_change_weight{1.5};  // [m] cost of a change of direction
  } search_configs;
  struct CostmapConfigs {
    int obstacle_threshold{30};  // occupancy grid values >= this (or unknown) are obstacles
    double resolution{0.2};      // [m] cells of the costmap built from lanes and objects
  } costmap_configs;
  struct Astar {
    bool use_back{true};                    // reverse primitives
    double distance_heuristic_weight{2.0};  // > 1: faster, less optimal (Autoware default)
    double expansion_distance{0.5};         // [m] arc length of a motion primitive
    // Not in Autoware: the obstacle-aware heuristic charges up to (1 + this) per metre through
    // places narrower than the vehicle needs to turn (see hybrid_astar.hpp); 0 = plain distance.
    double narrow_heuristic_penalty{3.0};
    // Not in Autoware: the heuristic also charges the turning still ahead on the obstacle-aware
    // way, at this times its least curve cost (see hybrid_astar.hpp); 0 = off.
    double turning_heuristic_weight{0.0};
    // Not in Autoware: the rescue searches of a stuck search (see hybrid_astar.hpp). At nodes in
    // a tight spot, primitives that collide are driven until contact when that is at least this
    // long [m] (0 = off, and no rescue searches at all); search_from_goal adds the search from a
    // goal in a tight spot; stall_expansions is how long the plain search may make no progress
    // near the goal before they join it.
    double min_expansion_distance{0.1};
    bool search_from_goal{true};
    int stall_expansions{1000};
  } astar;
};

}  // namespace pullout
