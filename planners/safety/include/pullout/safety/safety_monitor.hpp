// The dynamic-object safety of one vehicle's found path, evaluated on each odometry sample.
//
// Built once per found path from the request (lanes, objects) and the path; the objects are
// replaced by each re-sent request (update_objects). evaluate() answers, for the vehicle's current
// pose and speed and the segment it is on:
//   - before departure, "nearby moving object risk" when an object of a checked class within
//     surround_moving_obstacle_check.search_radius moves faster than th_moving_obstacle_velocity;
//   - on forward segments (never in reverse), "dynamic object risk" when the RSS check
//     (rss_check.hpp) of the ego's predicted motion fails against a target object: an object of a
//     checked class, faster than ignore_object_velocity_threshold, on the current road lanes (the
//     chain of lanes through the road lane nearest the path's end pose) or on a road shoulder,
//     between object_check_backward_distance behind and object_check_forward_distance ahead.
// Rear-vehicle "preventing" bypass (unless skip_rear_vehicle_check): the RSS check is not run
// when, at the ego's pose or at its estimated stop pose (the jerk-limited stop of stop_condition.*
// along the segment), the ego already blocks the current lane for a vehicle coming from behind:
// its footprint corner nearest the bound on the passing side (the side away from where it merges
// from) is not farther from that bound than from the opposite bound (it has crossed the lane's
// middle), or the nearest target behind it on the current lane is wider, plus
// extra_width_margin_for_rear_obstacle, than the gap between the footprint and that bound.
// The verdict of the previous call sets the RSS hysteresis.
//
// Not thread-safe: one monitor per vehicle, used under the caller's lock.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/model/types.hpp"
#include "pullout/safety/safety_parameters.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout {

struct SafetyVerdict {
  bool safe{true};
  bool rss_checked{false};      // the RSS check ran (forward segment, enabled, not bypassed)
  bool preventing_rear{false};  // the ego blocks the lane for a vehicle from behind
  std::int64_t object_id{0};    // the object that made it unsafe
  std::string reason;           // "nearby moving object risk: ...", "dynamic object risk: ..."
};

class SafetyMonitor {
 public:
  // `path` must be a found path; `lanes` and `objects` from its request.
  SafetyMonitor(const SafetyParameters& parameters, const VehicleInfo& vehicle, const std::vector<Lane>& lanes,
                std::vector<Object> objects, const PullOutPath& path);
  // The same on a lane world already built from those lanes (the one the path was planned on,
  // PlannedWorld::lane_world), shared instead of built again. `lanes` must not be null and must be
  // complete (not stopped).
  SafetyMonitor(const SafetyParameters& parameters, const VehicleInfo& vehicle, std::shared_ptr<const LaneWorld> lanes,
                std::vector<Object> objects, const PullOutPath& path);

  void update_objects(std::vector<Object> objects) { objects_ = std::move(objects); }

  // The verdict for the vehicle at `ego` moving at `velocity` on segment `segment_idx`;
  // `departed` false runs the surrounding-moving-object check too.
  SafetyVerdict evaluate(const Pose2& ego, double velocity, std::uint32_t segment_idx, bool departed);

  // Whether the ego at these poses blocks the current lane for the nearest target behind it (the
  // bypass above). Exposed for tests.
  bool preventing_rear_vehicle(const std::vector<Pose2>& poses) const;
  // The targets of the RSS check for the ego at `ego`. Exposed for tests.
  std::vector<Object> targets(const Pose2& ego) const;

 private:
  // Signed gap [m] from p to the lane bound on the passing side (positive inside the lane) and to
  // the opposite bound, on the current lane at p.
  struct Gaps {
    double passing{0.0};
    double other{0.0};
  };
  Gaps gaps(const Vec2& p) const;

  SafetyParameters parameters_;
  Footprint footprint_;
  std::shared_ptr<const LaneWorld> lanes_;  // immutable: may be shared with the planned world
  std::vector<Object> objects_;
  PullOutPath path_;
  const LaneChain* current_{nullptr};  // the road lanes the path merges into (in lanes_)
  bool merging_from_left_{true};
  bool previous_safe_{true};
};

}  // namespace pullout
