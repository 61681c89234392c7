#include "svg_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pullout/geometry/angle.hpp"
#include "svg_draw.hpp"

namespace pullout::cli {

namespace {

using namespace svg;  // the drawing primitives (svg_draw.hpp) are this file's vocabulary

// --- style ---
constexpr double kMarginPx = 20.0;
constexpr double kLegendWidthPx = 230.0;
constexpr double kLegendRowPx = 20.0;
constexpr double kTitleHeightPx = 24.0;
constexpr double kScaleBarHeightPx = 36.0;
constexpr double kPaddingM = 2.0;     // world padding around the whole scene [m]
constexpr double kMinExtentM = 10.0;  // a view spans at least this much [m]
constexpr double kMaxScalePxPerM = 60.0;
// The inset: at most this big, and at most this fraction of the main drawing on each axis.
constexpr double kInsetMaxWidthPx = 280.0;
constexpr double kInsetMaxHeightPx = 160.0;
constexpr double kInsetMaxFraction = 0.4;
constexpr double kInsetGapPx = 8.0;  // between the inset and the main view's edge
constexpr double kLabelRadiusPx = 8.0;

// Indices of the partial paths after which the vehicle stops to change direction.
std::vector<std::size_t> cusp_segments(const PullOutPath* path) {
  std::vector<std::size_t> out;
  if (!path_drawn(path)) return out;
  for (std::size_t i = 0; i + 1 < path->partial_paths.size(); ++i) {
    const auto& a = path->partial_paths[i];
    if (!a.points.empty() && segment_is_reverse(a) != segment_is_reverse(path->partial_paths[i + 1])) {
      out.push_back(i);
    }
  }
  return out;
}

// The runs of occupied cells along each row of the request's grid (map frame corners).
// A grid whose data does not fill width x height (a request the validation rejects, still drawn)
// or without a positive resolution draws nothing. Occupied: unknown (< 0) or >= 50, as in ROS.
std::vector<std::vector<Point2>> occupied_runs(const OccupancyGrid& g) {
  std::vector<std::vector<Point2>> runs;
  if (g.data.size() < static_cast<std::size_t>(g.width) * g.height || !(g.resolution_m > 0.0) ||
      !std::isfinite(g.resolution_m)) {
    return runs;
  }
  const double c = std::cos(g.origin.yaw);
  const double s = std::sin(g.origin.yaw);
  const auto at = [&](double u, double v) { return Point2{g.origin.x + c * u - s * v, g.origin.y + s * u + c * v}; };
  const auto occupied = [&](std::uint32_t i, std::uint32_t j) {
    const int v = g.data[static_cast<std::size_t>(j) * g.width + i];
    return v < 0 || v >= 50;
  };
  for (std::uint32_t j = 0; j < g.height; ++j) {
    std::uint32_t i = 0;
    while (i < g.width) {
      if (!occupied(i, j)) {
        ++i;
        continue;
      }
      std::uint32_t end = i;
      while (end < g.width && occupied(end, j)) ++end;
      const double r = g.resolution_m;
      runs.push_back({at(i * r, j * r), at(end * r, j * r), at(end * r, (j + 1) * r), at(i * r, (j + 1) * r)});
      i = end;
    }
  }
  return runs;
}

struct LegendEntry {
  std::string swatch;  // SVG element drawn in a 16 x 12 box at the origin
  std::string label;
};

std::string box_swatch(const std::string& style) {
  return "<rect x=\"0\" y=\"0\" width=\"16\" height=\"12\" " + style + "/>";
}

std::string footprint_swatch(const char* colour) {
  return box_swatch(std::string("fill=\"") + colour + "\" fill-opacity=\"0.15\" stroke=\"" + colour +
                    "\" stroke-width=\"2\"");
}

std::vector<LegendEntry> legend_entries(const PullOutRequest& request, const PullOutPath* path,
                                        const std::vector<Lane>& map_lanes, bool inset) {
  std::vector<LegendEntry> entries;
  const auto any = [&](LaneSubtype subtype) {
    const auto is = [subtype](const Lane& l) { return l.subtype == subtype; };
    return std::any_of(request.lanes.begin(), request.lanes.end(), is) ||
           std::any_of(map_lanes.begin(), map_lanes.end(), is);
  };
  const bool has_route =
      std::any_of(map_lanes.begin(), map_lanes.end(), [&](const Lane& l) { return on_route(request, l); });
  if (any(LaneSubtype::kRoad)) {
    entries.push_back(
        {box_swatch(std::string("fill=\"") + kRoadFill + "\" stroke=\"" + kLaneStroke + "\""), "road lane"});
  }
  if (any(LaneSubtype::kRoadShoulder)) {
    entries.push_back(
        {box_swatch(std::string("fill=\"") + kShoulderFill + "\" stroke=\"" + kLaneStroke + "\""), "road shoulder"});
  }
  if (has_route) {
    entries.push_back(
        {box_swatch(std::string("fill=\"") + kRoadFill + "\" stroke=\"" + kRouteStroke + "\" stroke-width=\"2\""),
         "route"});
  }
  if (!request.objects.empty()) {
    entries.push_back(
        {box_swatch(std::string("fill=\"") + kObjectFill + "\" stroke=\"" + kObjectStroke + "\""), "object"});
  }
  if (request.occupancy_grid) {
    entries.push_back({box_swatch(std::string("fill=\"") + kGridFill + "\" stroke=\"none\""), "occupied grid cell"});
  }
  entries.push_back({footprint_swatch(kStartStroke), "vehicle at start"});
  if (!cusp_segments(path).empty()) entries.push_back({footprint_swatch(kCuspStroke), "vehicle at a cusp"});
  if (path_drawn(path)) {
    entries.push_back({footprint_swatch(kEndStroke), "vehicle at end"});
    for (std::size_t i = 0; i < path->partial_paths.size(); ++i) {
      const bool reverse = segment_is_reverse(path->partial_paths[i]);
      const char* colour = segment_colour(i);
      entries.push_back({std::string("<line x1=\"0\" y1=\"6\" x2=\"16\" y2=\"6\" stroke=\"") + colour +
                             "\" stroke-width=\"3\"" + (reverse ? " stroke-dasharray=\"4 2\"" : "") + "/>",
                         "segment " + std::to_string(i + 1) + (reverse ? ": reverse (dashed)" : ": forward")});
    }
  }
  entries.push_back(
      {std::string("<circle cx=\"8\" cy=\"6\" r=\"4\" fill=\"none\" stroke=\"") + kGoalStroke + "\"/>", "goal"});
  if (inset) {
    entries.push_back(
        {box_swatch(std::string("fill=\"none\" stroke=\"") + kInsetViewStroke + "\" stroke-width=\"1.5\""),
         "inset: this view in the whole"});
  }
  return entries;
}

void draw_footprint(std::ostringstream& svg, const Frame& f, const VehicleInfo& vehicle, const Pose2& pose,
                    const char* css_class, const char* colour, const std::string& extra = {}) {
  const auto corners = vehicle_footprint(vehicle, pose);
  draw_polygon(svg, f, {corners.begin(), corners.end()},
               std::string("class=\"") + css_class + "\"" + extra + " fill=\"" + colour + "\" fill-opacity=\"0.15\"",
               std::string("stroke=\"") + colour + "\" stroke-width=\"2\"");
  // A tick from base_link towards the front shows the heading.
  const Point2 base{pose.x, pose.y};
  const Point2 nose{pose.x + vehicle.base_to_front_m() * std::cos(pose.yaw),
                    pose.y + vehicle.base_to_front_m() * std::sin(pose.yaw)};
  draw_polyline(svg, f, {base, nose},
                std::string("class=\"") + css_class + "-heading\" stroke=\"" + colour + "\" stroke-width=\"1\"");
}

// Freespace elements: the request's occupancy grid as its occupied cells (merged into runs along
// each row), what the freespace search avoided.
void draw_grid(std::ostringstream& svg, const Frame& f, const PullOutRequest& request) {
  svg << "  <g id=\"grid\" shape-rendering=\"crispEdges\">\n";
  if (request.occupancy_grid) {
    const std::string attributes = std::string("class=\"grid-occupied\" fill=\"") + kGridFill + "\"";
    for (const auto& run : occupied_runs(*request.occupancy_grid)) draw_polygon(svg, f, run, attributes, "");
  }
  svg << "  </g>\n";
}

// The footprint where the vehicle stops to change direction: the last point of every partial path
// followed by one in the other direction (the next segment's number is drawn there).
void draw_cusp_footprints(std::ostringstream& svg, const Frame& f, const VehicleInfo& vehicle,
                          const PullOutPath* path) {
  svg << "  <g id=\"cusps\">\n";
  for (std::size_t i : cusp_segments(path)) {
    draw_footprint(svg, f, vehicle, path->partial_paths[i].points.back().pose, "footprint-cusp", kCuspStroke,
                   " data-after=\"" + std::to_string(i + 1) + "\"");
  }
  svg << "  </g>\n";
}

// Arrow heads for the segments' ends, one per colour (context-stroke is not read everywhere).
void draw_markers(std::ostringstream& svg, const PullOutPath* path) {
  if (!path_drawn(path) || path->partial_paths.empty()) return;
  svg << "  <defs>\n";
  const std::size_t n = std::min(path->partial_paths.size(), kSegmentColours.size());
  for (std::size_t i = 0; i < n; ++i) {
    svg << "    <marker id=\"arrow-" << i
        << "\" viewBox=\"0 0 10 10\" refX=\"7\" refY=\"5\" markerWidth=\"4\" markerHeight=\"4\" orient=\"auto\">"
        << "<path d=\"M0,0 L10,5 L0,10 z\" fill=\"" << segment_colour(i) << "\"/></marker>\n";
  }
  svg << "  </defs>\n";
}

// Where a segment's number goes [px]: on its start pose when no earlier number is there, else the
// first free spot on rings around it (up first, then clockwise), inside the view; a leader joins
// it to the start pose.
template <typename Labels>
Point2 label_place(const Point2& anchor, const Labels& placed, const Frame& f) {
  const double spacing = 2.0 * kLabelRadiusPx + 2.0;
  const auto free = [&](const Point2& c) {
    const bool inside = c.x - kLabelRadiusPx >= f.left && c.x + kLabelRadiusPx <= f.left + f.width_px() &&
                        c.y - kLabelRadiusPx >= f.top && c.y + kLabelRadiusPx <= f.top + f.height_px();
    return inside && std::none_of(placed.begin(), placed.end(),
                                  [&](const auto& l) { return std::hypot(l.at.x - c.x, l.at.y - c.y) < spacing; });
  };
  if (free(anchor)) return anchor;
  for (int ring = 1; ring <= 3; ++ring) {
    for (int k = 0; k < 8; ++k) {
      const double angle = -kPi / 2.0 + k * kPi / 4.0;
      const Point2 c{anchor.x + ring * spacing * std::cos(angle), anchor.y + ring * spacing * std::sin(angle)};
      if (free(c)) return c;
    }
  }
  return anchor;
}

// Each partial path in its colour, reverse dashed, an arrow at its end; its number at its start.
void draw_segments(std::ostringstream& svg, const Frame& f, const PullOutPath* path) {
  svg << "  <g id=\"segments\">\n";
  if (path_drawn(path)) {
    for (std::size_t i = 0; i < path->partial_paths.size(); ++i) {
      const bool reverse = segment_is_reverse(path->partial_paths[i]);
      draw_polyline(svg, f, segment_points(path->partial_paths[i]),
                    "class=\"segment\" data-index=\"" + std::to_string(i) + "\" stroke=\"" + segment_colour(i) +
                        "\" stroke-width=\"3\"" +
                        (reverse ? std::string(" stroke-dasharray=\"") + kReverseDash + "\"" : "") +
                        " stroke-linejoin=\"round\"",
                    " marker-end=\"url(#arrow-" + std::to_string(i % kSegmentColours.size()) + ")\"");
    }
  }
  svg << "  </g>\n";
  svg << "  <g id=\"segment-labels\">\n";
  struct Label {
    std::size_t index;
    Point2 anchor;  // the segment's start pose [px]
    Point2 at;      // the disc's centre [px]
  };
  std::vector<Label> labels;
  if (path_drawn(path)) {
    for (std::size_t i = 0; i < path->partial_paths.size(); ++i) {
      const auto& points = path->partial_paths[i].points;
      if (points.empty()) continue;
      const Point2 start{points.front().pose.x, points.front().pose.y};
      if (!std::isfinite(start.x) || !std::isfinite(start.y) || !f.view.contains(start)) continue;
      const Point2 anchor{f.x(start.x), f.y(start.y)};
      labels.push_back({i, anchor, label_place(anchor, labels, f)});
    }
  }
  // Start dots and leaders first, the numbered discs over them.
  for (const Label& l : labels) {
    const char* colour = segment_colour(l.index);
    svg << "    <circle class=\"segment-start\" data-index=\"" << l.index << "\" cx=\"" << num(l.anchor.x) << "\" cy=\""
        << num(l.anchor.y) << "\" r=\"2.5\" fill=\"" << colour << "\"/>\n";
    if (l.at.x != l.anchor.x || l.at.y != l.anchor.y) {
      svg << "    <line class=\"segment-label-leader\" data-index=\"" << l.index << "\" x1=\"" << num(l.anchor.x)
          << "\" y1=\"" << num(l.anchor.y) << "\" x2=\"" << num(l.at.x) << "\" y2=\"" << num(l.at.y) << "\" stroke=\""
          << colour << "\" stroke-width=\"1\"/>\n";
    }
  }
  for (const Label& l : labels) {
    const std::string x = num(l.at.x);
    const std::string y = num(l.at.y);
    svg << "    <circle class=\"segment-label-disc\" data-index=\"" << l.index << "\" cx=\"" << x << "\" cy=\"" << y
        << "\" r=\"" << num(kLabelRadiusPx) << "\" fill=\"" << segment_colour(l.index)
        << "\" stroke=\"#ffffff\" stroke-width=\"1.5\"/>\n"
        << "    <text class=\"segment-label\" data-index=\"" << l.index << "\" x=\"" << x << "\" y=\"" << y
        << "\" dy=\"0.35em\" text-anchor=\"middle\" font-size=\"11\" font-weight=\"bold\" fill=\"#ffffff\">"
        << l.index + 1 << "</text>\n";
  }
  svg << "  </g>\n";
}

// The whole scene, small, in a corner of the main view, with the main view outlined.
void draw_inset(std::ostringstream& svg, const Frame& inset, const Frame& main, const PullOutRequest& request,
                const PullOutPath* path, const std::vector<Lane>& map_lanes) {
  svg << "  <g id=\"inset\">\n";
  svg << "    <rect class=\"inset-frame\" x=\"" << num(inset.left) << "\" y=\"" << num(inset.top) << "\" width=\""
      << num(inset.width_px()) << "\" height=\"" << num(inset.height_px())
      << "\" fill=\"#ffffff\" fill-opacity=\"0.92\" stroke=\"#595959\" stroke-width=\"1\"/>\n";
  const auto lane = [&](const Lane& l, bool route) {
    const bool shoulder = l.subtype == LaneSubtype::kRoadShoulder;
    draw_polygon(svg, inset, lane_outline(l),
                 std::string("class=\"inset-lane\" fill=\"") + (shoulder ? kShoulderFill : kRoadFill) + "\"",
                 std::string("stroke=\"") + (route ? kRouteStroke : kLaneStroke) + "\" stroke-width=\"0.5\"");
  };
  for (const Lane& l : map_lanes) lane(l, on_route(request, l));
  for (const Lane& l : request.lanes) lane(l, false);
  for (const Object& object : request.objects) {
    draw_polygon(svg, inset, object_footprint(object),
                 std::string("class=\"inset-object\" fill=\"") + kObjectFill + "\"",
                 std::string("stroke=\"") + kObjectStroke + "\" stroke-width=\"0.5\"");
  }
  if (path_drawn(path)) {
    for (std::size_t i = 0; i < path->partial_paths.size(); ++i) {
      const bool reverse = segment_is_reverse(path->partial_paths[i]);
      draw_polyline(svg, inset, segment_points(path->partial_paths[i]),
                    "class=\"inset-segment\" data-index=\"" + std::to_string(i) + "\" stroke=\"" + segment_colour(i) +
                        "\" stroke-width=\"1.5\"" + (reverse ? " stroke-dasharray=\"3 2\"" : ""));
    }
  }
  draw_goal(svg, inset, request.goal_pose, "inset-goal", 3.0);
  const Box v = main.view.intersection(inset.view);
  if (!v.empty()) {
    svg << "    <rect class=\"inset-view\" x=\"" << num(inset.x(v.min_x)) << "\" y=\"" << num(inset.y(v.max_y))
        << "\" width=\"" << num(v.width() * inset.scale) << "\" height=\"" << num(v.height() * inset.scale)
        << "\" fill=\"none\" stroke=\"" << kInsetViewStroke << "\" stroke-width=\"1.5\"/>\n";
  }
  svg << "  </g>\n";
}

// The inset's frame: `whole` scaled into a corner of the main view; of the four corners the one
// whose inset covers least of `keep_clear` (the manoeuvre, in the main view's world frame).
Frame inset_frame(const Box& whole, const Frame& main, const Box& keep_clear) {
  Frame inset;
  inset.view = whole;
  inset.scale = std::min({kInsetMaxWidthPx / whole.width(), kInsetMaxHeightPx / whole.height(),
                          kInsetMaxFraction * main.width_px() / whole.width(),
                          kInsetMaxFraction * main.height_px() / whole.height()});
  const double w = inset.width_px();
  const double h = inset.height_px();
  const double left = main.left + kInsetGapPx;
  const double right = main.left + main.width_px() - kInsetGapPx - w;
  const double top = main.top + kInsetGapPx;
  const double bottom = main.top + main.height_px() - kInsetGapPx - h;
  // Order of preference on a tie: top-right, bottom-right, bottom-left, top-left.
  const std::array<std::pair<double, double>, 4> corners{{{right, top}, {right, bottom}, {left, bottom}, {left, top}}};
  const double kx0 = main.x(keep_clear.min_x);
  const double kx1 = main.x(keep_clear.max_x);
  const double ky0 = main.y(keep_clear.max_y);
  const double ky1 = main.y(keep_clear.min_y);
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [x, y] : corners) {
    const double overlap =
        std::max(0.0, std::min(x + w, kx1) - std::max(x, kx0)) * std::max(0.0, std::min(y + h, ky1) - std::max(y, ky0));
    if (overlap < best) {
      best = overlap;
      inset.left = x;
      inset.top = y;
    }
  }
  return inset;
}

}  // namespace

double nice_scale_length(double max_length_m) {
  if (!(max_length_m > 0.0) || !std::isfinite(max_length_m)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(max_length_m)));
  for (double step : {5.0, 2.0, 1.0}) {
    if (step * decade <= max_length_m * (1.0 + 1e-9)) return step * decade;
  }
  return decade;
}

std::string render_svg(const PullOutRequest& request, const VehicleInfo& vehicle, const PullOutPath* path,
                       const SvgOptions& options) {
  // --- the whole scene, and what the main view frames ---
  Box scene;
  for (const auto& lane : options.map_lanes) {
    scene.add_all(lane.left_bound);
    scene.add_all(lane.right_bound);
  }
  for (const auto& lane : request.lanes) {
    scene.add_all(lane.left_bound);
    scene.add_all(lane.right_bound);
    scene.add_all(lane.centerline);
  }
  for (const auto& object : request.objects) scene.add_all(object_footprint(object));
  scene.add_all(vehicle_footprint(vehicle, request.ego_pose));
  scene.add({request.goal_pose.x, request.goal_pose.y});
  if (path_drawn(path)) {
    for (const auto& segment : path->partial_paths) scene.add_all(segment_points(segment));
    scene.add_all(vehicle_footprint(vehicle, path->end_pose));
  }
  if (scene.empty()) scene.add({0.0, 0.0});
  const Box whole = scene.inflated(kPaddingM).at_least(kMinExtentM, kMinExtentM);

  Box view = whole;
  bool inset = false;
  Box manoeuvre;  // the manoeuvre's footprints (and the objects they meet): kept clear of the inset
  if (options.frame_manoeuvre) {
    manoeuvre = manoeuvre_view(request, vehicle, path, 0.0);
    const double margin = path_drawn(path) ? kViewMarginM : kNoPathViewMarginM;
    const Box focus =
        manoeuvre_view(request, vehicle, path, margin).intersection(whole).at_least(kMinExtentM, kMinExtentM);
    if (!focus.empty() && (focus.width() < kInsetBelowFraction * whole.width() ||
                           focus.height() < kInsetBelowFraction * whole.height())) {
      view = focus;
      inset = true;
    }
  }

  Frame f;
  f.view = view;
  f.scale = std::min(
      {options.max_drawing_width_px / view.width(), options.max_drawing_height_px / view.height(), kMaxScalePxPerM});
  f.left = kMarginPx;
  f.top = kMarginPx + (options.title.empty() ? 0.0 : kTitleHeightPx);
  const double drawing_w = f.width_px();
  const double drawing_h = f.height_px();

  const std::vector<LegendEntry> legend = legend_entries(request, path, options.map_lanes, inset);
  const double legend_h = kLegendRowPx * static_cast<double>(legend.size() + 1);
  const double total_w = kMarginPx + drawing_w + kMarginPx + kLegendWidthPx;
  const double total_h = f.top + std::max(drawing_h + kScaleBarHeightPx, legend_h) + kMarginPx;

  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(total_w) << "\" height=\"" << num(total_h)
      << "\" viewBox=\"0 0 " << num(total_w) << ' ' << num(total_h)
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  draw_markers(svg, path);
  svg << "  <rect class=\"background\" x=\"0\" y=\"0\" width=\"" << num(total_w) << "\" height=\"" << num(total_h)
      << "\" fill=\"white\"/>\n";
  if (!options.title.empty()) {
    svg << "  <text class=\"title\" x=\"" << num(kMarginPx) << "\" y=\"" << num(kMarginPx + 12.0)
        << "\" font-size=\"14\">" << escape_xml(options.title) << "</text>\n";
  }
  svg << "  <rect class=\"frame\" x=\"" << num(f.left) << "\" y=\"" << num(f.top) << "\" width=\"" << num(drawing_w)
      << "\" height=\"" << num(drawing_h) << "\" fill=\"none\" stroke=\"#bfbfbf\"/>\n";

  svg << "  <g id=\"map\">\n";
  for (const auto& lane : options.map_lanes) {
    const bool shoulder = lane.subtype == LaneSubtype::kRoadShoulder;
    const bool route = on_route(request, lane);
    draw_polygon(svg, f, lane_outline(lane),
                 std::string("class=\"") + (shoulder ? "map-shoulder" : "map-road") + (route ? " route" : "") +
                     "\" data-id=\"" + std::to_string(lane.id) + "\" fill=\"" + (shoulder ? kShoulderFill : kRoadFill) +
                     "\"",
                 std::string("stroke=\"") + (route ? kRouteStroke : kLaneStroke) + "\" stroke-width=\"" +
                     (route ? "2" : "1") + "\"");
  }
  svg << "  </g>\n";

  svg << "  <g id=\"lanes\">\n";
  for (const auto& lane : request.lanes) {
    const bool shoulder = lane.subtype == LaneSubtype::kRoadShoulder;
    draw_polygon(svg, f, lane_outline(lane),
                 std::string("class=\"") + (shoulder ? "lane-shoulder" : "lane-road") + "\" data-id=\"" +
                     std::to_string(lane.id) + "\" fill=\"" + (shoulder ? kShoulderFill : kRoadFill) + "\"",
                 std::string("stroke=\"") + kLaneStroke + "\" stroke-width=\"1\"");
    if (lane.centerline.size() >= 2) {
      draw_polyline(svg, f, lane.centerline,
                    "class=\"centerline\" stroke=\"#ffffff\" stroke-width=\"1\" stroke-dasharray=\"6 4\"");
    }
  }
  svg << "  </g>\n";

  svg << "  <g id=\"objects\">\n";
  for (const auto& object : request.objects) {
    draw_polygon(svg, f, object_footprint(object),
                 "class=\"object\" data-id=\"" + std::to_string(object.id) + "\" fill=\"" + kObjectFill +
                     "\" fill-opacity=\"0.7\"",
                 std::string("stroke=\"") + kObjectStroke + "\" stroke-width=\"1\"");
  }
  svg << "  </g>\n";

  draw_grid(svg, f, request);
  draw_cusp_footprints(svg, f, vehicle, path);

  svg << "  <g id=\"footprints\">\n";
  draw_footprint(svg, f, vehicle, request.ego_pose, "footprint-start", kStartStroke);
  if (path_drawn(path)) draw_footprint(svg, f, vehicle, path->end_pose, "footprint-end", kEndStroke);
  svg << "  </g>\n";

  draw_segments(svg, f, path);
  draw_goal(svg, f, request.goal_pose, "goal", 5.0);
  if (inset) draw_inset(svg, inset_frame(whole, f, manoeuvre), f, request, path, options.map_lanes);

  // --- scale bar, under the drawing ---
  const double bar_m = nice_scale_length(view.width() / 4.0);
  const double bar_y = f.top + drawing_h + 18.0;
  const double bar_x1 = kMarginPx + bar_m * f.scale;
  svg << "  <g id=\"scale-bar\" stroke=\"#000000\" stroke-width=\"1.5\">\n"
      << "    <line x1=\"" << num(kMarginPx) << "\" y1=\"" << num(bar_y) << "\" x2=\"" << num(bar_x1) << "\" y2=\""
      << num(bar_y) << "\"/>\n"
      << "    <line x1=\"" << num(kMarginPx) << "\" y1=\"" << num(bar_y - 5.0) << "\" x2=\"" << num(kMarginPx)
      << "\" y2=\"" << num(bar_y + 5.0) << "\"/>\n"
      << "    <line x1=\"" << num(bar_x1) << "\" y1=\"" << num(bar_y - 5.0) << "\" x2=\"" << num(bar_x1) << "\" y2=\""
      << num(bar_y + 5.0) << "\"/>\n"
      << "    <text x=\"" << num(bar_x1 + 6.0) << "\" y=\"" << num(bar_y + 4.0) << "\" stroke=\"none\">"
      << length_label(bar_m) << " m</text>\n"
      << "  </g>\n";

  // --- legend, right of the drawing ---
  const double legend_x = kMarginPx + drawing_w + kMarginPx;
  svg << "  <g id=\"legend\">\n";
  svg << "    <text x=\"" << num(legend_x) << "\" y=\"" << num(f.top + 12.0)
      << "\" font-weight=\"bold\">legend</text>\n";
  for (std::size_t i = 0; i < legend.size(); ++i) {
    const double row_y = f.top + kLegendRowPx * static_cast<double>(i + 1);
    svg << "    <g transform=\"translate(" << num(legend_x) << ',' << num(row_y + 2.0) << ")\">" << legend[i].swatch
        << "<text x=\"24\" y=\"11\">" << escape_xml(legend[i].label) << "</text></g>\n";
  }
  svg << "  </g>\n";
  svg << "</svg>\n";
  return svg.str();
}

void write_text_file(const std::string& file, const std::string& svg) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot open '" + file + "' for writing");
  out << svg;
  out.close();
  if (!out) throw std::runtime_error("cannot write '" + file + "'");
}

}  // namespace pullout::cli
