#include "pullout/maps/map_lanes.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace pullout {

namespace {

constexpr double kNearestReportRadius = 200.0;  // [m] how far to look for the lanelet named in "off the map"

std::string fixed2(double v) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  os << v;
  return os.str();
}

bool drivable(const Lanelet& ll) { return ll.subtype != LaneletSubtype::kOther; }

// The next lanelet when a chain leaves the route: of `candidates` with `subtype`, prefer the
// straight (or untagged) ones, then the lowest index (the file order: deterministic).
std::optional<std::size_t> choose(const LaneletMap& map, const std::vector<std::size_t>& candidates,
                                  LaneletSubtype subtype, const std::unordered_set<std::size_t>& used) {
  std::optional<std::size_t> best;
  int best_rank = std::numeric_limits<int>::max();
  for (std::size_t c : candidates) {
    const Lanelet& ll = map.lanelet(c);
    if (ll.subtype != subtype || used.count(c) != 0) continue;
    const bool straight = ll.turn_direction == TurnDirection::kStraight || ll.turn_direction == TurnDirection::kNone;
    const int rank = straight ? 0 : 1;
    if (rank < best_rank || (rank == best_rank && c < *best)) {
      best_rank = rank;
      best = c;
    }
  }
  return best;
}

// Extends `chain` (driving order) at its front through predecessors and at its back through
// successors of `subtype` until `behind` / `ahead` metres lie before / after lanelet `anchor`.
void extend(const LaneletMap& map, std::deque<std::size_t>& chain, std::size_t anchor, LaneletSubtype subtype,
            double behind, double ahead) {
  std::unordered_set<std::size_t> used(chain.begin(), chain.end());
  const auto anchor_pos = std::find(chain.begin(), chain.end(), anchor) - chain.begin();
  double covered = 0.0;
  for (auto i = anchor_pos; i > 0; --i) covered += map.lanelet(chain[i - 1]).length_m;
  while (covered < behind) {
    const auto prev = choose(map, map.lanelet(chain.front()).predecessors, subtype, used);
    if (!prev) break;
    chain.push_front(*prev);
    used.insert(*prev);
    covered += map.lanelet(*prev).length_m;
  }
  covered = 0.0;
  for (auto i = static_cast<std::size_t>(anchor_pos) + 1; i < chain.size(); ++i)
    covered += map.lanelet(chain[i]).length_m;
  while (covered < ahead) {
    const auto next = choose(map, map.lanelet(chain.back()).successors, subtype, used);
    if (!next) break;
    chain.push_back(*next);
    used.insert(*next);
    covered += map.lanelet(*next).length_m;
  }
}

// Trims `chain` to the lanelets overlapping [-behind, +ahead] around lanelet `anchor`.
void trim(const LaneletMap& map, std::deque<std::size_t>& chain, std::size_t anchor, double behind, double ahead) {
  auto pos = static_cast<std::size_t>(std::find(chain.begin(), chain.end(), anchor) - chain.begin());
  double covered = 0.0;
  std::size_t first = pos;
  while (first > 0 && covered < behind) covered += map.lanelet(chain[--first]).length_m;
  covered = 0.0;
  std::size_t last = pos;
  while (last + 1 < chain.size() && covered < ahead) covered += map.lanelet(chain[++last]).length_m;
  chain.erase(chain.begin() + static_cast<std::ptrdiff_t>(last) + 1, chain.end());
  chain.erase(chain.begin(), chain.begin() + static_cast<std::ptrdiff_t>(first));
}

// One route segment on the map (indices into map.lanelets()): the preferred lanelet and every
// lanelet of the segment, the preferred one included.
struct MapSegment {
  std::size_t preferred{0};
  std::vector<std::size_t> primitives;
};

bool contains(const std::vector<std::size_t>& v, std::size_t x) { return std::find(v.begin(), v.end(), x) != v.end(); }

// The road lanelets reachable from `from` through left / right neighbours (from included): the
// lanelets a vehicle may change lanes into.
std::vector<std::size_t> lane_change_group(const LaneletMap& map, std::size_t from) {
  std::vector<std::size_t> group{from};
  for (std::size_t k = 0; k < group.size(); ++k) {
    const Lanelet& ll = map.lanelet(group[k]);
    for (const auto* side : {&ll.left_neighbours, &ll.right_neighbours}) {
      for (std::size_t n : *side) {
        if (map.lanelet(n).subtype == LaneletSubtype::kRoad && !contains(group, n)) group.push_back(n);
      }
    }
  }
  return group;
}

// Whether some lanelet of `next` follows some lanelet of `previous`.
bool follows(const LaneletMap& map, const std::vector<std::size_t>& previous, const std::vector<std::size_t>& next) {
  for (std::size_t p : previous) {
    for (std::size_t s : map.lanelet(p).successors) {
      if (contains(next, s)) return true;
    }
  }
  return false;
}

// Checks one lanelet id of the route: on the map, a road lanelet, not listed before (`seen` maps
// ids to the field that named them first). Returns its index when usable.
std::optional<std::size_t> check_lanelet(const LaneletMap& map, std::int64_t id, const std::string& field,
                                         std::unordered_map<std::int64_t, std::string>& seen,
                                         std::vector<RequestIssue>& issues) {
  const auto idx = map.find(id);
  if (!idx) {
    issues.push_back({field, "unknown lanelet id " + std::to_string(id) + ": not on the map"});
    return std::nullopt;
  }
  if (map.lanelet(*idx).subtype != LaneletSubtype::kRoad) {
    issues.push_back({field, "lanelet " + std::to_string(id) + " is a " + map.lanelet(*idx).subtype_name +
                                 " lanelet, not a road: a route runs on road lanelets"});
    return std::nullopt;
  }
  if (const auto [it, fresh] = seen.emplace(id, field); !fresh) {
    issues.push_back({field, "lanelet " + std::to_string(id) + " is listed twice (also " + it->second + ")"});
    return std::nullopt;
  }
  return idx;
}

// route_lanelet_ids: each id one segment. An id follows the one before it, or a lane-change
// neighbour of it (a lane change on the way; that neighbour joins the earlier segment).
std::vector<RequestIssue> check_route_ids(const LaneletMap& map, const std::vector<std::int64_t>& route,
                                          std::vector<MapSegment>& segments) {
  std::vector<RequestIssue> issues;
  std::unordered_map<std::int64_t, std::string> seen;
  std::optional<std::size_t> prev;
  for (std::size_t i = 0; i < route.size(); ++i) {
    const std::string field = "route_lanelet_ids[" + std::to_string(i) + "]";
    const auto current = check_lanelet(map, route[i], field, seen, issues);
    if (current && prev && segments.size() == i) {
      MapSegment& before = segments.back();
      if (!follows(map, {*prev}, {*current})) {
        bool joined = false;
        for (std::size_t n : lane_change_group(map, *prev)) {
          if (n != *prev && follows(map, {n}, {*current})) {
            before.primitives.push_back(n);
            joined = true;
            break;
          }
        }
        if (!joined) {
          issues.push_back({field, "lanelet " + std::to_string(route[i]) + " does not follow lanelet " +
                                       std::to_string(map.lanelet(*prev).id) + " (route_lanelet_ids[" +
                                       std::to_string(i - 1) +
                                       "]) nor a lane-change neighbour of it: the route is "
                                       "not connected"});
        }
      }
    }
    if (current) segments.push_back({*current, {*current}});
    prev = current;
  }
  return issues;
}

// route_segments: each primitive a road lanelet on the map, listed once, a lane-change neighbour
// of the segment's preferred lanelet; some lanelet of each segment follows one of the segment
// before it.
std::vector<RequestIssue> check_route_segments(const LaneletMap& map, const std::vector<RouteSegment>& route,
                                               std::vector<MapSegment>& segments) {
  std::vector<RequestIssue> issues;
  std::unordered_map<std::int64_t, std::string> seen;
  for (std::size_t i = 0; i < route.size(); ++i) {
    const std::string field = "route_segments[" + std::to_string(i) + "]";
    const RouteSegment& in = route[i];
    std::unordered_map<std::int64_t, std::string> preferred_seen;
    const auto preferred = check_lanelet(map, in.preferred_id, field + ".preferred_primitive", preferred_seen, issues);
    if (!preferred) continue;
    MapSegment segment{*preferred, {}};
    const std::vector<std::size_t> group = lane_change_group(map, *preferred);
    bool preferred_listed = in.primitive_ids.empty();
    for (std::size_t j = 0; j < in.primitive_ids.size(); ++j) {
      const std::string pfield = field + ".primitives[" + std::to_string(j) + "]";
      const auto idx = check_lanelet(map, in.primitive_ids[j], pfield, seen, issues);
      if (!idx) continue;
      if (!contains(group, *idx)) {
        issues.push_back({pfield, "lanelet " + std::to_string(in.primitive_ids[j]) +
                                      " is not a lane-change neighbour of the preferred lanelet " +
                                      std::to_string(in.preferred_id) + ": the segment is not connected"});
        continue;
      }
      if (*idx == *preferred) preferred_listed = true;
      segment.primitives.push_back(*idx);
    }
    if (in.primitive_ids.empty()) {
      const auto idx = check_lanelet(map, in.preferred_id, field + ".preferred_primitive", seen, issues);
      if (idx) segment.primitives.push_back(*idx);
    }
    if (!preferred_listed) {
      issues.push_back({field + ".preferred_primitive",
                        "lanelet " + std::to_string(in.preferred_id) + " is not among the segment's primitives"});
    }
    if (segment.primitives.empty()) continue;
    if (!segments.empty() && segments.size() == i && !follows(map, segments.back().primitives, segment.primitives)) {
      issues.push_back({field, "no lanelet of this segment follows a lanelet of route_segments[" +
                                   std::to_string(i - 1) + "]: the route is not connected"});
    }
    segments.push_back(std::move(segment));
  }
  return issues;
}

// The route's road lanes through the vehicle: from `current` (a primitive of segment `at`) back
// through predecessors and on through successors that are primitives of the neighbouring
// segments (the preferred one first), as far as the route goes that way.
std::deque<std::size_t> route_chain(const LaneletMap& map, const std::vector<MapSegment>& segments, std::size_t at,
                                    std::size_t current) {
  const auto pick = [&](const std::vector<std::size_t>& links,
                        const MapSegment& segment) -> std::optional<std::size_t> {
    if (contains(links, segment.preferred) && contains(segment.primitives, segment.preferred)) return segment.preferred;
    for (std::size_t p : segment.primitives) {
      if (contains(links, p)) return p;
    }
    return std::nullopt;
  };
  std::deque<std::size_t> chain{current};
  for (std::size_t k = at; k > 0; --k) {
    const auto prev = pick(map.lanelet(chain.front()).predecessors, segments[k - 1]);
    if (!prev) break;
    chain.push_front(*prev);
  }
  for (std::size_t k = at + 1; k < segments.size(); ++k) {
    const auto next = pick(map.lanelet(chain.back()).successors, segments[k]);
    if (!next) break;
    chain.push_back(*next);
  }
  return chain;
}

}  // namespace

MapLanes select_map_lanes(const LaneletMap& map, const PullOutRequest& request, const MapLaneOptions& options) {
  MapLanes out;
  std::vector<MapSegment> segments;
  const bool by_segments = !request.route_segments.empty();
  const std::string route_field = by_segments ? "route_segments" : "route_lanelet_ids";
  out.issues = by_segments ? check_route_segments(map, request.route_segments, segments)
                           : check_route_ids(map, request.route_lanelet_ids, segments);
  if (!out.issues.empty()) return out;
  if (segments.empty()) {
    out.issues.push_back({route_field, "names no lanelet"});
    return out;
  }

  // Where the vehicle stands.
  const Point2 ego{request.ego_pose.x, request.ego_pose.y};
  std::optional<std::size_t> shoulder;
  double shoulder_distance = std::numeric_limits<double>::infinity();
  std::vector<std::size_t> under;  // drivable lanelets containing the start pose
  bool on_map = false;
  for (std::size_t i : map.lanelets_near(ego, options.start_tolerance_m)) {
    const Lanelet& ll = map.lanelet(i);
    if (!drivable(ll)) continue;
    on_map = true;
    const double d = map.distance_to(i, ego);
    if (d == 0.0) under.push_back(i);
    if (ll.subtype == LaneletSubtype::kRoadShoulder && d < shoulder_distance) {
      shoulder_distance = d;
      shoulder = i;
    }
  }
  if (!on_map) {
    std::optional<std::size_t> nearest;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i : map.lanelets_near(ego, kNearestReportRadius)) {
      if (!drivable(map.lanelet(i))) continue;
      const double d = map.distance_to(i, ego);
      if (d < best) {
        best = d;
        nearest = i;
      }
    }
    std::string problem =
        "(" + fixed2(ego.x) + ", " + fixed2(ego.y) + ") is on no road or road_shoulder lanelet of the map";
    problem += nearest ? " (the nearest, lanelet " + std::to_string(map.lanelet(*nearest).id) + ", is " + fixed2(best) +
                             " m away)"
                       : " (none within " + fixed2(kNearestReportRadius) + " m)";
    out.issues.push_back({"ego_pose", problem});
    return out;
  }

  // The road lanes: the route around its lanelet nearest to the vehicle (of any segment: a
  // lane-change neighbour too, as Autoware's closest lanelet within the route), extended.
  std::size_t current = segments.front().preferred;
  std::size_t current_segment = 0;
  double current_distance = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < segments.size(); ++k) {
    for (std::size_t i : segments[k].primitives) {
      const double d = map.distance_to(i, ego);
      if (d < current_distance) {
        current_distance = d;
        current = i;
        current_segment = k;
      }
    }
  }
  if (current_distance > options.max_route_distance_m) {
    out.issues.push_back({route_field, "does not pass by the vehicle: the nearest route lanelet, " +
                                           std::to_string(map.lanelet(current).id) + ", is " +
                                           fixed2(current_distance) + " m from ego_pose (at most " +
                                           fixed2(options.max_route_distance_m) + " m)"});
    return out;
  }
  std::deque<std::size_t> road = route_chain(map, segments, current_segment, current);
  trim(map, road, current, options.backward_length_m, options.forward_length_m);
  extend(map, road, current, LaneletSubtype::kRoad, options.backward_length_m, options.forward_length_m);

  std::deque<std::size_t> pull_out;
  if (shoulder) {
    pull_out.push_back(*shoulder);
    extend(map, pull_out, *shoulder, LaneletSubtype::kRoadShoulder, options.backward_length_m,
           options.forward_length_m);
  }

  std::unordered_set<std::size_t> added;
  const auto add = [&](std::size_t i) {
    if (!added.insert(i).second) return;
    if (auto lane = to_lane(map.lanelet(i))) out.lanes.push_back(std::move(*lane));
  };
  for (std::size_t i : road) {
    add(i);
    out.road_ids.push_back(map.lanelet(i).id);
  }
  for (std::size_t i : pull_out) {
    add(i);
    out.pull_out_ids.push_back(map.lanelet(i).id);
  }
  for (std::size_t i : under) add(i);
  // The lane-change neighbours of the route's segments along the road lanes: a path may use them
  // (Autoware's departure check takes the route's lanes with their neighbours).
  const std::unordered_set<std::size_t> on_road(road.begin(), road.end());
  for (const MapSegment& segment : segments) {
    const bool along = std::any_of(segment.primitives.begin(), segment.primitives.end(),
                                   [&on_road](std::size_t i) { return on_road.count(i) != 0; });
    if (!along) continue;
    for (std::size_t i : segment.primitives) {
      if (on_road.count(i) == 0) {
        add(i);
        out.neighbour_ids.push_back(map.lanelet(i).id);
      }
    }
  }
  return out;
}

}  // namespace pullout
