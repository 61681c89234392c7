// An SVG picture of a pull-out: lanes (filled, shoulders in a sandy tone; map lanelets around the
// vehicle for a route request, the route outlined), objects, a request's occupancy grid (its
// occupied cells), the vehicle footprint at the start (request ego pose), at every cusp (where
// it stops to change direction) and at the end (path end pose, found paths only), each partial
// path in its own colour with an arrow at its end (reverse segments dashed) and its number
// (1..n in driving order) on a disc at its start pose, the goal, a legend and a scale bar.
//
// Framing: the main view shows the manoeuvre (manoeuvre_view in svg_geometry.hpp: the vehicle's
// footprints from the start to the end pose and the objects around them, within kViewMarginM, or
// kNoPathViewMarginM around the start when no path was found). When that view spans less than
// kInsetBelowFraction of the whole scene (everything drawn: lanes, objects, the whole path, the
// goal) on either axis, an inset in a corner of the main view (the one that covers least of the
// manoeuvre) draws the whole scene small, with a box marking the main view; otherwise the main
// view shows the whole scene and there is no inset. What the main view does not cover is clipped
// at its edge (polygons and polylines are cut, never drawn beyond the view).
//
// Frames: world coordinates are the map frame of pullout/model/types.hpp (metres, y up). The
// picture keeps y pointing up: a world point (x, y) is drawn at
//   X = margin + (x - min_x) * scale,   Y = top + (max_y - y) * scale      [px]
// where [min_x, max_x] x [min_y, max_y] is the main view and scale [px/m] is the largest that
// fits it into SvgOptions' maximum size (at most 60 px/m). The inset uses the same rule with its
// own box and scale. The viewBox is "0 0 width height" in px. Non-finite coordinates are skipped.
#pragma once

#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/vehicle/vehicle_info.hpp"
#include "svg_geometry.hpp"

namespace pullout::cli {

struct SvgOptions {
  double max_drawing_width_px{1000.0};  // the map part, without legend
  double max_drawing_height_px{800.0};
  std::string title;  // shown at the top; empty: none
  // Lanelets of a Lanelet2 map around the vehicle, drawn under everything else (with the road and
  // shoulder colours); those whose id is in the request's route_lanelet_ids get a dark outline.
  std::vector<Lane> map_lanes;
  // true: frame the manoeuvre, with an inset of the whole scene when it is much larger (see the
  // file comment); false: the main view shows the whole scene, no inset.
  bool frame_manoeuvre{true};
};

constexpr double kViewMarginM = 5.0;         // [m] around the manoeuvre's footprints
constexpr double kNoPathViewMarginM = 10.0;  // [m] around the start footprint when no path was found
constexpr double kInsetBelowFraction = 0.75;

// The scale bar length [m]: the largest 1, 2 or 5 x 10^k not above `max_length_m` (> 0).
double nice_scale_length(double max_length_m);

// Renders the whole picture. `path` may be null (no path to draw).
std::string render_svg(const PullOutRequest& request, const VehicleInfo& vehicle, const PullOutPath* path,
                       const SvgOptions& options = {});

// Writes `svg` to `file`. Throws std::runtime_error naming the file when it cannot be written.
void write_text_file(const std::string& file, const std::string& svg);

}  // namespace pullout::cli
