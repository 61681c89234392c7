// Loading of scenario files (see scenario.hpp for the format).
#include "pullout/config/scenario.hpp"

#include <cmath>
#include <filesystem>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "config/config_detail.hpp"
#include "config/grid_file.hpp"
#include "config/yaml_fields.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/model/names.hpp"

namespace pullout {
namespace {

using yaml_fields::MapReader;
using yaml_fields::Problems;

// Scenario requests carry a fixed id: a client sending one assigns its own.
constexpr std::uint64_t kScenarioRequestId = 1;

std::optional<Point2> read_point(const YAML::Node& node, const std::string& path, Problems& problems) {
  if (!node.IsSequence() || node.size() != 2) {
    problems.push_back(path + ": expected [x, y]" + yaml_fields::where(node));
    return std::nullopt;
  }
  const auto x = yaml_fields::to_double(node[0], path + ".x", problems);
  const auto y = yaml_fields::to_double(node[1], path + ".y", problems);
  if (!x || !y) return std::nullopt;
  return Point2{*x, *y};
}

// A list of [x, y] points. `min_points` > 0 also checks the count.
std::vector<Point2> read_points(MapReader& r, const std::string& key, std::size_t min_points) {
  std::vector<Point2> points;
  const YAML::Node n = r.get(key);
  const std::string path = r.key_path(key);
  if (!n.IsDefined()) {
    if (min_points > 0) r.problems().push_back(path + ": required");
    return points;
  }
  if (!n.IsSequence()) {
    r.problems().push_back(path + ": expected a list of [x, y] points" + yaml_fields::where(n));
    return points;
  }
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (auto p = read_point(n[i], yaml_fields::indexed(path, i), r.problems())) points.push_back(*p);
  }
  if (n.size() < min_points) {
    r.problems().push_back(path + ": needs at least " + std::to_string(min_points) + " points, got " +
                           std::to_string(n.size()) + yaml_fields::where(n));
  }
  return points;
}

// yaw [rad] or yaw_deg; neither means 0.
double read_yaw(MapReader& r) {
  double yaw = 0.0;
  double yaw_deg = 0.0;
  const bool has_rad = r.read("yaw", yaw);
  const bool has_deg = r.read("yaw_deg", yaw_deg);
  if (r.has("yaw") && r.has("yaw_deg")) {
    r.problems().push_back(r.key_path("yaw_deg") + ": give either yaw [rad] or yaw_deg, not both");
  }
  const double value = has_deg ? yaw_deg * kDegToRad : (has_rad ? yaw : 0.0);
  // Within [-pi, pi], as a request's quaternion gives it (yaw_deg: 1e10 was echoed as 174532925
  // rad); NaN and infinity are left for the request's validation to name.
  return std::isfinite(value) && std::abs(value) > kPi ? normalize_angle(value) : value;
}

// {x, y, yaw | yaw_deg}
Pose2 read_pose(MapReader& parent, const std::string& key, bool required) {
  Pose2 pose;
  if (!parent.has(key)) {
    parent.get(key);
    if (required) parent.problems().push_back(parent.key_path(key) + ": required ({x, y, yaw_deg})");
    return pose;
  }
  MapReader r(parent.get(key), parent.key_path(key), parent.problems());
  if (!r.valid()) return pose;
  if (!r.read("x", pose.x) && !r.has("x")) r.problems().push_back(r.key_path("x") + ": required");
  if (!r.read("y", pose.y) && !r.has("y")) r.problems().push_back(r.key_path("y") + ": required");
  pose.yaw = read_yaw(r);
  r.finish();
  return pose;
}

Lane read_lane(const YAML::Node& node, const std::string& path, Problems& problems) {
  Lane lane;
  MapReader r(node, path, problems);
  if (!r.valid()) return lane;
  if (!r.read("id", lane.id) && !r.has("id")) problems.push_back(r.key_path("id") + ": required");
  std::string subtype;
  if (r.read("subtype", subtype)) {
    if (const auto s = lane_subtype_from_string(subtype)) {
      lane.subtype = *s;
    } else {
      problems.push_back(r.key_path("subtype") + ": unknown subtype '" + subtype +
                         "' (expected road or road_shoulder)" + yaml_fields::where(r.get("subtype")));
    }
  }
  r.read("speed_limit", lane.speed_limit_mps);
  lane.left_bound = read_points(r, "left_bound", 2);
  lane.right_bound = read_points(r, "right_bound", 2);
  lane.centerline = read_points(r, "centerline", 0);
  if (r.has("centerline") && !lane.centerline.empty() && lane.centerline.size() < 2) {
    problems.push_back(r.key_path("centerline") + ": needs at least 2 points when given");
  }
  r.finish();
  return lane;
}

template <typename Item, typename ReadItem>
std::vector<Item> read_list(MapReader& r, const std::string& key, ReadItem read_item) {
  std::vector<Item> items;
  const YAML::Node n = r.get(key);
  if (!n.IsDefined() || n.IsNull()) return items;
  const std::string path = r.key_path(key);
  if (!n.IsSequence()) {
    r.problems().push_back(path + ": expected a list" + yaml_fields::where(n));
    return items;
  }
  for (std::size_t i = 0; i < n.size(); ++i) items.push_back(read_item(n[i], yaml_fields::indexed(path, i), i));
  return items;
}

// {time_step, confidence, points: [[x, y], ...]}: poses every time_step seconds from now; each
// pose heads towards the next point (the last keeps the previous heading).
PredictedPath read_predicted_path(const YAML::Node& node, const std::string& path, Problems& problems) {
  PredictedPath out;
  MapReader r(node, path, problems);
  if (!r.valid()) return out;
  if (r.read("time_step", out.time_step_s) && !(out.time_step_s > 0.0)) {
    problems.push_back(r.key_path("time_step") + ": must be > 0");
  }
  if (r.read("confidence", out.confidence) && !(out.confidence >= 0.0 && out.confidence <= 1.0)) {
    problems.push_back(r.key_path("confidence") + ": must be in [0, 1]");
  }
  const std::vector<Point2> points = read_points(r, "points", 1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    Pose2 pose{points[i].x, points[i].y, 0.0};
    if (i + 1 < points.size()) {
      pose.yaw = std::atan2(points[i + 1].y - points[i].y, points[i + 1].x - points[i].x);
    } else if (i > 0) {
      pose.yaw = out.poses.back().yaw;
    }
    out.poses.push_back(pose);
  }
  r.finish();
  return out;
}

Object read_object(const YAML::Node& node, const std::string& path, std::size_t index, Problems& problems) {
  Object object;
  object.id = static_cast<std::int64_t>(index);  // default: the position in the list
  MapReader r(node, path, problems);
  if (!r.valid()) return object;
  r.read("id", object.id);
  std::string name;
  if (r.read("class", name)) {
    if (const auto c = object_class_from_string(name)) {
      object.object_class = *c;
    } else {
      problems.push_back(r.key_path("class") + ": unknown class '" + name +
                         "' (expected unknown, car, truck, bus, trailer, motorcycle, bicycle or pedestrian)" +
                         yaml_fields::where(r.get("class")));
    }
  }
  if (!r.read("x", object.pose.x) && !r.has("x")) problems.push_back(r.key_path("x") + ": required");
  if (!r.read("y", object.pose.y) && !r.has("y")) problems.push_back(r.key_path("y") + ": required");
  object.pose.yaw = read_yaw(r);
  if (r.read("length", object.length_m) && !(object.length_m > 0.0)) {
    problems.push_back(r.key_path("length") + ": must be > 0");
  }
  if (r.read("width", object.width_m) && !(object.width_m > 0.0)) {
    problems.push_back(r.key_path("width") + ": must be > 0");
  }
  r.read("velocity", object.velocity_mps);
  object.predicted_paths =
      read_list<PredictedPath>(r, "predicted_paths", [&](const YAML::Node& n, const std::string& p, std::size_t) {
        PredictedPath path = read_predicted_path(n, p, problems);
        // A single point has no heading of its own: the object's.
        if (path.poses.size() == 1) path.poses[0].yaw = object.pose.yaw;
        return path;
      });
  object.polygon = read_points(r, "polygon", 0);
  if (r.has("polygon") && object.polygon.size() < 3) {
    problems.push_back(r.key_path("polygon") + ": needs at least 3 points when given");
  }
  r.finish();
  return object;
}

// {preferred: id, primitives: [id, ...]}: one segment of an Autoware route; primitives default to
// [preferred].
RouteSegment read_route_segment(const YAML::Node& node, const std::string& path, Problems& problems) {
  RouteSegment out;
  MapReader r(node, path, problems);
  if (!r.valid()) return out;
  if (!r.read("preferred", out.preferred_id) && !r.has("preferred")) {
    problems.push_back(r.key_path("preferred") + ": required (the segment's preferred lanelet id)");
  }
  out.primitive_ids =
      read_list<std::int64_t>(r, "primitives", [&](const YAML::Node& n, const std::string& p, std::size_t) {
        return yaml_fields::to_int(n, p, problems).value_or(0);
      });
  if (r.has("primitives") && out.primitive_ids.empty()) {
    problems.push_back(r.key_path("primitives") + ": must name at least one lanelet when given");
  }
  r.finish();
  return out;
}

void read_expectation(MapReader& parent, ScenarioExpectation& out) {
  MapReader r(parent.get("expect"), "expect", parent.problems());
  if (!r.valid()) return;
  bool found = false;
  if (r.read("found", found)) out.found = found;
  std::string planner;
  if (r.read("planner", planner)) {
    if (const auto p = parse_planner_name(planner)) {
      out.planner = *p;
    } else {
      r.problems().push_back(r.key_path("planner") + ": unknown planner '" + planner + "'" +
                             yaml_fields::where(r.get("planner")));
    }
  }
  double margin = 0.0;
  if (r.read("margin", margin)) out.margin_m = margin;
  bool safe = true;
  if (r.read("safe", safe)) out.safe = safe;
  std::int64_t stop_object = 0;
  if (r.read("stops_before_object", stop_object)) out.stops_before_object = stop_object;
  std::string waits_for;
  if (r.read("waits_for", waits_for)) out.waits_for = waits_for;
  r.finish();
}

// The request-level overrides a scenario's `planner:` section implies, so that a scenario sent to
// a running service (which has its own parameters) searches the same planners in the same way.
void set_overrides(const YAML::Node& planner, const StartPlannerParameters& params, PlannerOverrides& out) {
  if (!planner.IsMap()) return;
  if (planner["search_priority"].IsDefined()) out.search_priority = params.search_priority;
  if (planner["search_policy"].IsDefined()) out.search_policy = params.search_policy;
}

// The dotted keys under `planner:` (at `prefix`) that set_overrides does not carry, in file order.
void collect_local_keys(const YAML::Node& node, const std::string& prefix, std::vector<std::string>& out) {
  for (const auto& entry : node) {
    const std::string name = entry.first.as<std::string>("?");
    if (prefix.empty() && (name == "search_priority" || name == "search_policy")) continue;
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    if (entry.second.IsMap()) {
      collect_local_keys(entry.second, key, out);
    } else {
      out.push_back(key);
    }
  }
}

// `vehicle:` (at `key`): either `{profile: NAME}` (a profile of the config the request is planned
// with: the request names it, and the service resolves it) or dimension keys over the base
// config's vehicle (the request carries them all). `vehicle` gets what the CLI draws.
void read_vehicle(const YAML::Node& node, const std::string& key, const Config& base, VehicleInfo& vehicle,
                  PullOutRequest& request, Problems& problems) {
  if (node.IsMap() && node["profile"].IsDefined()) {
    const auto name = yaml_fields::to_string(node["profile"], key + ".profile", problems);
    if (node.size() > 1) {
      problems.push_back(key + ".profile: give a profile or the vehicle's dimensions, not both" +
                         yaml_fields::where(node));
    }
    if (!name) return;
    request.vehicle_profile = *name;
    const auto it = base.vehicle_profiles.find(*name);
    if (it != base.vehicle_profiles.end()) vehicle = it->second;  // else the planner rejects the name
    return;
  }
  apply_vehicle_info(node, key, vehicle, problems);
  request.vehicle = vehicle;
}

// `fleet:`: the other vehicles, each {vehicle_id, start, goal, start_velocity, vehicle} on this
// scenario's lanes and objects.
void read_fleet(MapReader& root, const Config& base, Scenario& s, Problems& problems) {
  const YAML::Node list = root.get("fleet");
  if (!list.IsSequence()) {
    problems.push_back("fleet: expected a list of vehicles" + yaml_fields::where(list));
    return;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = yaml_fields::indexed("fleet", i);
    MapReader r(list[i], key, problems);
    if (!r.valid()) continue;
    PullOutRequest other = s.request;
    other.vehicle_profile.clear();
    other.vehicle.reset();
    if (!r.read("vehicle_id", other.vehicle_id)) problems.push_back(r.key_path("vehicle_id") + ": required");
    if (other.vehicle_id == s.request.vehicle_id) {
      problems.push_back(r.key_path("vehicle_id") + ": '" + other.vehicle_id + "' is this scenario's own vehicle");
    }
    other.ego_pose = read_pose(r, "start", true);
    other.ego_velocity_mps = 0.0;
    r.read("start_velocity", other.ego_velocity_mps);
    other.goal_pose = read_pose(r, "goal", true);
    VehicleInfo vehicle = base.vehicle;
    if (r.has("vehicle")) read_vehicle(r.get("vehicle"), r.key_path("vehicle"), base, vehicle, other, problems);
    r.finish();
    s.fleet.push_back(std::move(other));
  }
}

}  // namespace

Scenario load_scenario(const std::string& path, const Config& base) {
  const YAML::Node doc = load_yaml_file(path);
  Scenario s;
  s.path = path;
  s.vehicle = base.vehicle;
  s.parameters = base.start_planner;
  Problems problems;
  MapReader root(doc, "", problems);
  if (!root.valid()) throw ConfigError(path, std::move(problems));

  root.read("description", s.description);
  PullOutRequest& request = s.request;
  request.vehicle_id = std::filesystem::path(path).stem().string();
  root.read("vehicle_id", request.vehicle_id);
  if (request.vehicle_id.empty()) problems.push_back("vehicle_id: must not be empty");
  request.request_id = kScenarioRequestId;

  if (root.has("vehicle")) read_vehicle(root.get("vehicle"), "vehicle", base, s.vehicle, request, problems);
  std::string map_file;
  if (root.read("map", map_file)) {
    std::filesystem::path file(map_file);
    if (file.is_relative()) file = std::filesystem::path(path).parent_path() / file;
    s.map_path = file.lexically_normal().string();
    try {
      s.map = load_lanelet_map(s.map_path);
    } catch (const MapLoadError& e) {
      problems.push_back(std::string("map: ") + e.what());
    }
  }
  // route: lanelet ids in driving order, or Autoware route segments ({preferred, primitives}); the
  // first item decides which.
  const YAML::Node route_node = root.has("route") ? root.get("route") : YAML::Node();
  const bool by_segments = route_node.IsSequence() && route_node.size() > 0 && route_node[0].IsMap();
  if (by_segments) {
    request.route_segments = read_list<RouteSegment>(
        root, "route",
        [&](const YAML::Node& n, const std::string& p, std::size_t) { return read_route_segment(n, p, problems); });
  } else {
    request.route_lanelet_ids =
        read_list<std::int64_t>(root, "route", [&](const YAML::Node& n, const std::string& p, std::size_t) {
          if (n.IsMap()) {
            problems.push_back(p +
                               ": expected a lanelet id, like route[0] (or every item a segment {preferred, "
                               "primitives})" +
                               yaml_fields::where(n));
            return std::int64_t{0};
          }
          return yaml_fields::to_int(n, p, problems).value_or(0);
        });
  }
  if (root.has("route") && !has_route(request)) problems.push_back("route: must name at least one lanelet");
  if (root.has("map") && !root.has("route")) {
    problems.push_back("route: required with map: (the road lanelet ids to pull out onto, in driving order)");
  }

  request.lanes = read_list<Lane>(
      root, "lanes", [&](const YAML::Node& n, const std::string& p, std::size_t) { return read_lane(n, p, problems); });
  if (root.has("lanes") && root.has("route")) {
    problems.push_back("lanes: give either inline lanes or a route (map: and route:), not both");
  }
  if (root.has("grid")) {
    OccupancyGrid grid;
    if (read_scenario_grid(root, std::filesystem::path(path).parent_path().string(), base.service.limits, grid)) {
      request.occupancy_grid = std::move(grid);
    }
  }
  if (!root.has("lanes") && !root.has("route") && !root.has("grid")) {
    problems.push_back(
        "lanes: required (the inline lanes, map: and route: for a Lanelet2 map, or a grid for a pure freespace "
        "problem)");
  }

  request.ego_pose = read_pose(root, "start", true);
  root.read("start_velocity", request.ego_velocity_mps);
  request.goal_pose = read_pose(root, "goal", true);
  request.objects = read_list<Object>(root, "objects", [&](const YAML::Node& n, const std::string& p, std::size_t i) {
    return read_object(n, p, i, problems);
  });

  if (root.has("planner")) {
    const YAML::Node planner = root.get("planner");
    apply_start_planner_parameters(planner, "planner", s.parameters, problems);
    append_parameter_issues(validate_parameters(s.parameters), "planner", problems);  // between keys
    set_overrides(planner, s.parameters, request.overrides);
    if (planner.IsMap()) collect_local_keys(planner, "", s.local_planner_keys);
  }
  if (root.read("deadline_ms", request.deadline_ms) && request.deadline_ms < 0.0) {
    problems.push_back("deadline_ms: must be >= 0 (0 = the default)");
  }
  if (root.has("expect")) read_expectation(root, s.expect);
  if (root.has("fleet")) read_fleet(root, base, s, problems);
  root.finish();

  if (!problems.empty()) throw ConfigError(path, std::move(problems));
  return s;
}

}  // namespace pullout
