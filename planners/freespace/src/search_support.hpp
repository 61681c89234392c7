// Internal pieces of the hybrid A* search: driving arcs, checking them against the costmap, the
// obstacle-aware distance heuristic, and the lattice's node table.
#pragma once

#include <cstdint>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "pullout/freespace/costmap.hpp"
#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/model/types.hpp"

namespace pullout::freespace_detail {

// The pose after driving `distance` [m] (negative: reverse) on an arc of `curvature` [1/m]
// (0: straight; positive turns left) from `from`.
Pose2 drive(const Pose2& from, double curvature, double distance);

// An arc from a pose: its start, with cos and sin of the start heading computed once, and the
// pose after any length along it (one sincos per pose).
class Arc {
 public:
  Arc(const Pose2& from, double curvature);
  // cos_yaw, sin_yaw: std::cos and std::sin of from.yaw (the checker gets them from at()).
  Arc(const Pose2& from, double cos_yaw, double sin_yaw, double curvature);
  // The pose after `distance` [m] (negative: reverse), with cos and sin of its heading.
  Pose2 at(double distance, double& cos_yaw, double& sin_yaw) const;
  Pose2 at(double distance) const;
  double curvature() const { return curvature_; }

 private:
  Pose2 from_;
  double cos_{1.0};
  double sin_{0.0};
  double curvature_{0.0};
};

// True when the footprint stays clear of every occupied cell over the whole arc, the motion
// between the poses tested included. The start is known to be free with clearance lower bound
// `start_clearance` [m] (0 when unknown beyond being free) and is not tested again; the end is
// tested exactly and `end_clearance` receives its clearance bound.
//
// While the vehicle drives a length l on the arc no point of it moves farther than
// sweep_factor * l, so the clearance bounds of the start and the end prove stretches next to them
// free. The rest is covered by hull tests (GridCollisionChecker::sweep_collides) of poses at most
// 0.15 rad apart in heading, grown by the sagitta of that turn (at most 1.5 cm for a body point
// 5.5 m from the turning centre): conservative by that much, never optimistic.
bool arc_free(const GridCollisionChecker& checker, const Arc& arc, double start_clearance, double distance,
              double& end_clearance);
// The same, also giving the end pose (arc.at(distance), the value the test used), so that a caller
// does not drive the arc a second time.
bool arc_free(const GridCollisionChecker& checker, const Arc& arc, double start_clearance, double distance,
              double& end_clearance, Pose2& end);

// The length [m] of a collision-free prefix of the arc ("drive until contact"), at least
// `min_length`, or 0 when there is none: the motion is driven until a sample (a cell of body
// motion apart) collides, and the longest prefix up to the last free sample that arc_free accepts
// is found by bisection (to 1/32 of the interval). The start is known to be free with clearance
// bound `start_clearance`, as for arc_free.
double free_prefix(const GridCollisionChecker& checker, const Arc& arc, double start_clearance, double distance,
                   double min_length);

// A quick necessary condition for arc_free: the poses every `spacing` [m] along the arc and its
// end are free (exact tests). Most arcs that collide fail here at a fraction of the cost.
bool arc_samples_free(const GridCollisionChecker& checker, const Pose2& from, double curvature, double distance,
                      double spacing);

// Shortest 8-connected distance [m] from the goal to every cell of a coarse grid laid over the
// costmap, through cells the rear-axle centre can occupy: a coarse cell is blocked only when
// every costmap cell in it lies closer than `half_width` to an obstacle (the disc of that radius
// around the rear axle lies inside the footprint), so no feasible pose is ever cut off.
//
// Narrow places cost more: crossing a cell whose room (the largest obstacle distance in it) is
// below `turning_room` costs 1 + narrow_penalty * (1 - room / turning_room) per metre. A gap the
// rear axle fits through is often one the vehicle cannot turn into; without the charge the plain
// distance leads the search into such gaps, where it floods every heading before it gives up
// (the cost-aware obstacle heuristic of Nav2's Smac planner follows the same idea). The result is
// no longer a lower bound, like any weighted heuristic. narrow_penalty 0: the plain distance.
struct ObstacleHeuristicConfig {
  double half_width{1.0};    // [m] half the footprint's width
  double cell_size{0.5};     // [m] of the coarse grid (a multiple of the costmap's resolution)
  double turning_room{3.0};  // [m]
  double narrow_penalty{0.0};
};

// Computed lazily: the search from the goal runs only until the cells asked for are final, and a
// cell's passability and rate are worked out when the search first reaches it, so the cost
// follows the part of the map the hybrid A* explores, not the map's size. The search from the
// goal is an A* towards the cell the hybrid A* starts from ("reverse resumable A*": D. Silver,
// "Cooperative Pathfinding", AIIDE 2005), its estimate the octile distance (the shortest
// 8-connected path on an empty grid; every rate is at least 1, so it never overestimates and is
// consistent): where a Dijkstra search would settle every cell closer to the goal than the start
// (most of a lot whose goal and start lie at opposite ends, and the distance transform under it),
// it settles a corridor between them. A cell's
// distance is final once nothing left on the open list could still lower it, whatever the order:
// the distances are the same as a Dijkstra search's. Not thread safe (distance() advances the
// search); one per plan.
//
// One distance() may have to flood the whole grid (a pose the goal cannot be reached from): with
// watch(stop), that flood checks the stop condition every 1024 cells it settles, and once it says
// stop, stopped() is set and every distance() returns at once (a value of no use: the hybrid A*
// ends its search on stopped()).
class ObstacleHeuristic {
 public:
  // Distances to `goal`; `toward` is where the queries begin (the hybrid A*'s root).
  ObstacleHeuristic(const Costmap& costmap, const ObstacleHeuristicConfig& config, const Pose2& goal,
                    const Pose2& toward);

  // The stop condition to honour inside distance(); must outlive this object.
  void watch(const StopCondition& stop) { stop_ = &stop; }
  StopReason stopped() const { return stopped_; }

  // Distance [m] from p (map frame) to the goal; +inf when the goal cannot be reached from p.
  double distance(const Pose2& p);

  // The way from p to the goal: the shortest 8-connected path of the distances above pulled taut
  // (any-angle, as Theta* does: a cell's next corner is its next cell's corner when the straight
  // line to it crosses no blocked cell, else its next cell). `yaw` is the direction from p to its
  // cell's next corner, `turning` the sum of the way's turns at its corners from there to the goal
  // [rad]: a staircase of grid steps, as the shortest paths over open ground are, turns nothing,
  // and a way round a corner turns there. `known` is false where the way is not known (p's cell
  // unreachable, or the goal's own cell: no direction). `room`: p's cell has room to turn (its
  // rate is 1: no narrow charge; with narrow_penalty 0 every cell says so).
  struct Way {
    double yaw{0.0};      // [rad] map frame
    double turning{0.0};  // [rad] >= 0
    bool known{false};
    bool room{false};
  };
  Way way(const Pose2& p);

 private:
  // The final distance of coarse cell `c`, running the search as far as that needs.
  float settle(std::int32_t c);
  // The A* estimate of coarse cell `c`: a lower bound of its distance to `toward`'s cell [m].
  float estimate(std::int32_t c) const;
  // Per-metre cost of crossing coarse cell `c` (+inf: blocked), from its costmap cells on first use.
  float rate(std::int32_t c);
  // The rooms (room2_) of the coarse cells of room tile `tile`.
  void fill_room_tile(std::int32_t tile);
  // Fills the way fields of settled cell `c` (and of the cells ahead of it on its way, first).
  void fill_way(std::int32_t c);
  // Whether the straight line between the centres of cells a and b crosses no blocked cell.
  bool visible(std::int32_t a, std::int32_t b);

  const Costmap& costmap_;
  ObstacleHeuristicConfig config_;
  int factor_{1};  // costmap cells per coarse cell, per axis
  int width_{0};
  int height_{0};
  double cell_size_{0.0};
  std::vector<float> distance_;
  std::vector<float> rate_;  // NaN until computed
  // The cell a settled cell's distance came from (its next cell on the way to the goal); -1: none.
  std::vector<std::int32_t> parent_;
  // Per cell, allocated on the first way(): its next corner on the taut way (-2 until computed;
  // the goal's cell is its own) and the turning from there to the goal [rad].
  std::vector<std::int32_t> corner_;
  std::vector<float> turning_;
  std::vector<std::int32_t> chain_;  // scratch of fill_way
  int open_reach_{-1};               // [costmap cells] see rate(); -1: not used
  // The rooms from capped distances (see rate()): the cap [costmap cells] (-1: the rooms are
  // scanned from the distance field instead), and per coarse cell the largest squared distance of
  // its costmap cells [cells^2, capped], filled per tile of kRoomTile cells of a coarse row.
  static constexpr int kRoomTile = 16;
  int room_cap_{-1};
  int room_tiles_per_row_{0};
  std::vector<std::int16_t> room2_;
  std::vector<std::uint8_t> room_tile_ready_;
  int toward_x_{0};  // the coarse cell of `toward`
  int toward_y_{0};
  using Item = std::pair<float, std::int32_t>;  // (distance + estimate, cell)
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open_;
  const StopCondition* stop_{nullptr};
  StopReason stopped_{StopReason::kNone};
  std::size_t settled_{0};  // cells taken off the open list, for the stop checks
};

// The turning [rad] still ahead of a pose that moves in heading `travel_yaw` (its heading, or the
// opposite one when it reverses) where the way to the goal is `way` (known): from its heading of
// travel to the way's direction, then the way's own turning.
double turning_ahead(const ObstacleHeuristic::Way& way, double travel_yaw);

// Open-addressing map from a lattice key to a node index.
class NodeTable {
 public:
  NodeTable();
  // The slot of `key`: *slot is -1 when the key is new (assign the node index to it).
  std::int32_t* find_or_insert(std::uint64_t key);
  std::size_t size() const { return size_; }

 private:
  void grow();
  std::vector<std::uint64_t> keys_;
  std::vector<std::int32_t> values_;
  std::size_t size_{0};
  std::uint64_t mask_{0};
  int shift_{64};  // 64 - log2(slots): a hash's top bits index the slots
};

constexpr std::uint64_t kEmptyKey = std::numeric_limits<std::uint64_t>::max();

}  // namespace pullout::freespace_detail
