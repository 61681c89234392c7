// The path published when a departed vehicle must stop because traffic became unsafe: the same
// path with its velocities capped by a jerk-limited stop (stop_condition.*) from the vehicle's
// current speed and position on its current segment; every later segment gets velocity 0.
#pragma once

#include <cstdint>

#include "pullout/model/types.hpp"
#include "pullout/safety/safety_parameters.hpp"

namespace pullout {

// `path` is a found path, `segment_idx` the vehicle's current segment, `ego` and `velocity` its
// odometry. The result keeps every field of `path` except the velocities (and terminal pairs of
// the current and later segments, set to (0, 0)). Distance along the segment is measured from the
// projection of `ego`; points behind it keep min(their speed, |velocity|).
PullOutPath insert_feasible_stop(const PullOutPath& path, std::uint32_t segment_idx, const Pose2& ego, double velocity,
                                 const StopConditionParameters& p);

}  // namespace pullout
