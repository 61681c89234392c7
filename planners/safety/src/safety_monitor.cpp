#include "pullout/safety/safety_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pullout/safety/rss_check.hpp"

namespace pullout {
namespace {

// +1 when the segment is driven forward, -1 in reverse (sign of its first non-zero velocity).
bool forward_segment(const PathWithLaneId& segment) {
  for (const PathPoint& p : segment.points) {
    if (p.longitudinal_velocity_mps > 0.0) return true;
    if (p.longitudinal_velocity_mps < 0.0) return false;
  }
  return true;
}

Polyline segment_line(const PathWithLaneId& segment) {
  std::vector<Vec2> points;
  points.reserve(segment.points.size());
  for (const PathPoint& p : segment.points) points.push_back(to_vec(p.pose));
  return Polyline(points);
}

double max_speed(const PathWithLaneId& segment) {
  double v = 0.0;
  for (const PathPoint& p : segment.points) v = std::max(v, std::abs(p.longitudinal_velocity_mps));
  return v;
}

}  // namespace

SafetyMonitor::SafetyMonitor(const SafetyParameters& parameters, const VehicleInfo& vehicle,
                             const std::vector<Lane>& lanes, std::vector<Object> objects, const PullOutPath& path)
    : SafetyMonitor(parameters, vehicle, std::make_shared<const LaneWorld>(lanes), std::move(objects), path) {}

SafetyMonitor::SafetyMonitor(const SafetyParameters& parameters, const VehicleInfo& vehicle,
                             std::shared_ptr<const LaneWorld> lanes, std::vector<Object> objects,
                             const PullOutPath& path)
    : parameters_(parameters),
      footprint_(vehicle_footprint(vehicle)),
      lanes_(std::move(lanes)),
      objects_(std::move(objects)),
      path_(path) {
  if (const auto road = lanes_->nearest_lane(to_vec(path_.end_pose), LaneSubtype::kRoad)) {
    current_ = &lanes_->chain_through(*road);
    if (current_->centerline.size() >= 2) {
      merging_from_left_ = current_->centerline.project(to_vec(path_.start_pose)).lateral >= 0.0;
    } else {
      current_ = nullptr;
    }
  }
}

SafetyMonitor::Gaps SafetyMonitor::gaps(const Vec2& p) const {
  const LaneChain& chain = *current_;
  const LaneGeometry& lane = lanes_->lanes()[chain.lanes[chain.lane_at(chain.centerline.project(p).s)]];
  // Lateral offsets are left-positive; inside the lane: left of the right bound, right of the left.
  const double from_right = lane.right.size() >= 2 ? lane.right.project(p).lateral : 0.0;
  const double from_left = lane.left.size() >= 2 ? -lane.left.project(p).lateral : 0.0;
  // Merging from the left, vehicles from behind pass on the right, and vice versa.
  return merging_from_left_ ? Gaps{from_right, from_left} : Gaps{from_left, from_right};
}

std::vector<Object> SafetyMonitor::targets(const Pose2& ego) const {
  const TargetFilteringParameters& f = parameters_.path_safety_check.target_filtering;
  std::vector<Object> out;
  const double s_ego = current_ ? current_->centerline.project(to_vec(ego)).s : 0.0;
  for (const Object& o : objects_) {
    if (!f.object_types_to_check.includes(o.object_class)) continue;
    if (std::abs(o.velocity_mps) <= f.ignore_object_velocity_threshold) continue;
    const Vec2 p = to_vec(o.pose);
    bool on_lane = false;
    for (const std::size_t i : lanes_->lanes_containing(p)) {
      const LaneGeometry& lane = lanes_->lanes()[i];
      if (lane.subtype == LaneSubtype::kRoadShoulder && f.check_shoulder_lane) on_lane = true;
      if (lane.subtype == LaneSubtype::kRoad && f.check_current_lane && current_ &&
          std::find(current_->lanes.begin(), current_->lanes.end(), i) != current_->lanes.end()) {
        on_lane = true;
      }
    }
    if (!on_lane) continue;
    if (current_) {
      const double ds = current_->centerline.project(p).s - s_ego;
      if (ds > f.object_check_forward_distance || ds < -f.object_check_backward_distance) continue;
    }
    out.push_back(o);
  }
  return out;
}

bool SafetyMonitor::preventing_rear_vehicle(const std::vector<Pose2>& poses) const {
  if (!current_) return false;
  for (const Pose2& pose : poses) {
    // The corner nearest the passing-side bound.
    double min_gap = std::numeric_limits<double>::infinity();
    Gaps nearest;
    for (const Vec2& corner : footprint_corners(footprint_, pose)) {
      const Gaps g = gaps(corner);
      if (g.passing < min_gap) {
        min_gap = g.passing;
        nearest = g;
      }
    }
    if (nearest.passing <= nearest.other) return true;  // over the middle of the lane

    // The nearest target behind the ego on the current lane.
    const double s_ego = current_->centerline.project(to_vec(pose)).s;
    // `rear` points into `candidates`, which must outlive its use below.
    const std::vector<Object> candidates = targets(pose);
    const Object* rear = nullptr;
    double best = std::numeric_limits<double>::infinity();
    for (const Object& o : candidates) {
      const Vec2 p = to_vec(o.pose);
      bool on_current = false;
      for (const std::size_t i : lanes_->lanes_containing(p)) {
        on_current |= std::find(current_->lanes.begin(), current_->lanes.end(), i) != current_->lanes.end();
      }
      const double behind = s_ego - current_->centerline.project(p).s;
      if (!on_current || behind < 0.0 || behind >= best) continue;
      best = behind;
      rear = &o;
    }
    if (rear == nullptr) continue;
    double rear_width = rear->width_m;
    if (!rear->polygon.empty()) {
      double lo = 0.0;
      double hi = 0.0;
      for (const Point2& q : rear->polygon) {
        lo = std::min(lo, q.y);
        hi = std::max(hi, q.y);
      }
      rear_width = hi - lo;
    }
    if (rear_width + parameters_.extra_width_margin_for_rear_obstacle > std::max(min_gap, 0.0)) return true;
  }
  return false;
}

SafetyVerdict SafetyMonitor::evaluate(const Pose2& ego, double velocity, std::uint32_t segment_idx, bool departed) {
  SafetyVerdict verdict;
  if (path_.partial_paths.empty()) return verdict;
  if (!departed) {
    if (const auto id = moving_object_around(ego, objects_, parameters_.surround_moving_obstacle_check)) {
      verdict.safe = false;
      verdict.object_id = *id;
      verdict.reason = "nearby moving object risk: object " + std::to_string(*id);
      previous_safe_ = false;
      return verdict;
    }
  }
  const auto idx = std::min<std::size_t>(segment_idx, path_.partial_paths.size() - 1);
  const PathWithLaneId& segment = path_.partial_paths[idx];
  const SafetyCheckParams& check = parameters_.path_safety_check.safety_check_params;
  if (!check.enable_safety_check || !forward_segment(segment) || segment.points.size() < 2) {
    previous_safe_ = true;
    return verdict;
  }
  const Polyline line = segment_line(segment);
  if (line.size() < 2) return verdict;
  const double v0 = std::max(velocity, 0.0);

  if (!parameters_.skip_rear_vehicle_check) {
    const StopProfile stop(v0, parameters_.stop_condition.maximum_deceleration_for_stop,
                           parameters_.stop_condition.maximum_jerk_for_stop);
    const double s_ego = line.project(to_vec(ego)).s;
    verdict.preventing_rear = preventing_rear_vehicle({ego, line.pose_at(s_ego + stop.distance())});
    if (verdict.preventing_rear) {
      previous_safe_ = true;
      return verdict;
    }
  }

  const TerminalVelocityAccel pair = idx < path_.pairs_terminal_velocity_and_accel.size()
                                         ? path_.pairs_terminal_velocity_and_accel[idx]
                                         : TerminalVelocityAccel{};
  const EgoPredictedPathParameters& ego_params = parameters_.path_safety_check.ego_predicted_path;
  const double max_velocity = pair.velocity_mps > 0.0 ? pair.velocity_mps : max_speed(segment);
  const double accel = std::max(pair.accel_mps2, ego_params.min_acceleration);
  const auto ego_path = predict_ego_motion(line, ego, v0, max_velocity, accel, ego_params);
  const double hysteresis = previous_safe_ ? 1.0 : check.hysteresis_factor_expand_rate;
  const RssVerdict rss =
      check_rss(ego_path, footprint_, targets(ego), parameters_.path_safety_check.target_filtering, check, hysteresis);
  verdict.rss_checked = true;
  verdict.safe = rss.safe;
  verdict.object_id = rss.object_id;
  if (!rss.safe) verdict.reason = "dynamic object risk: " + rss.reason;
  previous_safe_ = rss.safe;
  return verdict;
}

}  // namespace pullout
