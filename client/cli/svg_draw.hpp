// Drawing primitives of the CLI's pictures (svg_writer.hpp): the colours, the world -> picture
// transform of one view, and polygons and polylines clipped to that view. Internal to the CLI.
//
// Frames: world coordinates are the map frame (metres, y up); picture coordinates are SVG px
// (y down). Non-finite coordinates are skipped everywhere.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "svg_geometry.hpp"

namespace pullout::cli::svg {

inline constexpr const char* kRoadFill = "#d9d9d9";
inline constexpr const char* kShoulderFill = "#f2e2b3";
inline constexpr const char* kLaneStroke = "#8c8c8c";
inline constexpr const char* kRouteStroke = "#262626";
inline constexpr const char* kObjectFill = "#ff7875";
inline constexpr const char* kObjectStroke = "#a8071a";
inline constexpr const char* kGridFill = "#7f7f7f";
inline constexpr const char* kStartStroke = "#0050b3";
inline constexpr const char* kEndStroke = "#237804";
inline constexpr const char* kCuspStroke = "#7030a0";
inline constexpr const char* kGoalStroke = "#000000";
inline constexpr const char* kInsetViewStroke = "#cf1322";
// Segment colours: distinct from the lane, object and footprint colours above.
inline constexpr std::array<const char*, 8> kSegmentColours{"#fa8c16", "#722ed1", "#13c2c2", "#eb2f96",
                                                            "#8c6d1f", "#2f54eb", "#7cb305", "#595959"};
inline constexpr const char* kReverseDash = "8 4";

const char* segment_colour(std::size_t i);

// World -> picture transform (y flipped so that it points up in the picture) of one view.
struct Frame {
  Box view;           // the world box shown [m]
  double scale{1.0};  // [px/m]
  double left{0.0};   // picture x of view.min_x [px]
  double top{0.0};    // picture y of view.max_y [px]

  double x(double wx) const { return left + (wx - view.min_x) * scale; }
  double y(double wy) const { return top + (view.max_y - wy) * scale; }
  double width_px() const { return view.width() * scale; }
  double height_px() const { return view.height() * scale; }
};

// "%.2f": px coordinates and sizes in attributes.
std::string num(double v);
// "%g": lengths in labels.
std::string length_label(double metres);
// Text for an XML text node or attribute: markup characters escaped, control characters dropped.
std::string escape_xml(const std::string& text);

// "x,y x,y ..." in px, non-finite points skipped.
template <typename Points>
std::string points_attr(const Frame& f, const Points& points) {
  std::string out;
  for (const auto& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    if (!out.empty()) out += ' ';
    out += num(f.x(p.x)) + ',' + num(f.y(p.y));
  }
  return out;
}

// The lane's outline: the left bound, then the right bound reversed.
std::vector<Point2> lane_outline(const Lane& lane);
std::vector<Point2> segment_points(const PathWithLaneId& segment);
bool path_drawn(const PullOutPath* path);
// Whether the request's route (route_lanelet_ids or route_segments) names the lane.
bool on_route(const PullOutRequest& request, const Lane& lane);

// A polygon clipped to the view; nothing when none of it is inside. `attributes` (class, fill)
// go on the polygon; `stroke` (its outline's attributes) too when it is wholly inside. A polygon
// the view's edge cuts is filled without an outline and its own edges are drawn as polylines of
// class "cut-outline", so that the cut does not look like an edge of the lane or object.
void draw_polygon(std::ostringstream& svg, const Frame& f, const std::vector<Point2>& polygon,
                  const std::string& attributes, const std::string& stroke);
// A polyline clipped to the view, one <polyline> per stretch inside; `last_extra` (attributes)
// goes on the last one (e.g. an arrow head at the end).
void draw_polyline(std::ostringstream& svg, const Frame& f, const std::vector<Point2>& polyline,
                   const std::string& attributes, const std::string& last_extra = {});
// The goal as a circle of `radius_px`, when it is in the view.
void draw_goal(std::ostringstream& svg, const Frame& f, const Pose2& goal, const char* css_class, double radius_px);

}  // namespace pullout::cli::svg
