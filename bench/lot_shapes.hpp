// Shapes the generated parking lots of the freespace benchmarks are made of.
#pragma once

#include "pullout/collision/footprint.hpp"
#include "pullout/model/types.hpp"

namespace pullout::bench {

// A length x width box centred on (cx, cy), turned by yaw: a parked car or a wall.
inline Polygon box(double cx, double cy, double yaw, double length, double width) {
  Object o;
  o.pose = {cx, cy, yaw};
  o.length_m = length;
  o.width_m = width;
  return object_polygon(o);
}

}  // namespace pullout::bench
