#include "svg_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace pullout::cli {

namespace {

bool finite(const Point2& p) { return std::isfinite(p.x) && std::isfinite(p.y); }

Point2 transform(const Pose2& pose, const Point2& local) {
  const double c = std::cos(pose.yaw);
  const double s = std::sin(pose.yaw);
  return {pose.x + c * local.x - s * local.y, pose.y + s * local.x + c * local.y};
}

// One half-plane of the box for Sutherland-Hodgman: inside() and where an edge crosses it.
struct HalfPlane {
  int axis;      // 0: x, 1: y
  double limit;  // the box's bound on that axis
  bool keep_below;

  double coord(const Point2& p) const { return axis == 0 ? p.x : p.y; }
  bool inside(const Point2& p) const { return keep_below ? coord(p) <= limit : coord(p) >= limit; }
  Point2 crossing(const Point2& a, const Point2& b) const {
    const double t = (limit - coord(a)) / (coord(b) - coord(a));
    Point2 p{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
    (axis == 0 ? p.x : p.y) = limit;  // exactly on the bound, whatever the rounding
    return p;
  }
};

}  // namespace

Box::Box()
    : min_x(std::numeric_limits<double>::infinity()),
      min_y(std::numeric_limits<double>::infinity()),
      max_x(-std::numeric_limits<double>::infinity()),
      max_y(-std::numeric_limits<double>::infinity()) {}

void Box::add(const Point2& p) {
  if (!finite(p)) return;
  min_x = std::min(min_x, p.x);
  min_y = std::min(min_y, p.y);
  max_x = std::max(max_x, p.x);
  max_y = std::max(max_y, p.y);
}

void Box::add_box(const Box& other) {
  if (other.empty()) return;
  add({other.min_x, other.min_y});
  add({other.max_x, other.max_y});
}

Box Box::inflated(double margin) const {
  if (empty()) return *this;
  return {min_x - margin, min_y - margin, max_x + margin, max_y + margin};
}

Box Box::at_least(double min_width, double min_height) const {
  if (empty()) return *this;
  const double grow_x = std::max(0.0, min_width - width()) / 2.0;
  const double grow_y = std::max(0.0, min_height - height()) / 2.0;
  return {min_x - grow_x, min_y - grow_y, max_x + grow_x, max_y + grow_y};
}

Box Box::intersection(const Box& other) const {
  const Box b{std::max(min_x, other.min_x), std::max(min_y, other.min_y), std::min(max_x, other.max_x),
              std::min(max_y, other.max_y)};
  return b.empty() ? Box{} : b;
}

bool Box::contains(const Box& other) const {
  return !empty() && !other.empty() && other.min_x >= min_x && other.max_x <= max_x && other.min_y >= min_y &&
         other.max_y <= max_y;
}

bool Box::meets(const Box& other) const { return !intersection(other).empty(); }

std::array<Point2, 4> vehicle_footprint(const VehicleInfo& vehicle, const Pose2& pose) {
  const double front = vehicle.base_to_front_m();
  const double rear = -vehicle.base_to_rear_m();
  const double left = vehicle.base_to_left_m();
  const double right = -vehicle.base_to_right_m();
  return {transform(pose, {front, left}), transform(pose, {rear, left}), transform(pose, {rear, right}),
          transform(pose, {front, right})};
}

std::vector<Point2> object_footprint(const Object& object) {
  std::vector<Point2> local = object.polygon;
  if (local.empty()) {
    const double hl = object.length_m / 2.0;
    const double hw = object.width_m / 2.0;
    local = {{hl, hw}, {-hl, hw}, {-hl, -hw}, {hl, -hw}};
  }
  std::vector<Point2> out;
  out.reserve(local.size());
  for (const auto& p : local) out.push_back(transform(object.pose, p));
  return out;
}

std::vector<Point2> clip_polygon(const std::vector<Point2>& polygon, const Box& box) {
  std::vector<Point2> out;
  if (box.empty()) return out;
  std::copy_if(polygon.begin(), polygon.end(), std::back_inserter(out), finite);
  // Wholly inside (the common case): as it is.
  if (std::all_of(out.begin(), out.end(), [&](const Point2& p) { return box.contains(p); })) return out;
  const HalfPlane planes[4] = {
      {0, box.min_x, false}, {0, box.max_x, true}, {1, box.min_y, false}, {1, box.max_y, true}};
  for (const HalfPlane& plane : planes) {
    if (out.empty()) break;
    std::vector<Point2> next;
    next.reserve(out.size() + 4);
    for (std::size_t i = 0; i < out.size(); ++i) {
      const Point2& a = out[(i + out.size() - 1) % out.size()];
      const Point2& b = out[i];
      const bool a_in = plane.inside(a);
      const bool b_in = plane.inside(b);
      if (b_in) {
        if (!a_in) next.push_back(plane.crossing(a, b));
        next.push_back(b);
      } else if (a_in) {
        next.push_back(plane.crossing(a, b));
      }
    }
    out = std::move(next);
  }
  if (out.size() < 3) out.clear();
  return out;
}

std::vector<std::vector<Point2>> clip_polyline(const std::vector<Point2>& polyline, const Box& box) {
  std::vector<std::vector<Point2>> runs;
  if (box.empty()) return runs;
  std::vector<Point2> run;
  const auto close_run = [&] {
    if (run.size() >= 2) runs.push_back(std::move(run));
    run.clear();
  };
  for (std::size_t i = 0; i + 1 < polyline.size(); ++i) {
    const Point2& a = polyline[i];
    const Point2& b = polyline[i + 1];
    if (!finite(a) || !finite(b)) {
      close_run();
      continue;
    }
    // Liang-Barsky: the parameter range [t0, t1] of a + t (b - a) inside the box.
    double t0 = 0.0;
    double t1 = 1.0;
    const double d[2] = {b.x - a.x, b.y - a.y};
    const double lo[2] = {box.min_x - a.x, box.min_y - a.y};
    const double hi[2] = {box.max_x - a.x, box.max_y - a.y};
    bool outside = false;
    for (int k = 0; k < 2 && !outside; ++k) {
      if (d[k] == 0.0) {
        outside = lo[k] > 0.0 || hi[k] < 0.0;
        continue;
      }
      double enter = lo[k] / d[k];
      double leave = hi[k] / d[k];
      if (enter > leave) std::swap(enter, leave);
      t0 = std::max(t0, enter);
      t1 = std::min(t1, leave);
      outside = t0 > t1;
    }
    if (outside) {
      close_run();
      continue;
    }
    const auto at = [&](double t) {
      // The end points themselves when not cut: no rounding on points inside.
      if (t == 0.0) return a;
      if (t == 1.0) return b;
      return Point2{std::clamp(a.x + t * d[0], box.min_x, box.max_x), std::clamp(a.y + t * d[1], box.min_y, box.max_y)};
    };
    if (t0 > 0.0) close_run();  // entered the box here: a new run
    if (run.empty()) run.push_back(at(t0));
    run.push_back(at(t1));
    if (t1 < 1.0) close_run();  // left the box here
  }
  close_run();
  return runs;
}

std::vector<Pose2> manoeuvre_poses(const PullOutPath& path) {
  std::vector<Pose2> poses;
  const auto finite_pose = [](const Pose2& p) { return std::isfinite(p.x) && std::isfinite(p.y); };
  for (std::size_t s = 0; s < path.partial_paths.size(); ++s) {
    const auto& points = path.partial_paths[s].points;
    std::size_t last = points.empty() ? 0 : points.size() - 1;
    if (s + 1 == path.partial_paths.size() && !points.empty()) {
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < points.size(); ++i) {
        const double d = std::hypot(points[i].pose.x - path.end_pose.x, points[i].pose.y - path.end_pose.y);
        if (d < best) {
          best = d;
          last = i;
        }
      }
    }
    for (std::size_t i = 0; i < points.size() && i <= last; ++i) {
      if (finite_pose(points[i].pose)) poses.push_back(points[i].pose);
    }
  }
  return poses;
}

Box manoeuvre_view(const PullOutRequest& request, const VehicleInfo& vehicle, const PullOutPath* path, double margin) {
  Box core;
  core.add_all(vehicle_footprint(vehicle, request.ego_pose));
  if (path != nullptr && path->found) {
    for (const Pose2& pose : manoeuvre_poses(*path)) core.add_all(vehicle_footprint(vehicle, pose));
    core.add_all(vehicle_footprint(vehicle, path->end_pose));
  }
  const Box view = core.inflated(margin);
  Box out = view;
  for (const Object& object : request.objects) {
    const Box b = box_of(object_footprint(object));
    if (b.meets(view) && b.width() <= kWholeObjectMaxM && b.height() <= kWholeObjectMaxM) out.add_box(b);
  }
  return out;
}

bool segment_is_reverse(const PathWithLaneId& segment) {
  int balance = 0;
  for (const auto& p : segment.points) {
    if (p.longitudinal_velocity_mps > 0.0) ++balance;
    if (p.longitudinal_velocity_mps < 0.0) --balance;
  }
  return balance < 0;
}

}  // namespace pullout::cli
