// The lanes of one request, prepared for planning: polygons, centerlines, topology, a spatial
// index, and the lane-departure test of a footprint against the union of all lanes.
//
// Topology: lane B succeeds lane A when B's bounds start where A's bounds end (both end points
// within 0.1 m). Lanes are expected to be valid (see StartPlanner::validate): at least two points
// per bound and a polygon with non-zero area. Derived centerlines are sampled every 0.5 m, and
// edges cut into 0.5 m pieces, up to 1e5 per line (longer lines get longer steps).
//
// Cost: the building work grows with the lanes' length (samples and edge pieces every 0.5 m), so
// the pipeline crops the lanes to the planning horizon first (lane_crop.hpp) and hands a stop
// condition in: it is checked before every lane and every 1024 samples or edge pieces, and a build
// it stops returns at once with stopped() set. A stopped world is incomplete: plan nothing on it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <vector>

#include "pullout/geometry/grid_index.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/geometry/polyline.hpp"
#include "pullout/model/types.hpp"
#include "pullout/search/stop_condition.hpp"

namespace pullout {

struct LaneGeometry {
  std::int64_t id{0};
  LaneSubtype subtype{LaneSubtype::kRoad};
  Polyline left;
  Polyline right;
  Polyline centerline;  // given, or the midpoints of the bounds resampled by arc length
  Polygon polygon;      // left bound forward, right bound backward
  Aabb box;
  // The polygon cut across the lane into pieces of a few dozen vertices (by normalised arc
  // length on both bounds), so that point-in-lane tests stay cheap on long, dense lanes.
  std::vector<Polygon> pieces;
  std::vector<Aabb> piece_boxes;
  double speed_limit_mps{0.0};
  std::vector<std::size_t> successors;
  std::vector<std::size_t> predecessors;
};

// A sequence of connected lanes and the centerline through them, with the arc-length range each
// lane covers on it.
struct LaneChain {
  std::vector<std::size_t> lanes;
  Polyline centerline;
  std::vector<double> lane_end_s;  // arc length at which lanes[i] ends on `centerline`

  // Index into `lanes` of the lane covering arc length s (clamped).
  std::size_t lane_at(double s) const;
};

// The lane polygon (left bound forward, right bound backward) cut across the lane into pieces at
// common normalised arc lengths of both bounds: about one piece per 16 vertices of the longer
// bound, each cut again where more than 64 vertices of one bound crowd into it, so that a point
// test against one piece costs at most about 130 edges. O(vertices + pieces x log vertices).
std::vector<Polygon> cut_lane_into_pieces(const Polyline& left, const Polyline& right);

// The polygon of a lane as LaneGeometry::polygon has it.
Polygon bounds_polygon(const Lane& lane);
// Whether p lies in one of the lanes: the same answer as LaneWorld(lanes).contains(p), without
// building the world (no index, no outline). O(vertices): for one query, e.g. validation.
bool lanes_contain(const std::vector<Lane>& lanes, const Vec2& p);

// Whether two lane lists are the same bit for bit: ids, subtypes, speed limits and every
// coordinate (compared as stored bits, so that 0.0 and -0.0 differ, as they may for atan2). The
// LaneWorld of one is then the LaneWorld of the other: a caller may reuse a complete world built
// for `a` where it would build one for `b`. O(points).
bool identical_lanes(const std::vector<Lane>& a, const std::vector<Lane>& b);

class LaneWorld {
 public:
  explicit LaneWorld(const std::vector<Lane>& lanes, const StopCondition& stop = {});

  // Why the build was cut short (see the file comment); kNone when the world is complete.
  StopReason stopped() const { return stopped_; }
  // Units of work the build did: centerline points and edge pieces examined. A measure of its
  // memory and time that does not depend on the clock (for tests and benchmarks).
  std::size_t build_work() const { return work_; }
  // Point-edge tests the build made to find the outline of the union (each edge piece's probe
  // against the candidate lane pieces near it): the build's other measure of time.
  std::size_t build_edge_tests() const { return edge_tests_; }

  const std::vector<LaneGeometry>& lanes() const { return lanes_; }
  std::optional<std::size_t> find(std::int64_t id) const;

  // Lanes whose polygon contains p.
  std::vector<std::size_t> lanes_containing(const Vec2& p) const;
  bool contains(const Vec2& p) const;

  // The lane of `subtype` whose centerline is nearest to p (lateral distance), if any.
  std::optional<std::size_t> nearest_lane(const Vec2& p, LaneSubtype subtype) const;

  // The chain of lanes through `seed`, following predecessors back and successors forward (the
  // first one when there are several), without cycles. Built on the first call for a seed and
  // kept: the reference lives as long as the world (a world reused for a vehicle's next request,
  // and shared with its safety monitor, builds each chain once). Thread-safe.
  const LaneChain& chain_through(std::size_t seed) const;
  // The chain of the given lanes in the given order (indices into lanes(); expected to be
  // connected, e.g. a route on a map).
  LaneChain chain_of(const std::vector<std::size_t>& order) const;

  // True when the footprint (corners counter-clockwise) lies inside the union of the lanes: every
  // corner is inside some lane and no footprint edge crosses the outer boundary of the union.
  bool footprint_inside(const std::array<Vec2, 4>& corners) const;

  // The outline of the union of the lanes: pieces of lane edges not shared with a neighbour.
  const std::vector<std::pair<Vec2, Vec2>>& outer_edges() const { return outer_edges_; }

 private:
  void build_topology();
  void build_index(const StopCondition& stop);

  std::vector<LaneGeometry> lanes_;
  StopReason stopped_{StopReason::kNone};
  std::size_t work_{0};
  std::size_t edge_tests_{0};
  // Pieces of lane edges that are not shared with a neighbouring lane: the outline of the union.
  std::vector<std::pair<Vec2, Vec2>> outer_edges_;
  static constexpr double kCellSize = 4.0;  // [m] cells of the indexes
  // Cells of the coarse piece index: 64 fine cells a side.
  static constexpr double kCoarseCellSize = 64 * kCellSize;
  static constexpr std::size_t kNoLane = static_cast<std::size_t>(-1);
  // (lane index, piece index) of the lane pieces, by the cells their boxes cover: the fine index
  // holds pieces covering up to 4096 of its cells, the coarse one the larger pieces (a diagonal
  // lane of a few hundred metres, a bound with a long spike), so that a query meets the large
  // pieces near it rather than every large piece of the world.
  GridIndex<std::pair<std::uint32_t, std::uint32_t>> piece_index_{kCellSize};
  GridIndex<std::pair<std::uint32_t, std::uint32_t>> coarse_piece_index_{kCoarseCellSize};
  // Calls accept(lane) for the lanes other than skip_lane with a piece containing p until it
  // returns true; counts the point-edge tests in *edge_tests when given.
  template <typename F>
  bool any_piece_containing(const Vec2& p, std::size_t skip_lane, F&& accept, std::size_t* edge_tests = nullptr) const;
  // Indices into outer_edges_, by the cells their boxes cover.
  GridIndex<std::uint32_t> edge_index_{kCellSize};
  // chain_through's chains by seed (node-based: references stay valid as it grows).
  struct ChainMemo {
    std::mutex mutex;
    std::unordered_map<std::size_t, LaneChain> by_seed;
  };
  std::unique_ptr<ChainMemo> chains_ = std::make_unique<ChainMemo>();
};

}  // namespace pullout
