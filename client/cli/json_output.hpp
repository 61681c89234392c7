// The `--json` output of the pullout CLI: ONE JSON object per run.
//
//   {
//     "found": true,
//     "planner": "shift",                     // pullout::to_string(PlannerType)
//     "state": "waiting_approval",            // pullout::to_string(ExecutionState): planning,
//                                             // rejected, no_path, waiting_approval,
//                                             // waiting_safety, executing, completed
//     "stop_reason": "waiting approval",       // why the vehicle must stand ("" when executing)
//     "turn_signal": "right",                  // none | left | right
//     "safe": true,                            // dynamic safety at the last progress sample
//     "segments": [{"points": 42, "direction": "forward" | "reverse",
//                   "terminal_velocity": 2.7, "terminal_acceleration": 0.0,   // null if unknown
//                   "length": 40.1,            // [m/s], [m/s^2], [m]
//                   "path": [{"x": 10.0, "y": 3.25, "yaw": 0.0, "velocity": 2.7}, ...]}],
//                                              // every point ("points" of them), in driving
//                                              // order: [m], [rad], [m/s] (negative reversing)
//     "start_pose": {"x": 0.0, "y": 0.0, "yaw": 0.0},   // [m], [rad]; null without a path
//     "end_pose":   {"x": 0.0, "y": 0.0, "yaw": 0.0},
//     "evaluation_table": [{"planner": "shift", "margin": 2.0, "backward_distance": 0.0,   // [m]
//                           "outcome": "collision",     // success | collision | lane_departure |
//                           // no_geometry | start_invalid | goal_invalid | timeout | cancelled |
//                           // node_limit | no_path
//                           "detail": "object 7 (4/4 candidates)"}],   // "" when none
//     "planning_time_ms": 3.2,
//     "reasons": ["..."],                      // why nothing was found; found: how the path ends
//     "error": ""                              // rejected: "<field>: <problem>" lines
//   }
//
// Keys keep the order above (nlohmann::ordered_json). Non-finite numbers are written as null.
#pragma once

#include <nlohmann/json.hpp>

#include "report.hpp"

namespace pullout::cli {

nlohmann::ordered_json to_json(const PlanReport& report);

}  // namespace pullout::cli
