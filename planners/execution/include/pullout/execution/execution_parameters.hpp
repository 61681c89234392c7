// Parameters of the execution tracker (execution_tracker.hpp): when a segment counts as done.
// Names follow Autoware's start_planner.param.yaml (flat keys); StartPlannerParameters derives
// from this struct. Validated by validate_parameters().
#pragma once

namespace pullout {

struct ExecutionParameters {
  double th_arrived_distance{1.0};   // [m] segment end reached within this distance
  double th_stopped_velocity{0.01};  // [m/s] |v| below this counts as stopped
  double th_stopped_time{1.0};       // [s] stopped for this long before a segment counts as done
};

}  // namespace pullout
