// A Lanelet2 map in memory: lanelets with aligned bounds, their topology and a spatial index.
//
// Built once (load_lanelet_map in osm_loader.hpp reads Autoware's OSM files), then immutable:
// every const method may be called concurrently from several threads.
//
// Frames and units: points are in the map frame (metres; the OSM nodes' local_x/local_y, or
// lat/lon projected as osm_loader.hpp describes), speed limits in m/s.
//
// Bounds: both bounds of a lanelet point in its driving direction and the left bound lies on the
// left. A bound drawn the other way in the file is reversed when the lanelet is built: the right
// bound is reversed when the middle of the left bound is not on its left, the left bound when the
// middle of the right bound is not on its right (so a lanelet whose bounds are both drawn against
// the driving direction of the file's ways is driven against them).
//
// Topology, from shared OSM nodes (the Lanelet2 convention): B succeeds A when B's bounds start at
// the nodes where A's bounds end. B is A's left neighbour when B's right bound is A's left bound
// (the same way) in the same direction; likewise on the right.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "pullout/geometry/grid_index.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

enum class LaneletSubtype : std::uint8_t { kRoad = 0, kRoadShoulder = 1, kOther = 2 };
enum class TurnDirection : std::uint8_t { kNone = 0, kStraight = 1, kLeft = 2, kRight = 3 };

// One bound or centerline as read from the map: its OSM way and the node ids at its two ends
// (after alignment).
struct LaneletBound {
  std::int64_t way_id{0};
  std::int64_t front_node{0};
  std::int64_t back_node{0};
  std::vector<Point2> points;
};

struct Lanelet {
  std::int64_t id{0};
  LaneletSubtype subtype{LaneletSubtype::kRoad};
  std::string subtype_name;  // the `subtype` tag as written ("road", "crosswalk", ...)
  LaneletBound left;
  LaneletBound right;
  std::vector<Point2> centerline;  // from a `centerline` member when the map has one, else empty
  double speed_limit_mps{13.89};   // [m/s] the `speed_limit` tag (km/h in the file); 50 km/h when absent
  TurnDirection turn_direction{TurnDirection::kNone};
  double length_m{0.0};         // mean length of the two bounds [m]
  std::vector<Point2> polygon;  // left bound forward, right bound backward
  Aabb box;
  // Topology: indices into LaneletMap::lanelets().
  std::vector<std::size_t> successors;
  std::vector<std::size_t> predecessors;
  std::vector<std::size_t> left_neighbours;
  std::vector<std::size_t> right_neighbours;
};

class LaneletMap {
 public:
  // Aligns the bounds (see the file comment), then derives polygons, boxes, lengths, the topology
  // and the spatial index. Every bound must have at least two points and ids must be unique (the
  // loader checks both); the derived fields and the topology given in `lanelets` are replaced.
  explicit LaneletMap(std::vector<Lanelet> lanelets);

  const std::vector<Lanelet>& lanelets() const { return lanelets_; }
  const Lanelet& lanelet(std::size_t index) const { return lanelets_[index]; }
  std::optional<std::size_t> find(std::int64_t id) const;
  std::size_t count(LaneletSubtype subtype) const;

  // Indices of the lanelets whose polygon contains p (boundary points may go either way), in
  // index order.
  std::vector<std::size_t> lanelets_containing(const Point2& p) const;
  // Indices of the lanelets whose polygon is within `radius` [m] of p (0 when p is inside), in
  // index order.
  std::vector<std::size_t> lanelets_near(const Point2& p, double radius) const;
  // Distance [m] from p to the polygon of lanelet `index` (0 inside).
  double distance_to(std::size_t index, const Point2& p) const;

 private:
  void build_topology();
  void build_index();

  std::vector<Lanelet> lanelets_;
  std::unordered_map<std::int64_t, std::size_t> by_id_;
  // Lanelet indices by the cells (16 m) their bounding boxes cover.
  GridIndex<std::uint32_t> index_{16.0};
};

// The lanelet as an inline lane for the planning core (road and road_shoulder only; nullopt for
// other subtypes).
std::optional<Lane> to_lane(const Lanelet& lanelet);

const char* to_string(LaneletSubtype subtype);

}  // namespace pullout
