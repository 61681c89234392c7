#include "svg_draw.hpp"

#include <algorithm>
#include <cstdio>
#include <iterator>

namespace pullout::cli::svg {

const char* segment_colour(std::size_t i) { return kSegmentColours[i % kSegmentColours.size()]; }

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

bool path_drawn(const PullOutPath* path) { return path != nullptr && path->found; }

bool on_route(const PullOutRequest& request, const Lane& lane) {
  const auto listed = [&lane](const std::vector<std::int64_t>& ids) {
    return std::find(ids.begin(), ids.end(), lane.id) != ids.end();
  };
  return listed(request.route_lanelet_ids) ||
         std::any_of(request.route_segments.begin(), request.route_segments.end(),
                     [&](const RouteSegment& s) { return s.preferred_id == lane.id || listed(s.primitive_ids); });
}

void draw_polygon(std::ostringstream& svg, const Frame& f, const std::vector<Point2>& polygon,
                  const std::string& attributes, const std::string& stroke) {
  const std::vector<Point2> clipped = clip_polygon(polygon, f.view);
  if (clipped.empty()) return;
  const bool cut = !std::all_of(polygon.begin(), polygon.end(), [&](const Point2& p) {
    return !std::isfinite(p.x) || !std::isfinite(p.y) || f.view.contains(p);
  });
  svg << "    <polygon " << attributes << ' ' << (cut ? std::string("stroke=\"none\"") : stroke) << " points=\""
      << points_attr(f, clipped) << "\"/>\n";
  if (cut && !stroke.empty()) {
    std::vector<Point2> ring = polygon;
    if (!ring.empty()) ring.push_back(ring.front());
    draw_polyline(svg, f, ring, "class=\"cut-outline\" " + stroke);
  }
}

void draw_polyline(std::ostringstream& svg, const Frame& f, const std::vector<Point2>& polyline,
                   const std::string& attributes, const std::string& last_extra) {
  // Non-finite points are skipped (the line joins their neighbours), as everywhere in the picture.
  std::vector<Point2> finite;
  std::copy_if(polyline.begin(), polyline.end(), std::back_inserter(finite),
               [](const Point2& p) { return std::isfinite(p.x) && std::isfinite(p.y); });
  const auto runs = clip_polyline(finite, f.view);
  for (std::size_t k = 0; k < runs.size(); ++k) {
    svg << "    <polyline " << attributes << " points=\"" << points_attr(f, runs[k]) << "\" fill=\"none\""
        << (k + 1 == runs.size() ? last_extra : std::string()) << "/>\n";
  }
}

void draw_goal(std::ostringstream& svg, const Frame& f, const Pose2& goal, const char* css_class, double radius_px) {
  if (!std::isfinite(goal.x) || !std::isfinite(goal.y) || !f.view.contains(Point2{goal.x, goal.y})) return;
  svg << "  <circle class=\"" << css_class << "\" cx=\"" << num(f.x(goal.x)) << "\" cy=\"" << num(f.y(goal.y))
      << "\" r=\"" << num(radius_px) << "\" fill=\"none\" stroke=\"" << kGoalStroke << "\" stroke-width=\"1.5\"/>\n";
}

}  // namespace pullout::cli::svg
