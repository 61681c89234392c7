// Cases on real Lanelet2 maps shared by the tests and the benchmarks: from a road_shoulder
// lanelet (the vehicle on its centerline, the route along the road beside it) or from a road
// lanelet (the route ahead of it), as Autoware's start-planner tests place them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "path_oracles.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/maps/lanelet_map.hpp"

namespace pullout {

// Every road and shoulder lanelet polygon of the map: where a path may go (the oracles' lanes).
inline std::vector<Polygon> drivable_polygons(const LaneletMap& map) {
  std::vector<Polygon> out;
  for (const Lanelet& ll : map.lanelets()) {
    if (auto lane = to_lane(ll)) out.push_back(oracle::lane_polygon(*lane));
  }
  return out;
}

// The road lanelet `from` and its road successors (turn_direction=straight first), about
// `length_m` of road in all.
inline std::vector<std::int64_t> route_ahead(const LaneletMap& map, std::size_t from, double length_m = 100.0) {
  std::vector<std::int64_t> route{map.lanelet(from).id};
  double length = map.lanelet(from).length_m;
  for (std::size_t cur = from; length < length_m;) {
    std::optional<std::size_t> next;
    for (std::size_t s : map.lanelet(cur).successors) {
      const Lanelet& ll = map.lanelet(s);
      if (ll.subtype != LaneletSubtype::kRoad) continue;
      if (std::find(route.begin(), route.end(), ll.id) != route.end()) continue;
      if (!next || ll.turn_direction == TurnDirection::kStraight) next = s;
    }
    if (!next) break;
    route.push_back(map.lanelet(*next).id);
    length += map.lanelet(*next).length_m;
    cur = *next;
  }
  return route;
}

// The end of the route's last lanelet's centerline: the goal.
inline Pose2 route_end(const LaneletMap& map, const std::vector<std::int64_t>& route) {
  const LaneWorld last({*to_lane(map.lanelet(*map.find(route.back())))});
  const Polyline& center = last.lanes()[0].centerline;
  return center.pose_at(center.length());
}

// The middle of a lanelet's centerline (derived as the core derives it).
inline Pose2 centerline_middle(const Lanelet& ll) {
  const LaneWorld world({*to_lane(ll)});
  const Polyline& center = world.lanes()[0].centerline;
  return center.pose_at(center.length() / 2.0);
}

struct ShoulderCase {
  std::int64_t shoulder_id{0};
  Pose2 ego;
  std::vector<std::int64_t> route;
  Pose2 goal;
};

// From the middle of a shoulder's centerline onto the road lanelet beside it (sharing a bound);
// nullopt when no road is beside it.
inline std::optional<ShoulderCase> shoulder_case(const LaneletMap& map, const Lanelet& shoulder) {
  std::optional<std::size_t> road;
  for (const auto* side : {&shoulder.left_neighbours, &shoulder.right_neighbours}) {
    for (std::size_t n : *side) {
      if (map.lanelet(n).subtype == LaneletSubtype::kRoad) road = n;
    }
  }
  if (!road) return std::nullopt;
  ShoulderCase c;
  c.shoulder_id = shoulder.id;
  c.route = route_ahead(map, *road);
  c.ego = centerline_middle(shoulder);
  c.goal = route_end(map, c.route);
  return c;
}

}  // namespace pullout
