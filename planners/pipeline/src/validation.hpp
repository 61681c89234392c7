// Internal: request validation steps used by StartPlanner.
#pragma once

#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/parameters.hpp"

namespace pullout {

// Checks that need no world: finite numbers, sizes within the limits, non-degenerate lanes,
// known planners; route ids only when a map is loaded (`has_map`), and not together with lanes.
// With `allow_grid_only` (the freespace planner is enabled) a request with an occupancy grid and no
// lanes is valid: a pure freespace problem.
std::vector<RequestIssue> validate_request_structure(const PullOutRequest& request, const RequestLimits& limits,
                                                     const std::vector<PlannerType>& available, bool has_map,
                                                     bool allow_grid_only = false);

// A progress sample's pose (finite, within max_coordinate_m) and speed (finite, within
// max_speed_mps): what the safety check and the stop it inserts are computed from.
std::vector<RequestIssue> validate_progress(const ExecutionProgress& progress, const RequestLimits& limits);

}  // namespace pullout
