// Parameters of the start planner. Names follow Autoware's start_planner.param.yaml where the
// concept is the same (see config/pullout.yaml), defaults are the same as that file's. The core
// assumes valid parameters: each key's allowed values are checked by the config tables
// (pullout::check_config, load_config), the checks between keys by validate_parameters().
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pullout/collision/object_types.hpp"
#include "pullout/execution/execution_parameters.hpp"
#include "pullout/freespace/freespace_parameters.hpp"
#include "pullout/lane_planners/lane_planner_parameters.hpp"
#include "pullout/model/types.hpp"
#include "pullout/safety/safety_parameters.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout {

// The start planner's parameters: every module's own struct (the flat keys of the execution
// tracker, the lane planners and the safety checks as base classes, so that each key stays a
// direct member as in Autoware's file), the freespace group, and the search's own keys.
struct StartPlannerParameters : ExecutionParameters, LanePlannerParameters, SafetyParameters {
  // --- search ---
  std::vector<double> collision_check_margins{2.0, 1.0, 0.5, 0.1};                         // [m] tried in order
  std::vector<PlannerType> search_priority{PlannerType::kShift, PlannerType::kGeometric};  // in order
  SearchPolicy search_policy{SearchPolicy::kPlannerPriority};

  // --- objects considered by path generation ---
  double th_moving_object_velocity{1.0};  // [m/s] objects slower than this are static obstacles
  ObjectTypesToCheck object_types_to_check_for_path_generation;

  // --- backward start-pose search ---
  bool enable_back{true};
  double max_back_distance{20.0};                        // [m]
  double backward_search_resolution{2.0};                // [m] spacing of start candidates
  double collision_check_margin_from_front_object{5.0};  // [m] candidates this close to an object ahead are skipped
  double ignore_distance_from_lane_end{0.0};             // [m] candidates this close to the lane end are skipped
  double backward_velocity{-1.0};                        // [m/s] < 0, speed of the reverse segment

  // --- approval, re-planning ---
  double prepare_time_before_start{0.0};      // [s] turn signal on this long before departure
  double backward_path_update_duration{3.0};  // [s] a re-sent request re-plans at most this often

  // --- freespace pull-out ---
  FreespaceParameters freespace_planner;
};

// Whether this version of the core implements a planner (search_priority may only name these).
bool planner_available(PlannerType type);

// One problem with a parameter: the parameter's name and what is wrong.
struct ParameterIssue {
  std::string name;
  std::string problem;
};

// The checks that involve more than one parameter (maximum >= minimum) and search_priority
// entries this version does not implement; names are config key paths. Empty when valid.
std::vector<ParameterIssue> validate_parameters(const StartPlannerParameters& p);

// Limits on the size of a request, so that one vehicle cannot make the service allocate or compute
// without bound. Defaults are generous for real use. A request beyond any of them is rejected, the
// field named ("lanes[0].left_bound[1].x: |x| 1e+20 exceeds 1e+07 m").
//
// Work that grows with the lanes' length is bounded by cropping them to the planning horizon
// (planning_horizon_m, start_planner.hpp) before anything is built; what the crop keeps is then
// bounded by max_horizon_lane_length_m, and coordinates by max_coordinate_m (so that distances
// and the crop's bisection stay well within double precision).
struct RequestLimits {
  std::size_t max_lanes{256};
  std::size_t max_points_per_line{10000};  // points in one bound or centerline
  std::size_t max_objects{512};
  std::size_t max_polygon_points{64};          // points of one object polygon
  std::size_t max_predicted_paths{16};         // per object
  std::size_t max_predicted_path_points{200};  // per predicted path
  std::size_t max_route_lanelets{1000};
  std::size_t max_grid_cells{std::size_t{16} * 1024 * 1024};
  double max_deadline_ms{10000.0};
  // [m] |x| and |y| of every point and pose (lanes, ego, goal, objects and their polygons and
  // predicted paths, the grid origin), and object lengths and widths. 1e7 m: the size of a UTM zone.
  double max_coordinate_m{1e7};
  // [m] Total length of the lanes' bounds (left + right, every lane) inside the planning horizon,
  // after the crop. A straight lane crossing the horizon keeps about 2 x 2 x 400 m; the default
  // admits several hundred of those, and bounds the zig-zag lanes no crop can shorten.
  double max_horizon_lane_length_m{500000.0};
  // [m/s] |speed| a request or a progress sample may report: ego_velocity_mps, every object's
  // velocity_mps, a progress sample's velocity_mps. The safety check's stop profile and the ego and
  // object predictions grow with the speed; 100 m/s (360 km/h) is beyond any road vehicle.
  double max_speed_mps{100.0};
};

}  // namespace pullout
