// The building blocks of the dynamic-object safety check: the ego's predicted motion along its
// current segment, the objects' predicted paths resampled in time, the RSS check between the two,
// the jerk-limited stop profile, and the "moving object nearby" test.
//
// RSS check (per object, per predicted path, at every object sample time t that the ego
// prediction covers):
//   - objects whose heading differs from the ego's by more than collision_check_yaw_diff_threshold
//     are skipped at that time;
//   - footprints that intersect are unsafe;
//   - otherwise the vehicle behind (rear) and ahead (front) are determined (the object is ahead when
//     its centre is ahead of the ego's base_link) and
//       d_rss = v_rear (t_react + t_margin) + v_rear^2 / (2 |b_rear|) - v_front^2 / (2 |b_front|),
//       d_min = longitudinal_velocity_delta_time * max(v_ego, v_obj) + longitudinal_distance_min_threshold,
//       lon = max(d_rss, d_min) * hysteresis, lat = lateral_distance_max_threshold * hysteresis;
//     the rear vehicle's footprint is extended forward by lon and sideways by lat on each side
//     (rectangle in its heading); unsafe when it intersects the front vehicle's footprint.
// `hysteresis` is 1 while the previous verdict was safe, else hysteresis_factor_expand_rate.
// The "along_path" policy is approximated by the rectangle (the ego's segment is nearly straight
// over the extension in pull-out situations).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/polyline.hpp"
#include "pullout/model/types.hpp"
#include "pullout/safety/safety_parameters.hpp"

namespace pullout {

struct TimedPose {
  double t{0.0};  // [s] from now
  Pose2 pose;
  double velocity{0.0};  // [m/s] >= 0
};

// The ego's motion along `segment` (forward) from its projection of `ego`: standing still for
// delay_until_departure, then from v0 with acceleration `accel` up to `max_velocity` (the speed is
// clamped to [min_velocity, max_velocity] and the distance integrates the clamped speed). Samples
// every time_resolution for t < max(time_horizon_for_front_object, time_horizon_for_rear_object).
// Beyond the segment's end the poses continue straight.
std::vector<TimedPose> predict_ego_motion(const Polyline& segment, const Pose2& ego, double v0, double max_velocity,
                                          double accel, const EgoPredictedPathParameters& p);

// The object's predicted path sampled every safety_check_time_resolution up to
// safety_check_time_horizon (linear interpolation; the object's speed is |velocity_mps|).
// An empty `path` means a constant-velocity straight line along the object's heading.
std::vector<TimedPose> sample_object_path(const Object& object, const PredictedPath* path,
                                          const TargetFilteringParameters& p);

// d_rss above [m] (may be negative when the front vehicle is much faster).
double rss_distance(double v_front, double v_rear, const RssParameters& p);
// max(d_rss, d_min) [m].
double rss_longitudinal_offset(double v_front, double v_rear, double v_ego, double v_object, const RssParameters& p);

// True when the convex polygons a and b overlap or touch.
bool polygons_intersect(const Polygon& a, const Polygon& b);

struct RssVerdict {
  bool safe{true};
  std::int64_t object_id{0};  // the first object found unsafe
  double time_s{0.0};         // when
  std::string reason;         // "collision with object 7 at t = 2.0 s", "RSS distance to object 7 ..."
};

// The RSS check of the ego prediction against every predicted path of `targets` (all of them, or
// the most confident one per object when !use_all_predicted_path).
RssVerdict check_rss(const std::vector<TimedPose>& ego_path, const Footprint& ego_footprint,
                     const std::vector<Object>& targets, const TargetFilteringParameters& filtering,
                     const SafetyCheckParams& p, double hysteresis);

// A jerk-limited stop from v0 >= 0 with zero initial acceleration: the deceleration ramps up at
// max_jerk to max_deceleration and holds until the speed is 0. Sampled every 5 ms, or coarser for a
// stop longer than 20 s, so that it holds at most about 4,100 samples for any speed.
class StopProfile {
 public:
  StopProfile(double v0, double max_deceleration, double max_jerk);
  double distance() const { return distance_; }  // [m] travelled until stopped
  std::size_t samples() const { return s_.size(); }
  // Speed [m/s] after travelling s metres (0 from distance() on).
  double velocity_at(double s) const;

 private:
  std::vector<double> s_;
  std::vector<double> v_;
  double distance_{0.0};
};

// The first object of a checked class within `search_radius` of the ego's base_link moving faster
// than th_moving_obstacle_velocity, if any (its id).
std::optional<std::int64_t> moving_object_around(const Pose2& ego, const std::vector<Object>& objects,
                                                 const SurroundMovingObstacleCheckParameters& p);

}  // namespace pullout
