#include "pullout/collision/footprint.hpp"

#include <algorithm>
#include <cmath>

namespace pullout {

double Footprint::bounding_radius() const { return std::hypot(std::max(front, rear), std::max(left, right)); }

Footprint vehicle_footprint(const VehicleInfo& vehicle, double expansion) {
  return {vehicle.base_to_front_m() + expansion, vehicle.base_to_rear_m() + expansion,
          vehicle.base_to_left_m() + expansion, vehicle.base_to_right_m() + expansion};
}

std::array<Vec2, 4> footprint_corners(const Footprint& f, const Pose2& pose) {
  return {to_global(pose, {f.front, f.left}), to_global(pose, {-f.rear, f.left}), to_global(pose, {-f.rear, -f.right}),
          to_global(pose, {f.front, -f.right})};
}

Polygon footprint_polygon(const Footprint& footprint, const Pose2& pose) {
  const auto c = footprint_corners(footprint, pose);
  return {c.begin(), c.end()};
}

Polygon object_polygon(const Object& object) {
  Polygon out;
  if (!object.polygon.empty()) {
    out.reserve(object.polygon.size());
    for (const Point2& p : object.polygon) out.push_back(to_global(object.pose, to_vec(p)));
    return out;
  }
  const double hl = object.length_m / 2.0;
  const double hw = object.width_m / 2.0;
  return {to_global(object.pose, {hl, hw}), to_global(object.pose, {-hl, hw}), to_global(object.pose, {-hl, -hw}),
          to_global(object.pose, {hl, -hw})};
}

}  // namespace pullout
