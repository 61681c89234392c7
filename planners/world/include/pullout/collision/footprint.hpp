// Footprints: the vehicle rectangle in its base_link frame (rear-axle centre, +x forward), and the
// polygons of objects, both placed in the map frame.
#pragma once

#include <array>

#include "pullout/geometry/polygon.hpp"
#include "pullout/model/types.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout {

// Extents of the vehicle rectangle from base_link [m], all positive.
struct Footprint {
  double front{0.0};
  double rear{0.0};
  double left{0.0};
  double right{0.0};

  double length() const { return front + rear; }
  double width() const { return left + right; }
  // Radius of the circle around base_link that contains the rectangle.
  double bounding_radius() const;
};

// The vehicle rectangle, each side pushed out by `expansion` [m].
Footprint vehicle_footprint(const VehicleInfo& vehicle, double expansion = 0.0);

// Corners of the footprint at pose X_MV, counter-clockwise: front-left, rear-left, rear-right,
// front-right.
std::array<Vec2, 4> footprint_corners(const Footprint& footprint, const Pose2& pose);
Polygon footprint_polygon(const Footprint& footprint, const Pose2& pose);

// The object's footprint in the map frame: its polygon (object frame) placed at its pose, or the
// length x width box centred on the pose.
Polygon object_polygon(const Object& object);

}  // namespace pullout
