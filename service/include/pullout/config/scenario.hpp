// Scenario files: one YAML format for the CLI, the tests and the benchmarks (see DESIGN.md).
//
//   vehicle: {wheel_base: 2.79, ...}          # optional, overrides the config's vehicle (and the
//                                             # request carries it), or {profile: bus}: a profile of
//                                             # the config's vehicle_profiles, named in the request
//   map: ../maps/straight_shoulder.osm        # Lanelet2 map, relative to this file ...
//   route: [101, 102, 103]                    # ... and the road lanelets to pull out onto, or
//                                             # Autoware route segments: [{preferred: 101,
//                                             #   primitives: [101, 111]}, ...]; or instead:
//   lanes:                                    # inline lanes
//     - {id: 1, subtype: road, speed_limit: 13.9,
//        left_bound: [[0, 1.75], [100, 1.75]], right_bound: [[0, -1.75], [100, -1.75]],
//        centerline: [[0, 0], [100, 0]]}       # centerline optional
//   start: {x: 10.0, y: 3.5, yaw_deg: 0.0}    # yaw [rad] or yaw_deg
//   start_velocity: 0.0                       # optional [m/s]
//   goal:  {x: 90.0, y: 0.0, yaw_deg: 0.0}
//   objects:
//     - {id: 7, class: car, x: 20.0, y: 3.5, yaw_deg: 0, length: 4.5, width: 1.9, velocity: 0.0,
//        predicted_paths: [{time_step: 1.0, confidence: 1.0, points: [[20, 3.5], [20, 3.5]]}]}
//        # optional; each pose heads to the next point. Without one, the safety check assumes
//        # constant velocity along the object's heading.
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
//   fleet:                                    # optional: other vehicles on the same lanes and
//     - {vehicle_id: fleet-a, start: {x: 20, y: 3.25, yaw_deg: 0}, goal: {x: 90, y: 0, yaw_deg: 0},
//        vehicle: {profile: van}}             #   objects, planned, approved and executing (in this
//                                             #   order) when this vehicle asks and departs
//   expect: {found: true, planner: shift, safe: true}   # optional, used by tests; safe: the
//                                             # safety verdict at the start, before departure;
//                                             # stops_before_object: 7, the published path stops
//                                             # before object 7 beyond the end pose;
//                                             # waits_for: fleet-a, the approved vehicle waits for
//                                             # that fleet vehicle ("": departs at once)
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pullout/config/config.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

class LaneletMap;

struct ScenarioExpectation {
  std::optional<bool> found;
  std::optional<PlannerType> planner;
  std::optional<double> margin_m;  // the collision margin the winning attempt used
  // The dynamic safety verdict for the found path at the start, before departure (approved).
  std::optional<bool> safe;
  // The published path is cut and stops (velocity 0) before this static object, beyond the end
  // pose (`stops_before_object: 7`).
  std::optional<std::int64_t> stops_before_object;
  // With `fleet:`: the vehicle the approved vehicle waits for while the fleet drives ("": none).
  std::optional<std::string> waits_for;
};

struct Scenario {
  std::string path;  // the file it was loaded from
  std::string description;
  PullOutRequest request;                 // vehicle_id, ego pose, goal, lanes or route, objects, deadline
  std::string map_path;                   // `map:` made absolute; empty when the scenario has none
  std::shared_ptr<const LaneletMap> map;  // loaded from map_path (null without)
  VehicleInfo vehicle;                    // base config's vehicle with the scenario's overrides
  StartPlannerParameters parameters;      // base config's parameters with `planner:` applied
  // The `planner:` keys a request does not carry (all but search_priority and search_policy),
  // dotted ("freespace_planner.vehicle_shape_margin"): `pullout plan` applies them, a running
  // service plans with its own parameters (`pullout request` names them).
  std::vector<std::string> local_planner_keys;
  ScenarioExpectation expect;
  // `fleet:`: the other vehicles' requests (this scenario's lanes and objects, their own id, start,
  // goal and vehicle), executing their paths in this order before `request` is planned.
  std::vector<PullOutRequest> fleet;
};

// Loads a scenario on top of `base` (vehicle and start_planner come from it unless overridden),
// and its map when it names one. Throws ConfigError naming every malformed field ("<file>:
// lanes[0].left_bound[3]: expected [x, y]", "<file>: map: <map file>: <problem>") or if the file
// cannot be read. A `route:` without `map:` is allowed: a running service plans it on its own map.
Scenario load_scenario(const std::string& path, const Config& base = Config{});

}  // namespace pullout
