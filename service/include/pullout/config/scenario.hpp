// Scenario files: one YAML format for the CLI, the tests and the benchmarks (see DESIGN.md).
//
//   vehicle: {wheel_base: 2.79, ...}          # optional, overrides the config's vehicle
//   lanes:                                    # inline lanes (or map + route, not yet supported)
//     - {id: 1, subtype: road, speed_limit: 13.9,
//        left_bound: [[0, 1.75], [100, 1.75]], right_bound: [[0, -1.75], [100, -1.75]],
//        centerline: [[0, 0], [100, 0]]}       # centerline optional
//   start: {x: 10.0, y: 3.5, yaw_deg: 0.0}    # yaw [rad] or yaw_deg
//   start_velocity: 0.0                       # optional [m/s]
//   goal:  {x: 90.0, y: 0.0, yaw_deg: 0.0}
//   objects:
//     - {id: 7, class: car, x: 20.0, y: 3.5, yaw_deg: 0, length: 4.5, width: 1.9, velocity: 0.0}
//   grid:                                     # optional occupancy grid (freespace planner):
//     map: lot.yaml                           #   a ROS map_server YAML beside its PGM image, or
//     resolution: 0.2                         #   [m] obstacle shapes on an extent:
//     origin: {x: 0, y: 0, yaw_deg: 0}
//     size: [30, 30]                          #   [m] width, height
//     obstacles: [{x: 5, y: 5, yaw_deg: 0, length: 4.5, width: 1.9}, {polygon: [[0, 0], [1, 0], [0, 1]]}]
//                                             # with a grid, lanes may be omitted: a pure freespace
//                                             # problem straight to the goal
//   planner:                                  # any start_planner parameter, overriding the config
//     search_priority: [shift]
//   deadline_ms: 200                          # optional
//   vehicle_id: demo-1                        # optional
//   description: "..."                        # optional, free text
//   expect: {found: true, planner: shift}     # optional, used by tests
#pragma once

#include <optional>
#include <string>

#include "pullout/config/config.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

struct ScenarioExpectation {
  std::optional<bool> found;
  std::optional<PlannerType> planner;
  std::optional<double> margin_m;  // the collision margin the winning attempt used
};

struct Scenario {
  std::string path;  // the file it was loaded from
  std::string description;
  PullOutRequest request;             // vehicle_id, ego pose, goal, lanes, objects, deadline
  VehicleInfo vehicle;                // base config's vehicle with the scenario's overrides
  StartPlannerParameters parameters;  // base config's parameters with `planner:` applied
  ScenarioExpectation expect;
};

// Loads a scenario on top of `base` (vehicle and start_planner come from it unless overridden).
// Throws ConfigError naming every malformed field ("<file>: lanes[0].left_bound[3]: expected
// [x, y]") or if the file cannot be read.
Scenario load_scenario(const std::string& path, const Config& base = Config{});

}  // namespace pullout
