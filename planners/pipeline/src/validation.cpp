// Structural validation of a request: everything that can be checked without building the world.
// Every problem is reported, each naming its field, so a vehicle developer can fix them in one go.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_set>

#include "pullout/geometry/polyline.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "validation.hpp"

namespace pullout {

namespace {

constexpr double kMinBoundLength = 0.1;  // [m]
constexpr double kMinLaneArea = 1e-2;    // [m^2]

class Checker {
 public:
  Checker(const RequestLimits& limits, std::vector<RequestIssue>& issues) : limits_(limits), issues_(issues) {}

  void add(const std::string& field, const std::string& problem) { issues_.push_back({field, problem}); }

  bool finite(const std::string& field, double v) {
    if (std::isfinite(v)) return true;
    add(field, std::string("not a finite number (") + (std::isnan(v) ? "NaN" : "infinite") + ")");
    return false;
  }
  // A finite coordinate within max_coordinate_m of the origin.
  bool coordinate(const std::string& field, const char* axis, double v) {
    if (!finite(field + "." + axis, v)) return false;
    return within_extent(field + "." + axis, std::string("|") + axis + "|", v);
  }
  // |v| <= max_coordinate_m (a length or a coordinate); `what` names it in the message.
  bool within_extent(const std::string& field, const std::string& what, double v) {
    if (std::abs(v) <= limits_.max_coordinate_m) return true;
    std::ostringstream os;
    os << what << " " << std::abs(v) << " exceeds " << limits_.max_coordinate_m << " m";
    add(field, os.str());
    return false;
  }
  // A finite speed within max_speed_mps.
  bool speed(const std::string& field, double v) {
    if (!finite(field, v)) return false;
    if (std::abs(v) <= limits_.max_speed_mps) return true;
    std::ostringstream os;
    os << "|speed| " << std::abs(v) << " exceeds " << limits_.max_speed_mps << " m/s";
    add(field, os.str());
    return false;
  }
  bool pose(const std::string& field, const Pose2& p) {
    bool ok = coordinate(field, "x", p.x);
    ok = coordinate(field, "y", p.y) && ok;
    return finite(field + ".yaw", p.yaw) && ok;
  }
  bool points(const std::string& field, const std::vector<Point2>& pts) {
    if (pts.size() > limits_.max_points_per_line) {
      add(field,
          std::to_string(pts.size()) + " points exceed the limit of " + std::to_string(limits_.max_points_per_line));
      return false;
    }
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const std::string f = field + "[" + std::to_string(i) + "]";
      if (!std::isfinite(pts[i].x) || !std::isfinite(pts[i].y)) {
        add(f, "not a finite point");
        return false;  // one report per line is enough
      }
      if (!within_extent(f + ".x", "|x|", pts[i].x) || !within_extent(f + ".y", "|y|", pts[i].y)) return false;
    }
    return true;
  }
  bool count(const std::string& field, std::size_t n, std::size_t limit, const char* what) {
    if (n <= limit) return true;
    add(field, std::to_string(n) + " " + what + " exceed the limit of " + std::to_string(limit));
    return false;
  }

 private:
  const RequestLimits& limits_;
  std::vector<RequestIssue>& issues_;
};

double lane_area(const Lane& lane) {
  double twice = 0.0;
  std::vector<Point2> ring = lane.left_bound;
  ring.insert(ring.end(), lane.right_bound.rbegin(), lane.right_bound.rend());
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Point2& a = ring[i];
    const Point2& b = ring[(i + 1) % ring.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return std::abs(0.5 * twice);
}

void validate_lane(Checker& c, const std::string& f, const Lane& lane) {
  bool ok = true;
  for (const auto& [name, line] : {std::pair<const char*, const std::vector<Point2>*>{"left_bound", &lane.left_bound},
                                   {"right_bound", &lane.right_bound}}) {
    const std::string lf = f + "." + name;
    if (line->size() < 2) {
      c.add(lf, "needs at least 2 points, has " + std::to_string(line->size()));
      ok = false;
    } else if (!c.points(lf, *line)) {
      ok = false;
    } else if (polyline_length(*line) < kMinBoundLength) {
      std::ostringstream os;
      os << "degenerate: shorter than " << kMinBoundLength << " m";  // 0.1, not to_string's 0.100000
      c.add(lf, os.str());
      ok = false;
    }
  }
  if (!lane.centerline.empty()) {
    if (lane.centerline.size() < 2) {
      c.add(f + ".centerline", "needs at least 2 points when given, has 1");
    } else {
      c.points(f + ".centerline", lane.centerline);
    }
  }
  if (c.finite(f + ".speed_limit_mps", lane.speed_limit_mps) && lane.speed_limit_mps <= 0.0) {
    c.add(f + ".speed_limit_mps", "must be positive");
  }
  if (ok && lane_area(lane) < kMinLaneArea) c.add(f, "degenerate: the left and right bounds enclose no area");
}

void validate_object(Checker& c, const std::string& f, const Object& o, const RequestLimits& limits) {
  c.pose(f + ".pose", o.pose);
  c.speed(f + ".velocity_mps", o.velocity_mps);
  if (o.polygon.empty()) {
    if (c.finite(f + ".length_m", o.length_m) && o.length_m <= 0.0) c.add(f + ".length_m", "must be positive");
    if (c.finite(f + ".width_m", o.width_m) && o.width_m <= 0.0) c.add(f + ".width_m", "must be positive");
    if (std::isfinite(o.length_m)) c.within_extent(f + ".length_m", "length", o.length_m);
    if (std::isfinite(o.width_m)) c.within_extent(f + ".width_m", "width", o.width_m);
  } else if (c.count(f + ".polygon", o.polygon.size(), limits.max_polygon_points, "points")) {
    if (o.polygon.size() < 3) {
      c.add(f + ".polygon", "needs at least 3 points, has " + std::to_string(o.polygon.size()));
    } else {
      c.points(f + ".polygon", o.polygon);
    }
  }
  if (!c.count(f + ".predicted_paths", o.predicted_paths.size(), limits.max_predicted_paths, "paths")) return;
  for (std::size_t k = 0; k < o.predicted_paths.size(); ++k) {
    const PredictedPath& pp = o.predicted_paths[k];
    const std::string pf = f + ".predicted_paths[" + std::to_string(k) + "]";
    if (!c.count(pf, pp.poses.size(), limits.max_predicted_path_points, "poses")) continue;
    if (c.finite(pf + ".time_step_s", pp.time_step_s) && pp.time_step_s <= 0.0)
      c.add(pf + ".time_step_s", "must be positive");
    if (c.finite(pf + ".confidence", pp.confidence) && (pp.confidence < 0.0 || pp.confidence > 1.0))
      c.add(pf + ".confidence", "must be in [0, 1]");
    for (std::size_t i = 0; i < pp.poses.size(); ++i) {
      if (!c.pose(pf + ".poses[" + std::to_string(i) + "]", pp.poses[i])) break;
    }
  }
}

}  // namespace

std::vector<RequestIssue> validate_request_structure(const PullOutRequest& r, const RequestLimits& limits,
                                                     const std::vector<PlannerType>& available, bool has_map,
                                                     bool allow_grid_only) {
  std::vector<RequestIssue> issues;
  Checker c(limits, issues);
  if (r.vehicle_id.empty()) c.add("vehicle_id", "empty");
  if (r.vehicle_id.size() > kMaxVehicleIdBytes) {
    c.add("vehicle_id", "longer than " + std::to_string(kMaxVehicleIdBytes) + " bytes");
  }
  c.pose("ego_pose", r.ego_pose);
  c.speed("ego_velocity_mps", r.ego_velocity_mps);
  c.pose("goal_pose", r.goal_pose);
  if (c.finite("deadline_ms", r.deadline_ms) && (r.deadline_ms < 0.0 || r.deadline_ms > limits.max_deadline_ms)) {
    std::ostringstream os;
    os << "must be in [0, " << limits.max_deadline_ms << "] (0 = the service's default), got " << r.deadline_ms;
    c.add("deadline_ms", os.str());
  }

  if (has_route(r)) {
    const std::string route_field = r.route_segments.empty() ? "route_lanelet_ids" : "route_segments";
    c.count("route_lanelet_ids", r.route_lanelet_ids.size(), limits.max_route_lanelets, "lanelets");
    c.count("route_segments", r.route_segments.size(), limits.max_route_lanelets, "segments");
    std::size_t primitives = 0;
    for (const auto& segment : r.route_segments) primitives += segment.primitive_ids.size();
    c.count("route_segments", primitives, limits.max_route_lanelets, "primitives in all segments");
    if (!has_map) {
      c.add(route_field, "no Lanelet2 map is loaded by this planner: send inline lanes instead");
    } else if (!r.lanes.empty()) {
      c.add("lanes", "give either inline lanes or a route on the map, not both");
    } else if (!r.route_lanelet_ids.empty() && !r.route_segments.empty()) {
      c.add("route_segments", "give either route_lanelet_ids or route_segments, not both");
    }
  } else if (r.lanes.empty() && !(allow_grid_only && r.occupancy_grid)) {
    c.add("lanes", allow_grid_only ? "empty: send at least one lane of subtype road, or an occupancy grid"
                                   : "empty: send at least one lane of subtype road");
  }
  if (c.count("lanes", r.lanes.size(), limits.max_lanes, "lanes")) {
    std::unordered_set<std::int64_t> ids;
    bool has_road = false;
    for (std::size_t i = 0; i < r.lanes.size(); ++i) {
      const std::string f = "lanes[" + std::to_string(i) + "]";
      if (!ids.insert(r.lanes[i].id).second) c.add(f + ".id", "duplicate lane id " + std::to_string(r.lanes[i].id));
      has_road = has_road || r.lanes[i].subtype == LaneSubtype::kRoad;
      validate_lane(c, f, r.lanes[i]);
    }
    if (!r.lanes.empty() && !has_road) c.add("lanes", "no lane of subtype road to pull out onto");
  }

  if (c.count("objects", r.objects.size(), limits.max_objects, "objects")) {
    for (std::size_t i = 0; i < r.objects.size(); ++i) {
      validate_object(c, "objects[" + std::to_string(i) + "]", r.objects[i], limits);
    }
  }

  if (r.occupancy_grid) {
    const OccupancyGrid& g = *r.occupancy_grid;
    const std::size_t cells = static_cast<std::size_t>(g.width) * g.height;
    const bool cell_ok = g.resolution_m >= kMinGridResolution && g.resolution_m <= kMaxGridResolution;
    if (c.finite("occupancy_grid.resolution_m", g.resolution_m) && !cell_ok) {
      std::ostringstream os;
      os << g.resolution_m << " m is outside [" << kMinGridResolution << ", " << kMaxGridResolution << "] m";
      c.add("occupancy_grid.resolution_m", os.str());
    }
    c.pose("occupancy_grid.origin", g.origin);
    // Its far edges within the coordinate limit too, as every other extent of a request (a grid of
    // 16 Mi x 1 cells of 5 m reached 84,000 km from its origin).
    if (cell_ok) {
      c.within_extent("occupancy_grid.width", "width x resolution_m", g.width * g.resolution_m);
      c.within_extent("occupancy_grid.height", "height x resolution_m", g.height * g.resolution_m);
    }
    if (c.count("occupancy_grid", cells, limits.max_grid_cells, "cells") && g.data.size() != cells) {
      c.add("occupancy_grid.data",
            "has " + std::to_string(g.data.size()) + " cells, width x height is " + std::to_string(cells));
    }
  }

  std::unordered_set<int> seen;
  for (std::size_t i = 0; i < r.overrides.search_priority.size(); ++i) {
    const PlannerType t = r.overrides.search_priority[i];
    const std::string f = "overrides.search_priority[" + std::to_string(i) + "]";
    if (std::find(available.begin(), available.end(), t) == available.end()) {
      c.add(f, std::string("planner '") + to_string(t) + "' is not available in this version");
    } else if (!seen.insert(static_cast<int>(t)).second) {
      c.add(f, std::string("planner '") + to_string(t) + "' listed twice");
    }
  }
  return issues;
}

std::vector<RequestIssue> validate_progress(const ExecutionProgress& progress, const RequestLimits& limits) {
  std::vector<RequestIssue> issues;
  Checker c(limits, issues);
  c.pose("progress.pose", progress.pose);
  c.speed("progress.velocity_mps", progress.velocity_mps);
  return issues;
}

std::string format_issues(const std::vector<RequestIssue>& issues) {
  std::string out;
  for (const RequestIssue& i : issues) {
    if (!out.empty()) out += '\n';
    out += i.field + ": " + i.problem;
  }
  return out;
}

}  // namespace pullout
