#include "pullout/session/fleet.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "pullout/geometry/angle.hpp"
#include "pullout/geometry/polyline.hpp"
#include "pullout/safety/rss_check.hpp"

namespace pullout {
namespace {

// The remaining poses of a path: from the point of segment `idx` nearest `pose` to the end, each
// with its |velocity| from the profile.
struct Remaining {
  std::vector<Pose2> poses;
  std::vector<double> speeds;
};

Remaining remaining(const PullOutPath& path, std::uint32_t idx, const Pose2& pose) {
  Remaining r;
  if (path.partial_paths.empty()) return r;
  const std::size_t first_segment = std::min<std::size_t>(idx, path.partial_paths.size() - 1);
  std::size_t first_point = nearest_point(path, static_cast<std::uint32_t>(first_segment), pose);
  for (std::size_t s = first_segment; s < path.partial_paths.size(); ++s) {
    const auto& points = path.partial_paths[s].points;
    for (std::size_t i = s == first_segment ? first_point : 0; i < points.size(); ++i) {
      r.poses.push_back(points[i].pose);
      r.speeds.push_back(std::abs(points[i].longitudinal_velocity_mps));
    }
    first_point = 0;
  }
  return r;
}

Pose2 interpolate(const Pose2& a, const Pose2& b, double f) {
  return {a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f, a.yaw + normalize_angle(b.yaw - a.yaw) * f};
}

// The remaining poses resampled every kFleetTimeStep: each stretch between two points takes its
// length over the mean of their speeds (at least kFleetMinTimingSpeed).
std::vector<Pose2> timed_poses(const Remaining& r) {
  std::vector<Pose2> out;
  if (r.poses.empty()) return out;
  out.push_back(r.poses.front());
  double t = 0.0;  // time at r.poses[i]
  double next = kFleetTimeStep;
  for (std::size_t i = 0; i + 1 < r.poses.size() && out.size() < kFleetMaxPredictedSamples; ++i) {
    const double ds = std::hypot(r.poses[i + 1].x - r.poses[i].x, r.poses[i + 1].y - r.poses[i].y);
    const double v = std::max(0.5 * (r.speeds[i] + r.speeds[i + 1]), kFleetMinTimingSpeed);
    const double dt = ds / v;
    while (next <= t + dt && out.size() < kFleetMaxPredictedSamples) {
      out.push_back(interpolate(r.poses[i], r.poses[i + 1], dt > 0.0 ? (next - t) / dt : 1.0));
      next += kFleetTimeStep;
    }
    t += dt;
  }
  if (out.size() < kFleetMaxPredictedSamples) out.push_back(r.poses.back());  // it ends standing there
  return out;
}

}  // namespace

std::size_t nearest_point(const PullOutPath& path, std::uint32_t segment_idx, const Pose2& pose) {
  if (path.partial_paths.empty()) return 0;
  const auto& points = path.partial_paths[std::min<std::size_t>(segment_idx, path.partial_paths.size() - 1)].points;
  std::size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = std::hypot(points[i].pose.x - pose.x, points[i].pose.y - pose.y);
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

FleetObstacle fleet_obstacle(const ExecutingPath& other, bool with_path, std::int64_t object_id) {
  FleetObstacle o;
  o.vehicle_id = other.vehicle_id;
  const Footprint footprint = vehicle_footprint(other.vehicle);
  Object& object = o.object;
  object.id = object_id;
  object.object_class = ObjectClass::kCar;
  object.pose = other.pose;
  object.length_m = footprint.length();
  object.width_m = footprint.width();
  // The footprint in base_link, counter-clockwise (footprint_corners' order).
  object.polygon = {{footprint.front, footprint.left},
                    {-footprint.rear, footprint.left},
                    {-footprint.rear, -footprint.right},
                    {footprint.front, -footprint.right}};
  object.velocity_mps = std::abs(other.velocity_mps);
  if (!with_path) return o;
  const Remaining r = remaining(other.path, other.current_path_idx, other.pose);
  o.swept.reserve(r.poses.size());
  for (const Pose2& p : r.poses) o.swept.push_back(footprint_polygon(footprint, p));
  PredictedPath predicted;
  predicted.time_step_s = kFleetTimeStep;
  predicted.confidence = 1.0;
  predicted.poses = timed_poses(r);
  if (predicted.poses.size() >= 2) object.predicted_paths.push_back(std::move(predicted));
  return o;
}

std::optional<FleetConflict> first_fleet_conflict(const PullOutPath& path, std::uint32_t segment_idx, const Pose2& ego,
                                                  const VehicleInfo& vehicle, double clearance,
                                                  const std::vector<FleetObstacle>& fleet) {
  if (fleet.empty()) return std::nullopt;
  const Footprint footprint = vehicle_footprint(vehicle, clearance);
  Remaining own = remaining(path, segment_idx, ego);
  own.poses.insert(own.poses.begin(), ego);  // where it stands now counts too
  std::vector<Polygon> sweep;
  std::vector<Aabb> sweep_boxes;
  Aabb all;
  sweep.reserve(own.poses.size());
  for (const Pose2& p : own.poses) {
    sweep.push_back(footprint_polygon(footprint, p));
    sweep_boxes.push_back(bounding_box(sweep.back()));
    all.extend(sweep_boxes.back().min);
    all.extend(sweep_boxes.back().max);
  }
  for (const FleetObstacle& other : fleet) {
    std::vector<Polygon> theirs = other.swept;
    theirs.push_back(object_polygon(other.object));  // its body
    for (const Polygon& polygon : theirs) {
      const Aabb box = bounding_box(polygon);
      if (!box.overlaps(all)) continue;
      for (std::size_t i = 0; i < sweep.size(); ++i) {
        if (box.overlaps(sweep_boxes[i]) && polygons_intersect(sweep[i], polygon)) {
          return FleetConflict{other.vehicle_id, other.object.id};
        }
      }
    }
  }
  return std::nullopt;
}

void FleetBoard::update(ExecutingPath entry) {
  const std::string id = entry.vehicle_id;
  auto it = entries_.find(id);
  if (it == entries_.end()) {
    it = entries_.emplace(id, Entry{}).first;
    it->second.order = next_order_++;
  }
  Entry& e = it->second;
  e.path = std::move(entry);
  e.bounds = Aabb{};
  e.bounds.extend(to_vec(e.path.pose));
  const Remaining r = remaining(e.path.path, e.path.current_path_idx, e.path.pose);
  for (const Pose2& p : r.poses) e.bounds.extend(to_vec(p));
  e.bounds = e.bounds.inflated(vehicle_footprint(e.path.vehicle).bounding_radius());
}

void FleetBoard::remove(const std::string& vehicle_id) { entries_.erase(vehicle_id); }

std::vector<FleetObstacle> FleetBoard::obstacles_for(const std::string& vehicle_id, const Pose2& ego,
                                                     double radius) const {
  std::vector<FleetObstacle> out;
  const auto self = entries_.find(vehicle_id);
  const std::uint64_t own_order =
      self == entries_.end() ? std::numeric_limits<std::uint64_t>::max() : self->second.order;
  std::int64_t next_id = -1;
  for (const auto& [id, entry] : entries_) {
    if (id == vehicle_id) continue;
    const std::int64_t object_id = next_id--;
    if (!entry.bounds.inflated(radius).contains(to_vec(ego))) continue;
    out.push_back(fleet_obstacle(entry.path, entry.order < own_order, object_id));
  }
  return out;
}

}  // namespace pullout
