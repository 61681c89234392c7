#include "svg_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pullout::cli {

namespace {

// --- style ---
constexpr double kMarginPx = 20.0;
constexpr double kLegendWidthPx = 210.0;
constexpr double kLegendRowPx = 20.0;
constexpr double kTitleHeightPx = 24.0;
constexpr double kScaleBarHeightPx = 36.0;
constexpr double kPaddingM = 2.0;     // world padding around the drawn content [m]
constexpr double kMinExtentM = 10.0;  // a picture spans at least this much [m]
constexpr double kMaxScalePxPerM = 60.0;

constexpr const char* kRoadFill = "#d9d9d9";
constexpr const char* kShoulderFill = "#f2e2b3";
constexpr const char* kLaneStroke = "#8c8c8c";
constexpr const char* kRouteStroke = "#262626";
constexpr const char* kObjectFill = "#ff7875";
constexpr const char* kObjectStroke = "#a8071a";
constexpr const char* kStartStroke = "#0050b3";
constexpr const char* kEndStroke = "#237804";
constexpr const char* kGoalStroke = "#000000";
// Segment colours: distinct from the lane, object and footprint colours above.
constexpr std::array<const char*, 8> kSegmentColours{"#fa8c16", "#722ed1", "#13c2c2", "#eb2f96",
                                                     "#8c6d1f", "#2f54eb", "#7cb305", "#595959"};

struct Bounds {
  double min_x{std::numeric_limits<double>::infinity()};
  double min_y{std::numeric_limits<double>::infinity()};
  double max_x{-std::numeric_limits<double>::infinity()};
  double max_y{-std::numeric_limits<double>::infinity()};

  void add(const Point2& p) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    min_x = std::min(min_x, p.x);
    min_y = std::min(min_y, p.y);
    max_x = std::max(max_x, p.x);
    max_y = std::max(max_y, p.y);
  }
  template <typename Points>
  void add_all(const Points& points) {
    for (const auto& p : points) add(p);
  }
  bool empty() const { return !(min_x <= max_x && min_y <= max_y); }
};

// World -> picture transform (y flipped so that it points up in the picture).
struct Frame {
  double min_x{0.0};
  double max_y{0.0};
  double scale{1.0};  // [px/m]
  double top{0.0};    // picture y of max_y [px]
  double width_m{0.0};
  double height_m{0.0};

  double x(double wx) const { return kMarginPx + (wx - min_x) * scale; }
  double y(double wy) const { return top + (max_y - wy) * scale; }
};

std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f", v);
  return buffer;
}

std::string length_label(double metres) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", metres);
  return buffer;
}

std::string escape_xml(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        // Control characters are not allowed in XML 1.0 text.
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t' || c == '\n') out += c;
    }
  }
  return out;
}

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

Point2 transform(const Pose2& pose, const Point2& local) {
  const double c = std::cos(pose.yaw);
  const double s = std::sin(pose.yaw);
  return {pose.x + c * local.x - s * local.y, pose.y + s * local.x + c * local.y};
}

std::vector<Point2> lane_outline(const Lane& lane) {
  std::vector<Point2> outline(lane.left_bound.begin(), lane.left_bound.end());
  outline.insert(outline.end(), lane.right_bound.rbegin(), lane.right_bound.rend());
  return outline;
}

std::vector<Point2> segment_points(const PathWithLaneId& segment) {
  std::vector<Point2> points;
  points.reserve(segment.points.size());
  for (const auto& p : segment.points) points.push_back({p.pose.x, p.pose.y});
  return points;
}

bool segment_is_reverse(const PathWithLaneId& segment) {
  int balance = 0;
  for (const auto& p : segment.points) {
    if (p.longitudinal_velocity_mps > 0.0) ++balance;
    if (p.longitudinal_velocity_mps < 0.0) --balance;
  }
  return balance < 0;
}

bool path_drawn(const PullOutPath* path) { return path != nullptr && path->found; }

struct LegendEntry {
  std::string swatch;  // SVG element drawn in a 16 x 12 box at the origin
  std::string label;
};

bool on_route(const PullOutRequest& request, const Lane& lane) {
  const auto listed = [&lane](const std::vector<std::int64_t>& ids) {
    return std::find(ids.begin(), ids.end(), lane.id) != ids.end();
  };
  return listed(request.route_lanelet_ids) ||
         std::any_of(request.route_segments.begin(), request.route_segments.end(),
                     [&](const RouteSegment& s) { return s.preferred_id == lane.id || listed(s.primitive_ids); });
}

std::vector<LegendEntry> legend_entries(const PullOutRequest& request, const PullOutPath* path,
                                        const std::vector<Lane>& map_lanes) {
  std::vector<LegendEntry> entries;
  const auto box = [](const std::string& style) {
    return "<rect x=\"0\" y=\"0\" width=\"16\" height=\"12\" " + style + "/>";
  };
  const auto any = [&](LaneSubtype subtype) {
    const auto is = [subtype](const Lane& l) { return l.subtype == subtype; };
    return std::any_of(request.lanes.begin(), request.lanes.end(), is) ||
           std::any_of(map_lanes.begin(), map_lanes.end(), is);
  };
  const bool has_road = any(LaneSubtype::kRoad);
  const bool has_shoulder = any(LaneSubtype::kRoadShoulder);
  const bool has_route =
      std::any_of(map_lanes.begin(), map_lanes.end(), [&](const Lane& l) { return on_route(request, l); });
  if (has_road) {
    entries.push_back({box(std::string("fill=\"") + kRoadFill + "\" stroke=\"" + kLaneStroke + "\""), "road lane"});
  }
  if (has_shoulder) {
    entries.push_back(
        {box(std::string("fill=\"") + kShoulderFill + "\" stroke=\"" + kLaneStroke + "\""), "road shoulder"});
  }
  if (has_route) {
    entries.push_back(
        {box(std::string("fill=\"") + kRoadFill + "\" stroke=\"" + kRouteStroke + "\" stroke-width=\"2\""), "route"});
  }
  if (!request.objects.empty()) {
    entries.push_back({box(std::string("fill=\"") + kObjectFill + "\" stroke=\"" + kObjectStroke + "\""), "object"});
  }
  entries.push_back({box(std::string("fill=\"") + kStartStroke + "\" fill-opacity=\"0.15\" stroke=\"" + kStartStroke +
                         "\" stroke-width=\"2\""),
                     "vehicle at start"});
  if (path_drawn(path)) {
    entries.push_back({box(std::string("fill=\"") + kEndStroke + "\" fill-opacity=\"0.15\" stroke=\"" + kEndStroke +
                           "\" stroke-width=\"2\""),
                       "vehicle at end"});
    for (std::size_t i = 0; i < path->partial_paths.size(); ++i) {
      const bool reverse = segment_is_reverse(path->partial_paths[i]);
      const char* colour = kSegmentColours[i % kSegmentColours.size()];
      entries.push_back({std::string("<line x1=\"0\" y1=\"6\" x2=\"16\" y2=\"6\" stroke=\"") + colour +
                             "\" stroke-width=\"3\"" + (reverse ? " stroke-dasharray=\"4 2\"" : "") + "/>",
                         "segment " + std::to_string(i) + (reverse ? " (reverse)" : " (forward)")});
    }
  }
  entries.push_back(
      {std::string("<circle cx=\"8\" cy=\"6\" r=\"4\" fill=\"none\" stroke=\"") + kGoalStroke + "\"/>", "goal"});
  return entries;
}

void draw_footprint(std::ostringstream& svg, const Frame& f, const VehicleInfo& vehicle, const Pose2& pose,
                    const char* css_class, const char* colour) {
  const auto corners = vehicle_footprint(vehicle, pose);
  svg << "    <polygon class=\"" << css_class << "\" points=\"" << points_attr(f, corners) << "\" fill=\"" << colour
      << "\" fill-opacity=\"0.15\" stroke=\"" << colour << "\" stroke-width=\"2\"/>\n";
  // A tick from base_link towards the front shows the heading.
  const Point2 base{pose.x, pose.y};
  const Point2 nose = transform(pose, {vehicle.base_to_front_m(), 0.0});
  svg << "    <line class=\"" << css_class << "-heading\" x1=\"" << num(f.x(base.x)) << "\" y1=\"" << num(f.y(base.y))
      << "\" x2=\"" << num(f.x(nose.x)) << "\" y2=\"" << num(f.y(nose.y)) << "\" stroke=\"" << colour
      << "\" stroke-width=\"1\"/>\n";
}

}  // namespace

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

double nice_scale_length(double max_length_m) {
  if (!(max_length_m > 0.0) || !std::isfinite(max_length_m)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(max_length_m)));
  for (double step : {5.0, 2.0, 1.0}) {
    if (step * decade <= max_length_m * (1.0 + 1e-9)) return step * decade;
  }
  return decade;
}

// Freespace elements: the request's occupancy grid as its occupied cells (merged into runs along
// each row), what the freespace search avoided.
void draw_grid(std::ostringstream& svg, const Frame& f, const PullOutRequest& request) {
  if (!request.occupancy_grid) return;
  const OccupancyGrid& g = *request.occupancy_grid;
  const double c = std::cos(g.origin.yaw);
  const double s = std::sin(g.origin.yaw);
  const auto at = [&](double u, double v) { return Point2{g.origin.x + c * u - s * v, g.origin.y + s * u + c * v}; };
  svg << "  <g id=\"grid\">\n";
  for (std::uint32_t j = 0; j < g.height; ++j) {
    std::uint32_t i = 0;
    while (i < g.width) {
      const auto occupied = [&](std::uint32_t k) {
        const int v = g.data[static_cast<std::size_t>(j) * g.width + k];
        return v < 0 || v >= 50;
      };
      if (!occupied(i)) {
        ++i;
        continue;
      }
      std::uint32_t end = i;
      while (end < g.width && occupied(end)) ++end;
      const double r = g.resolution_m;
      const std::vector<Point2> run{at(i * r, j * r), at(end * r, j * r), at(end * r, (j + 1) * r),
                                    at(i * r, (j + 1) * r)};
      svg << "    <polygon class=\"grid-occupied\" points=\"" << points_attr(f, run)
          << "\" fill=\"#7f7f7f\" stroke=\"none\"/>\n";
      i = end;
    }
  }
  svg << "  </g>\n";
}

// The footprint where the vehicle stops to change direction (the last point of every partial
// path followed by one in the other direction), numbered in driving order.
void draw_cusp_footprints(std::ostringstream& svg, const Frame& f, const VehicleInfo& vehicle,
                          const PullOutPath* path) {
  svg << "  <g id=\"cusps\">\n";
  if (path_drawn(path)) {
    int number = 0;
    for (std::size_t i = 0; i + 1 < path->partial_paths.size(); ++i) {
      const auto& a = path->partial_paths[i];
      if (a.points.empty() || segment_is_reverse(a) == segment_is_reverse(path->partial_paths[i + 1])) continue;
      draw_footprint(svg, f, vehicle, a.points.back().pose, "footprint-cusp", "#7030a0");
      const Pose2& p = a.points.back().pose;
      svg << "    <text class=\"cusp-label\" x=\"" << num(f.x(p.x) + 4.0) << "\" y=\"" << num(f.y(p.y) - 4.0)
          << "\" fill=\"#7030a0\">cusp " << ++number << "</text>\n";
    }
  }
  svg << "  </g>\n";
}

std::string render_svg(const PullOutRequest& request, const VehicleInfo& vehicle, const PullOutPath* path,
                       const SvgOptions& options) {
  // --- what is drawn, and its bounding box ---
  Bounds bounds;
  for (const auto& lane : options.map_lanes) {
    bounds.add_all(lane.left_bound);
    bounds.add_all(lane.right_bound);
  }
  for (const auto& lane : request.lanes) {
    bounds.add_all(lane.left_bound);
    bounds.add_all(lane.right_bound);
    bounds.add_all(lane.centerline);
  }
  for (const auto& object : request.objects) bounds.add_all(object_footprint(object));
  bounds.add_all(vehicle_footprint(vehicle, request.ego_pose));
  bounds.add({request.goal_pose.x, request.goal_pose.y});
  if (path_drawn(path)) {
    for (const auto& segment : path->partial_paths) bounds.add_all(segment_points(segment));
    bounds.add_all(vehicle_footprint(vehicle, path->end_pose));
  }
  if (bounds.empty()) bounds.add({0.0, 0.0});
  const double cx = (bounds.min_x + bounds.max_x) / 2.0;
  const double cy = (bounds.min_y + bounds.max_y) / 2.0;
  const double width_m = std::max(bounds.max_x - bounds.min_x + 2.0 * kPaddingM, kMinExtentM);
  const double height_m = std::max(bounds.max_y - bounds.min_y + 2.0 * kPaddingM, kMinExtentM);

  Frame f;
  f.min_x = cx - width_m / 2.0;
  f.max_y = cy + height_m / 2.0;
  f.width_m = width_m;
  f.height_m = height_m;
  f.scale =
      std::min({options.max_drawing_width_px / width_m, options.max_drawing_height_px / height_m, kMaxScalePxPerM});
  f.top = kMarginPx + (options.title.empty() ? 0.0 : kTitleHeightPx);
  const double drawing_w = width_m * f.scale;
  const double drawing_h = height_m * f.scale;

  const std::vector<LegendEntry> legend = legend_entries(request, path, options.map_lanes);
  const double legend_h = kLegendRowPx * static_cast<double>(legend.size() + 1);
  const double total_w = kMarginPx + drawing_w + kMarginPx + kLegendWidthPx;
  const double total_h = f.top + std::max(drawing_h + kScaleBarHeightPx, legend_h) + kMarginPx;

  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(total_w) << "\" height=\"" << num(total_h)
      << "\" viewBox=\"0 0 " << num(total_w) << ' ' << num(total_h)
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  svg << "  <rect class=\"background\" x=\"0\" y=\"0\" width=\"" << num(total_w) << "\" height=\"" << num(total_h)
      << "\" fill=\"white\"/>\n";
  if (!options.title.empty()) {
    svg << "  <text class=\"title\" x=\"" << num(kMarginPx) << "\" y=\"" << num(kMarginPx + 12.0)
        << "\" font-size=\"14\">" << escape_xml(options.title) << "</text>\n";
  }
  svg << "  <rect class=\"frame\" x=\"" << num(kMarginPx) << "\" y=\"" << num(f.top) << "\" width=\"" << num(drawing_w)
      << "\" height=\"" << num(drawing_h) << "\" fill=\"none\" stroke=\"#bfbfbf\"/>\n";

  svg << "  <g id=\"map\">\n";
  for (const auto& lane : options.map_lanes) {
    const bool shoulder = lane.subtype == LaneSubtype::kRoadShoulder;
    const bool route = on_route(request, lane);
    svg << "    <polygon class=\"" << (shoulder ? "map-shoulder" : "map-road") << (route ? " route" : "")
        << "\" data-id=\"" << lane.id << "\" points=\"" << points_attr(f, lane_outline(lane)) << "\" fill=\""
        << (shoulder ? kShoulderFill : kRoadFill) << "\" stroke=\"" << (route ? kRouteStroke : kLaneStroke)
        << "\" stroke-width=\"" << (route ? "2" : "1") << "\"/>\n";
  }
  svg << "  </g>\n";

  svg << "  <g id=\"lanes\">\n";
  for (const auto& lane : request.lanes) {
    const bool shoulder = lane.subtype == LaneSubtype::kRoadShoulder;
    svg << "    <polygon class=\"" << (shoulder ? "lane-shoulder" : "lane-road") << "\" data-id=\"" << lane.id
        << "\" points=\"" << points_attr(f, lane_outline(lane)) << "\" fill=\""
        << (shoulder ? kShoulderFill : kRoadFill) << "\" stroke=\"" << kLaneStroke << "\" stroke-width=\"1\"/>\n";
    if (lane.centerline.size() >= 2) {
      svg << "    <polyline class=\"centerline\" points=\"" << points_attr(f, lane.centerline)
          << "\" fill=\"none\" stroke=\"#ffffff\" stroke-width=\"1\" stroke-dasharray=\"6 4\"/>\n";
    }
  }
  svg << "  </g>\n";

  svg << "  <g id=\"objects\">\n";
  for (const auto& object : request.objects) {
    svg << "    <polygon class=\"object\" data-id=\"" << object.id << "\" points=\""
        << points_attr(f, object_footprint(object)) << "\" fill=\"" << kObjectFill
        << "\" fill-opacity=\"0.7\" stroke=\"" << kObjectStroke << "\" stroke-width=\"1\"/>\n";
  }
  svg << "  </g>\n";

  draw_grid(svg, f, request);
  draw_cusp_footprints(svg, f, vehicle, path);

  svg << "  <g id=\"footprints\">\n";
  draw_footprint(svg, f, vehicle, request.ego_pose, "footprint-start", kStartStroke);
  if (path_drawn(path)) draw_footprint(svg, f, vehicle, path->end_pose, "footprint-end", kEndStroke);
  svg << "  </g>\n";

  svg << "  <g id=\"segments\">\n";
  if (path_drawn(path)) {
    for (std::size_t i = 0; i < path->partial_paths.size(); ++i) {
      const auto& segment = path->partial_paths[i];
      const bool reverse = segment_is_reverse(segment);
      svg << "    <polyline class=\"segment\" data-index=\"" << i << "\" points=\""
          << points_attr(f, segment_points(segment)) << "\" fill=\"none\" stroke=\""
          << kSegmentColours[i % kSegmentColours.size()] << "\" stroke-width=\"3\""
          << (reverse ? " stroke-dasharray=\"8 4\"" : "") << " stroke-linejoin=\"round\"/>\n";
    }
  }
  svg << "  </g>\n";

  svg << "  <circle class=\"goal\" cx=\"" << num(f.x(request.goal_pose.x)) << "\" cy=\""
      << num(f.y(request.goal_pose.y)) << "\" r=\"5\" fill=\"none\" stroke=\"" << kGoalStroke
      << "\" stroke-width=\"1.5\"/>\n";

  // --- scale bar, under the drawing ---
  const double bar_m = nice_scale_length(width_m / 4.0);
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
