// The lanes of a route request on a Lanelet2 map: which lanelets the pipeline plans on.
//
// As Autoware's start planner determines them:
//   - pull-out lanes: when a road_shoulder lanelet contains the start pose (within
//     start_tolerance_m, half the vehicle width), the shoulder's lanelet sequence (road_shoulder
//     predecessors up to backward_length_m behind it, successors up to forward_length_m ahead);
//     otherwise the road lanes.
//   - road lanes: the route lanelet nearest to the start pose, with the route lanelets around it
//     up to backward_length_m behind and forward_length_m ahead; where the route ends before
//     that, it is extended through the map's road predecessors / successors (preferring a lanelet
//     tagged turn_direction=straight or untagged, then the one in the route).
//   - the lanes handed to the core: the road lanes, the pull-out lanes and the road or shoulder
//     lanelets that contain the start pose, converted to inline Lanes (to_lane).
//
// Failure modes, as request issues naming the field (nothing else is set then):
//   route_lanelet_ids[i]: an id not on the map, a lanelet that is not a road, a lanelet listed
//     twice, a lanelet that follows neither the one before it nor a lane-change neighbour of that
//     one (route not connected);
//   route_segments[i].preferred_primitive / .primitives[j] (an Autoware route, request.route_segments):
//     the same per lanelet; a primitive that is no lane-change neighbour (through left / right
//     neighbours) of the preferred lanelet; a preferred lanelet missing from non-empty primitives;
//   route_segments[i]: no lanelet of the segment follows one of segment i-1 (route not connected);
//   ego_pose: no road or road_shoulder lanelet within start_tolerance_m of the start;
//   route_lanelet_ids / route_segments: no route lanelet within max_route_distance_m of the start.
//
// Route segments: the road lanes start from the route lanelet nearest to the vehicle (any
// primitive) and follow successors that are primitives of the next segments (the preferred
// first); every primitive of a segment along the road lanes is handed to the core too, so that
// paths may use the lane-change neighbours (as Autoware's lane departure check does).
#pragma once

#include <cstdint>
#include <vector>

#include "pullout/maps/lanelet_map.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

struct MapLaneOptions {
  double backward_length_m{25.0};     // [m] road and shoulder lanes kept behind the start
  double forward_length_m{300.0};     // [m] ... and ahead of it
  double start_tolerance_m{0.95};     // [m] a lanelet this close to the start pose holds it
  double max_route_distance_m{10.0};  // [m] the route must pass this close to the start
};

struct MapLanes {
  std::vector<Lane> lanes;
  std::vector<std::int64_t> road_ids;       // the road lanes, in driving order
  std::vector<std::int64_t> pull_out_ids;   // the shoulder sequence, in driving order; empty: the road lanes
  std::vector<std::int64_t> neighbour_ids;  // lane-change neighbours from the route's segments along the road
  std::vector<RequestIssue> issues;
};

MapLanes select_map_lanes(const LaneletMap& map, const PullOutRequest& request, const MapLaneOptions& options);

}  // namespace pullout
