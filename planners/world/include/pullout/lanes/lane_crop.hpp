// Cropping the lanes and objects of a request to the region a plan can reach (the planning
// horizon, a square around the vehicle), so that the work of building the lane world, the
// centerlines and the costmap follows what is near the vehicle, not how far the input's
// coordinates run. A 2-point lane 1e7 m long keeps the few hundred metres around the vehicle.
//
// What is kept of a lane: the stretch between the first and the last cross-section that meets the
// square. A cross-section at t in [0, 1] is the segment from left(t) to right(t), both bounds
// matched by normalised arc length (as LaneWorld matches them for derived centerlines). Inside that
// stretch nothing is changed: every vertex is kept and only the two ends are new (cut at t_first
// and t_last on both bounds, and on a given centerline by its own normalised arc length). The cut
// is conservative: it lies up to kCropResolutionM before the first (after the last) cross-section
// that meets the square, never inside. A lane lying entirely inside the square is returned as it
// was; a lane no cross-section of which meets the square is dropped.
//
// Cost: O(vertices) per lane plus O(log(length / kCropResolutionM)) box tests per end, whatever
// the coordinates (the caller bounds them: RequestLimits::max_coordinate_m).
#pragma once

#include <cstddef>
#include <vector>

#include "pullout/geometry/polygon.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

// [m] Ends of a cropped lane lie at most this far (along each bound) outside the square.
constexpr double kCropResolutionM = 1.0;

struct CroppedLanes {
  std::vector<Lane> lanes;
  std::vector<std::size_t> source;  // per kept lane, its index in the input
  std::size_t cropped{0};           // lanes shortened (kept, but not whole)
  std::size_t dropped{0};           // lanes with no cross-section in the square
};

// The lanes cut to `square` (see the file comment). Lanes must have at least two points per bound
// and bounds of non-zero length (as validation ensures).
CroppedLanes crop_lanes(const std::vector<Lane>& lanes, const Aabb& square);

// Whether the object's footprint (its polygon, or its box when it has none) may reach into
// `square`: true when the disc around its pose holding the whole footprint overlaps it.
bool object_near(const Object& object, const Aabb& square);

// The square of half side `half_side` [m] centred on (x, y).
Aabb horizon_square(double x, double y, double half_side);

}  // namespace pullout
