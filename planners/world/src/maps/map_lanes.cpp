#include "pullout/maps/map_lanes.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
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

std::vector<RequestIssue> check_route(const LaneletMap& map, const std::vector<std::int64_t>& route,
                                      std::vector<std::size_t>& indices) {
  std::vector<RequestIssue> issues;
  std::unordered_map<std::int64_t, std::size_t> seen;
  std::optional<std::size_t> prev;
  for (std::size_t i = 0; i < route.size(); ++i) {
    const std::string field = "route_lanelet_ids[" + std::to_string(i) + "]";
    const std::int64_t id = route[i];
    const auto idx = map.find(id);
    std::optional<std::size_t> current;
    if (!idx) {
      issues.push_back({field, "unknown lanelet id " + std::to_string(id) + ": not on the map"});
    } else if (map.lanelet(*idx).subtype != LaneletSubtype::kRoad) {
      issues.push_back({field, "lanelet " + std::to_string(id) + " is a " + map.lanelet(*idx).subtype_name +
                                   " lanelet, not a road: a route runs on road lanelets"});
    } else if (const auto [it, fresh] = seen.emplace(id, i); !fresh) {
      issues.push_back({field, "lanelet " + std::to_string(id) + " is listed twice (also route_lanelet_ids[" +
                                   std::to_string(it->second) + "])"});
    } else {
      current = idx;
      if (prev) {
        const auto& succ = map.lanelet(*prev).successors;
        if (std::find(succ.begin(), succ.end(), *idx) == succ.end()) {
          issues.push_back({field, "lanelet " + std::to_string(id) + " does not follow lanelet " +
                                       std::to_string(map.lanelet(*prev).id) + " (route_lanelet_ids[" +
                                       std::to_string(i - 1) + "]): the route is not connected"});
        }
      }
      indices.push_back(*idx);
    }
    prev = current;
  }
  return issues;
}

}  // namespace

MapLanes select_map_lanes(const LaneletMap& map, const PullOutRequest& request, const MapLaneOptions& options) {
  MapLanes out;
  std::vector<std::size_t> route;
  out.issues = check_route(map, request.route_lanelet_ids, route);
  if (!out.issues.empty()) return out;

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

  // The road lanes: the route around its lanelet nearest to the vehicle, extended.
  std::size_t current = route.front();
  double current_distance = std::numeric_limits<double>::infinity();
  for (std::size_t i : route) {
    const double d = map.distance_to(i, ego);
    if (d < current_distance) {
      current_distance = d;
      current = i;
    }
  }
  if (current_distance > options.max_route_distance_m) {
    out.issues.push_back({"route_lanelet_ids", "does not pass by the vehicle: the nearest route lanelet, " +
                                                   std::to_string(map.lanelet(current).id) + ", is " +
                                                   fixed2(current_distance) + " m from ego_pose (at most " +
                                                   fixed2(options.max_route_distance_m) + " m)"});
    return out;
  }
  std::deque<std::size_t> road(route.begin(), route.end());
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
  return out;
}

}  // namespace pullout
