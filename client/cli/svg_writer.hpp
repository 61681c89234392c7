// An SVG picture of a pull-out: lanes (filled, shoulders in a sandy tone; map lanelets around the
// vehicle for a route request, the route outlined), objects, the vehicle
// footprint at the start (request ego pose) and at the end (path end pose, found paths only),
// each partial path in its own colour (reverse segments dashed), the goal, a legend and a scale
// bar.
//
// Frames: world coordinates are the map frame of pullout/model/types.hpp (metres, y up). The
// picture keeps y pointing up: a world point (x, y) is drawn at
//   X = margin + (x - min_x) * scale,   Y = margin + (max_y - y) * scale      [px]
// where [min_x, max_x] x [min_y, max_y] is the bounding box of everything drawn (plus padding)
// and scale [px/m] is the largest that fits the drawing into SvgOptions' maximum size. The
// viewBox is "0 0 width height" in px. Non-finite coordinates are skipped.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout::cli {

struct SvgOptions {
  double max_drawing_width_px{1000.0};  // the map part, without legend
  double max_drawing_height_px{800.0};
  std::string title;  // shown at the top; empty: none
  // Lanelets of a Lanelet2 map around the vehicle, drawn under everything else (with the road and
  // shoulder colours); those whose id is in the request's route_lanelet_ids get a dark outline.
  std::vector<Lane> map_lanes;
};

// Corners of the vehicle's footprint at `pose` (base_link = rear-axle centre), counter-clockwise
// from front-left: front-left, rear-left, rear-right, front-right. front = wheel_base +
// front_overhang, rear = rear_overhang, left = tread/2 + left_overhang, right = tread/2 +
// right_overhang.
std::array<Point2, 4> vehicle_footprint(const VehicleInfo& vehicle, const Pose2& pose);

// Footprint of an object in the map frame: its polygon when given, else its length x width box
// centred on its pose.
std::vector<Point2> object_footprint(const Object& object);

// The scale bar length [m]: the largest 1, 2 or 5 x 10^k not above `max_length_m` (> 0).
double nice_scale_length(double max_length_m);

// Renders the whole picture. `path` may be null (no path to draw).
std::string render_svg(const PullOutRequest& request, const VehicleInfo& vehicle, const PullOutPath* path,
                       const SvgOptions& options = {});

// Writes `svg` to `file`. Throws std::runtime_error naming the file when it cannot be written.
void write_text_file(const std::string& file, const std::string& svg);

}  // namespace pullout::cli
