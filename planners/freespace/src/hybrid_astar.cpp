#include "pullout/freespace/hybrid_astar.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <queue>

#include "pullout/freespace/reeds_shepp.hpp"
#include "pullout/geometry/angle.hpp"
#include "search_support.hpp"

namespace pullout {

namespace fd = freespace_detail;

namespace {

constexpr std::size_t kStopCheckInterval = 16;    // expansions between checks of the stop condition
constexpr int kShotCandidates = 3;                // Reeds-Shepp words tried per shot, cheapest first
constexpr double kShotDistancePerInterval = 4.0;  // [m] heuristic distance per expansion between shots
constexpr double kReedsSheppRange = 4.0;          // [turning radii] see heuristic()
constexpr double kCoarseSpacing = 1.0;            // [m] first-pass sample spacing of a shot
constexpr std::uint64_t kFineKey = 1ULL << 62;    // lattice keys of fine cells
// A node with fewer full-length primitives to new cells than this is constrained (see expand).
constexpr int kOpenPrimitives = 3;
// The plain search counts as stuck near the goal (see plan) within this many lattice cells of it.
constexpr double kNearGoalCells = 2.0;
constexpr double kProgress = 0.25;  // [m] a fall of the distance to the target that counts as progress

struct Node {
  Pose2 pose;
  double g{0.0};
  std::int32_t parent{-1};
  float clearance{0.0F};     // [m] clearance lower bound of the footprint at `pose` (0: near)
  double length{0.0};        // [m] arc length of the primitive that led here (cut short at a contact)
  std::int8_t steer{0};      // steer index of the primitive that led here
  std::int8_t direction{0};  // +1 / -1 of that primitive, 0 at the start
  // [m] obstacle-aware distance from `pose` to the target, set when the node is added (its
  // expansion needs it again for the shots: one lookup instead of two).
  double h2d{0.0};
  bool closed{false};
  bool fine{false};  // its lattice cell is a fine one (see key())
};

// How the last piece (goal region or shot) was reached.
struct Finish {
  std::int32_t node{-1};
  bool shot{false};
  ReedsSheppPath path;
};

// One direction of the search. From the start (forward), it ends in the goal region or with a
// Reeds-Shepp shot to the goal. From the goal (backward), it grows the path backwards in time:
// a primitive it drives forwards is one the vehicle drives in reverse (and is charged so), and it
// ends only with a shot to the exact start (a path must begin where the vehicle is).
class Search {
 public:
  enum class State { kRunning, kFound, kExhausted, kNodeLimit, kStopped };

  // `fine_moves`: constrained nodes also drive until contact and give their children fine cells
  // (needs config.min_primitive_length > 0); else the plain search.
  Search(const GridCollisionChecker& checker, const HybridAStarConfig& config, const Pose2& root, const Pose2& target,
         bool backward, bool fine_moves)
      : checker_(checker),
        costmap_(checker.costmap()),
        config_(config),
        root_(root),
        target_(target),
        backward_(backward),
        fine_moves_(fine_moves && config.min_primitive_length > 0.0),
        rs_(config.turning_radius),
        weights_{config.curve_weight, config.reverse_weight, config.direction_change_weight},
        heuristic_(costmap_, heuristic_config(checker, config), target, root) {}

  // Puts the root (known free, with clearance bound `clearance`) on the open list.
  void begin(const StopCondition& stop, double clearance) {
    heuristic_.watch(stop);
    Node root;
    root.pose = root_;
    root.clearance = static_cast<float>(clearance);
    add_node(root, key(root.pose, root.fine));
  }

  // One expansion (or none, when only superseded entries were popped).
  State step() {
    if (heuristic_.stopped() != StopReason::kNone) return State::kStopped;  // it stopped inside a flood
    while (!open_.empty()) {
      const std::int32_t index = open_.top().second;
      open_.pop();
      Node& top = nodes_[static_cast<std::size_t>(index)];
      if (top.closed) continue;
      top.closed = true;
      ++expansions_;
      const Node node = top;
      if (config_.expanded_poses != nullptr) config_.expanded_poses->push_back(node.pose);
      if (!backward_ && in_goal_region(node.pose)) {
        finish_.node = index;
        return State::kFound;
      }
      // Analytic expansion: every expansion near the target, less often far from it.
      const double h2d = node.h2d;
      if (h2d < best_h2d_ - kProgress) {
        best_h2d_ = h2d;
        last_progress_ = expansions_;
      }
      const auto interval = static_cast<std::size_t>(std::max(1.0, h2d / kShotDistancePerInterval));
      if (++since_shot_ >= interval) {
        since_shot_ = 0;
        ++shots_;
        if (shoot(node, finish_.path)) {
          finish_.node = index;
          finish_.shot = true;
          return State::kFound;
        }
      }
      if (nodes_.size() >= config_.max_nodes) return State::kNodeLimit;
      expand(index);
      return heuristic_.stopped() != StopReason::kNone ? State::kStopped : State::kRunning;
    }
    return State::kExhausted;
  }

  // Whether the root is in a tight spot (fewer than kOpenPrimitives primitives lead out of its
  // cell): known after the first step.
  bool root_constrained() const { return root_constrained_; }
  std::size_t expansions() const { return expansions_; }
  // Expansions since the obstacle-aware distance to the target last fell by kProgress.
  std::size_t since_progress() const { return expansions_ - last_progress_; }
  // The least obstacle-aware distance to the target of the poses expanded so far [m].
  double best_distance() const { return best_h2d_; }
  std::size_t nodes() const { return nodes_.size(); }
  std::size_t shots() const { return shots_; }
  StopReason heuristic_stopped() const { return heuristic_.stopped(); }

  // The path of a search that found one, from the start to the goal (or the pose in the goal
  // region) in the vehicle's direction of travel.
  void result(HybridAStarResult& out) const {
    out.reached_exact_goal = backward_ || finish_.shot;
    build_waypoints(out);
    out.found_from_goal = backward_;
  }

 private:
  static double xy_resolution(const HybridAStarConfig& config) {
    return config.xy_resolution > 0.0 ? config.xy_resolution : config.primitive_length;
  }
  double xy_resolution() const { return xy_resolution(config_); }

  static fd::ObstacleHeuristicConfig heuristic_config(const GridCollisionChecker& checker,
                                                      const HybridAStarConfig& config) {
    const Footprint& f = checker.footprint();
    fd::ObstacleHeuristicConfig h;
    h.half_width = 0.5 * f.width();
    h.cell_size = xy_resolution(config);
    // The room the body needs to turn about its middle: half its diagonal.
    h.turning_room = 0.5 * std::hypot(f.length(), f.width());
    h.narrow_penalty = config.narrow_heuristic_penalty;
    return h;
  }

  // The lattice cell of a pose: coarse, or (children of a constrained node, see expand) fine in
  // position and heading, where poses a few centimetres apart differ in what they can reach.
  std::uint64_t key(const Pose2& p, bool fine) const {
    const double cell = fine ? config_.fine_xy_resolution : xy_resolution();
    const int bins = fine ? config_.theta_size * config_.fine_theta_factor : config_.theta_size;
    const Vec2 g = costmap_.to_grid({p.x, p.y}) * (costmap_.resolution() / cell);
    const auto ix = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(g.x())) + (1 << 19));
    const auto iy = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(g.y())) + (1 << 19));
    const double bin = kTwoPi / bins;
    auto it = static_cast<std::int64_t>(std::floor((normalize_angle(p.yaw) + kPi) / bin));
    it = ((it % bins) + bins) % bins;
    return (fine ? kFineKey : 0) | (ix << 41) | (iy << 20) | static_cast<std::uint64_t>(it);
  }

  // Plain Reeds-Shepp length: the cost weights make the true cost larger still, but a weighted
  // Reeds-Shepp bound steers the search into obstacles the 2D distance goes around (measured:
  // 20x more expansions around a wall).
  // Far from the goal the 2D distance dominates (a Reeds-Shepp path exceeds the straight line by
  // at most a few turning radii, and obstacles lengthen the 2D distance): the Reeds-Shepp term,
  // the costliest part of an expansion, is only computed within kReedsSheppRange radii. There the
  // Reeds-Shepp distance sees the turns to the goal; the turning charge (turning_charge) is added
  // beyond it only (added near the goal too, it cost TPCAP case 7 twelve more direction changes).
  // `h2d`: the obstacle-aware distance of p (heuristic_.distance(p)); `direction`: see
  // turning_charge.
  double heuristic(const Pose2& p, double h2d, int direction) const {
    if (!std::isfinite(h2d)) return h2d;
    if (h2d > kReedsSheppRange * config_.turning_radius) {
      return config_.distance_heuristic_weight * h2d + turning_charge(p, direction);
    }
    return config_.distance_heuristic_weight * std::max(h2d, rs_.distance(p, target_));
  }

  // The least curve cost of the turning still ahead of p (turning_heuristic_weight > 0): from its
  // heading of travel to the way's direction, then the way's own turning. Turning an angle takes
  // at least turning_radius x angle of arc at full steer, which costs curve_weight per metre more
  // than a straight primitive (times 1 + reverse_weight in reverse); the distance term charges the
  // straight part. Without it, at distance_heuristic_weight 1 + reverse_weight a reversing path's
  // f stays flat along its straight stretches and rises at its corners only, so every reversing
  // pose whose detour costs less than the corners still ahead is expanded before the path ends
  // (bench/RESULTS.md, the slow lot).
  // The pose is taken to travel in the direction in which it faces along the way (forwards when
  // its heading is within 90 degrees of the way's direction), plus a change of direction when that
  // is not the direction of the primitive that led to it (`direction`; 0 at the root). Charging
  // the primitive's own direction instead made a pose that backs out of a bay turned away from the
  // way pay for turning round in reverse, where the path changes direction and turns forwards:
  // that f bump flooded lots 4, 6, 16 and 24 (12,000-33,000 expansions); the cheaper of the two
  // directions made a reversing pose turned 45 degrees off the aisle as cheap as an aligned one
  // (the slow lot: 6,093 expansions against 693).
  double turning_charge(const Pose2& p, int direction) const {
    if (config_.turning_heuristic_weight <= 0.0) return 0.0;
    const fd::ObstacleHeuristic::Way way = heuristic_.way(p);
    // Where the cell has no room to turn (the narrow charge applies), a car turns with short moves
    // and changes of direction, not round the way's corners at full steer: no charge there.
    // Charged there too, a pose in a narrow pocket of TPCAP case 20 (a maze) paid for way
    // directions that change from cell to cell: 29,874 expansions instead of 623.
    if (!way.known || !way.room) return 0.0;
    // The search's direction of travel (a search from the goal moves p as its primitives drive;
    // the vehicle reverses where that differs from the search's own direction).
    const double facing = std::abs(normalize_angle(p.yaw - way.yaw));
    int along = facing < 0.5 * kPi ? 1 : facing > 0.5 * kPi ? -1 : (direction != 0 ? direction : 1);
    if (!config_.use_back) along = 1;
    const double travel = along > 0 ? p.yaw : p.yaw + kPi;
    const double factor = (along < 0) != backward_ ? 1.0 + config_.reverse_weight : 1.0;
    const double per_radian = config_.turning_heuristic_weight * config_.curve_weight * config_.turning_radius;
    double charge = per_radian * factor * fd::turning_ahead(way, travel);
    if (direction != 0 && along != direction) charge += config_.direction_change_weight;
    return charge;
  }

  bool in_goal_region(const Pose2& p) const {
    const double c = std::cos(target_.yaw);
    const double s = std::sin(target_.yaw);
    const double dx = p.x - target_.x;
    const double dy = p.y - target_.y;
    const double lon = c * dx + s * dy;
    const double lat = -s * dx + c * dy;
    return std::abs(lon) <= 0.5 * config_.longitudinal_goal_range &&
           std::abs(lat) <= 0.5 * config_.lateral_goal_range &&
           std::abs(normalize_angle(p.yaw - target_.yaw)) <= 0.5 * config_.angle_goal_range;
  }

  // Adds a node unless its lattice cell holds a cheaper one; pushes it on the open list.
  // `cell`: key(node.pose, node.fine).
  void add_node(const Node& node, std::uint64_t cell) {
    std::int32_t* slot = table_.find_or_insert(cell);
    if (*slot >= 0) {
      Node& existing = nodes_[static_cast<std::size_t>(*slot)];
      if (existing.closed || existing.g <= node.g) return;
      existing.closed = true;  // superseded: its heap entry is skipped when popped
    }
    const double h2d = heuristic_.distance(node.pose);
    const double h = heuristic(node.pose, h2d, node.direction);
    if (!std::isfinite(h)) return;
    *slot = static_cast<std::int32_t>(nodes_.size());
    nodes_.push_back(node);
    nodes_.back().h2d = h2d;
    open_.push({node.g + h, *slot});
  }

  // A node's children: the full-length primitives that are free. A node with fewer than
  // kOpenPrimitives of them reaching a new cell is constrained (a tight spot: a bay's end, a
  // parallel slot, a pocket of a maze): it also drives the refused primitives until contact when
  // that is at least min_primitive_length, and its children get fine lattice cells, so that the
  // short moves between cusps with which a car wriggles out of such a spot are not merged away.
  // Elsewhere the search is the plain one.
  void expand(std::int32_t index) {
    const Node parent = nodes_[static_cast<std::size_t>(index)];
    const int steps = config_.turning_steps;
    const double c = std::cos(parent.pose.yaw);
    const double s = std::sin(parent.pose.yaw);
    struct Move {
      int direction;
      int steer;
      double distance;  // [m] signed
      Pose2 pose;
      double clearance;
      std::uint64_t coarse_key;  // key(pose, false); 0 for a move driven until contact (not computed)
    };
    constexpr std::size_t kMaxMoves = 2 * (2 * static_cast<std::size_t>(kMaxTurningSteps) + 1);
    std::array<Move, kMaxMoves> moves;
    std::array<Move, kMaxMoves> refused;
    std::size_t free_count = 0;
    std::size_t refused_count = 0;
    int open = 0;
    const std::uint64_t coarse_parent = key(parent.pose, false);
    for (const int direction : {1, -1}) {
      if (direction < 0 && !config_.use_back) continue;
      for (int steer = -steps; steer <= steps; ++steer) {
        const fd::Arc arc(parent.pose, c, s, curvature(steer));
        const double distance = direction * config_.primitive_length;
        double clearance = 0.0;
        Pose2 pose;
        if (!fd::arc_free(checker_, arc, parent.clearance, distance, clearance, pose)) {
          refused[refused_count++] = {direction, steer, distance, {}, 0.0, 0};
          continue;
        }
        const std::uint64_t coarse_key = key(pose, false);
        open += coarse_key != coarse_parent ? 1 : 0;
        moves[free_count++] = {direction, steer, distance, pose, clearance, coarse_key};
      }
    }
    const bool constrained = open < kOpenPrimitives;
    if (parent.parent < 0) root_constrained_ = constrained;
    // Fine moves (drive until contact, fine lattice cells) at constrained nodes of a rescue search.
    const bool fine = constrained && fine_moves_;
    if (fine) {
      for (std::size_t i = 0; i < refused_count; ++i) {
        Move m = refused[i];
        const fd::Arc arc(parent.pose, c, s, curvature(m.steer));
        const double free = fd::free_prefix(checker_, arc, parent.clearance, m.distance, config_.min_primitive_length);
        if (free < config_.min_primitive_length) continue;
        m.distance = m.direction * free;
        m.pose = arc.at(m.distance);
        if (checker_.collides(m.pose, m.clearance)) continue;  // (free_prefix tested it: rounding only)
        moves[free_count++] = m;
      }
    }
    const std::uint64_t parent_key = key(parent.pose, parent.fine);
    for (std::size_t i = 0; i < free_count; ++i) {
      const Move& m = moves[i];
      const std::uint64_t cell = fine ? key(m.pose, true) : m.coarse_key;
      if (cell == parent_key) continue;
      const double driven = std::abs(m.distance);
      double cost = driven * (1.0 + config_.curve_weight * std::abs(m.steer) / steps);
      if ((m.direction < 0) != backward_) cost *= 1.0 + config_.reverse_weight;  // the vehicle reverses
      if (parent.direction != 0 && parent.direction != m.direction) cost += config_.direction_change_weight;
      Node child;
      child.pose = m.pose;
      child.g = parent.g + cost;
      child.parent = index;
      child.clearance = static_cast<float>(m.clearance);
      child.length = driven;
      child.steer = static_cast<std::int8_t>(m.steer);
      child.direction = static_cast<std::int8_t>(m.direction);
      child.fine = fine;
      add_node(child, cell);
    }
  }

  double curvature(int steer) const {
    return static_cast<double>(steer) / config_.turning_steps / config_.turning_radius;
  }

  bool shoot(const Node& node, ReedsSheppPath& out) const {
    if (!config_.use_back) return false;  // Reeds-Shepp words reverse; a forward-only search never shoots
    std::vector<ReedsSheppPath> words = rs_.all(node.pose, target_);
    std::vector<std::pair<double, std::size_t>> order;
    order.reserve(words.size());
    for (std::size_t i = 0; i < words.size(); ++i)
      order.emplace_back(weighted_cost(words[i], weights_, node.direction), i);
    std::sort(order.begin(), order.end());
    for (int tried = 0; tried < kShotCandidates && tried < static_cast<int>(order.size()); ++tried) {
      const ReedsSheppPath& p = words[order[static_cast<std::size_t>(tried)].second];
      if (shot_free(node, p)) {
        out = p;
        return true;
      }
    }
    return false;
  }

  bool shot_free(const Node& from, const ReedsSheppPath& p) const {
    // Coarse samples of the whole path first: a colliding shot usually fails there, cheaply.
    for (const bool fine : {false, true}) {
      Pose2 pose = from.pose;
      double clearance = from.clearance;
      for (int i = 0; i < p.count; ++i) {
        const ReedsSheppSegment& seg = p.segments[static_cast<std::size_t>(i)];
        if (std::abs(seg.length) < 1e-9) continue;
        const double k = static_cast<double>(static_cast<int>(seg.kind)) / config_.turning_radius;
        const bool free = fine ? fd::arc_free(checker_, fd::Arc(pose, k), clearance, seg.length, clearance)
                               : fd::arc_samples_free(checker_, pose, k, seg.length, kCoarseSpacing);
        if (!free) return false;
        pose = fd::drive(pose, k, seg.length);
      }
    }
    return true;
  }

  // Appends the poses of one arc (excluding `from`, including its end) at most
  // waypoint_interval apart.
  void append_arc(const Pose2& from, double curvature, double distance, std::vector<Waypoint>& out) const {
    const int dir = distance < 0.0 ? -1 : 1;
    const int n = std::max(1, static_cast<int>(std::ceil(std::abs(distance) / config_.waypoint_interval - 1e-9)));
    for (int i = 1; i <= n; ++i) out.push_back({fd::drive(from, curvature, distance * i / n), dir});
  }

  // The waypoints from the root along the search's own direction of travel; the search from the
  // goal then turns them around (the same poses, in the opposite order and direction).
  void build_waypoints(HybridAStarResult& result) const {
    std::vector<std::int32_t> chain;
    for (std::int32_t i = finish_.node; i >= 0; i = nodes_[static_cast<std::size_t>(i)].parent) chain.push_back(i);
    std::reverse(chain.begin(), chain.end());
    std::vector<Waypoint> w;
    w.push_back({root_, 1});
    for (std::size_t c = 1; c < chain.size(); ++c) {
      const Node& n = nodes_[static_cast<std::size_t>(chain[c])];
      const Node& parent = nodes_[static_cast<std::size_t>(n.parent)];
      append_arc(parent.pose, curvature(n.steer), n.direction * n.length, w);
      result.length += n.length;
    }
    if (finish_.shot) {
      Pose2 pose = nodes_[static_cast<std::size_t>(finish_.node)].pose;
      for (int i = 0; i < finish_.path.count; ++i) {
        const ReedsSheppSegment& seg = finish_.path.segments[static_cast<std::size_t>(i)];
        if (std::abs(seg.length) < 1e-9) continue;
        const double k = static_cast<double>(static_cast<int>(seg.kind)) / config_.turning_radius;
        append_arc(pose, k, seg.length, w);
        pose = fd::drive(pose, k, seg.length);
      }
      result.length += finish_.path.length;
      w.back().pose = target_;  // removes the rounding of the integration
    }
    if (w.size() == 1) w.push_back(w.front());  // the root already in the goal region: a zero-length path
    if (backward_) {
      // Waypoint i's direction is that of the motion from i - 1 to i: reversed, the motion from
      // w[n - i + 1] to w[n - i] is the search's motion into w[n - i + 1], driven the other way.
      std::vector<Waypoint> turned(w.size());
      const std::size_t n = w.size() - 1;
      for (std::size_t i = 0; i <= n; ++i) {
        turned[i].pose = w[n - i].pose;
        turned[i].direction = i == 0 ? 1 : -w[n - i + 1].direction;
      }
      w.swap(turned);
    }
    w.front().direction = w[1].direction;
    result.waypoints = std::move(w);
  }

  const GridCollisionChecker& checker_;
  const Costmap& costmap_;
  const HybridAStarConfig& config_;
  Pose2 root_;
  Pose2 target_;
  bool backward_{false};
  bool fine_moves_{false};
  ReedsShepp rs_;
  ReedsSheppWeights weights_;
  mutable fd::ObstacleHeuristic heuristic_;  // computed lazily, as the search asks
  std::vector<Node> nodes_;
  fd::NodeTable table_;
  Finish finish_;
  std::size_t since_shot_{0};
  std::size_t expansions_{0};
  std::size_t shots_{0};
  double best_h2d_{std::numeric_limits<double>::infinity()};
  std::size_t last_progress_{0};
  bool root_constrained_{false};
  using OpenItem = std::pair<double, std::int32_t>;
  std::priority_queue<OpenItem, std::vector<OpenItem>, std::greater<OpenItem>> open_;
};

}  // namespace

const char* to_string(HybridAStarResult::Status status) {
  switch (status) {
    case HybridAStarResult::Status::kSuccess:
      return "success";
    case HybridAStarResult::Status::kStartOccupied:
      return "start occupied";
    case HybridAStarResult::Status::kGoalOccupied:
      return "goal occupied";
    case HybridAStarResult::Status::kTimeout:
      return "timeout";
    case HybridAStarResult::Status::kCancelled:
      return "cancelled";
    case HybridAStarResult::Status::kNodeLimit:
      return "node limit";
    case HybridAStarResult::Status::kNoPath:
      return "no path";
  }
  return "invalid";
}

HybridAStar::HybridAStar(const GridCollisionChecker& checker, const HybridAStarConfig& config)
    : checker_(checker), config_(config) {
  config_.turning_steps = std::clamp(config_.turning_steps, 1, kMaxTurningSteps);
}

HybridAStarResult HybridAStar::plan(const Pose2& start, const Pose2& goal, const StopCondition& stop) const {
  HybridAStarResult result;
  // Stopped before it starts: no heuristic grid either (the costliest part of the set-up).
  if (const StopReason reason = stop.check(); reason != StopReason::kNone) {
    result.stopped = reason;
    result.status =
        reason == StopReason::kCancelled ? HybridAStarResult::Status::kCancelled : HybridAStarResult::Status::kTimeout;
    return result;
  }
  double start_clearance = 0.0;
  if (checker_.collides(start, start_clearance)) {
    result.status = HybridAStarResult::Status::kStartOccupied;
    return result;
  }
  double goal_clearance = 0.0;
  if (checker_.collides(goal, goal_clearance)) {
    result.status = HybridAStarResult::Status::kGoalOccupied;
    return result;
  }
  // The plain search from the start first. When it is stuck (its open list empties, or it has
  // come within kNearGoalCells lattice cells of the goal and not got closer by kProgress over
  // stall_expansions expansions: far from the goal a long plateau is normal), the
  // rescue searches join it, taking turns: from the goal (search_from_goal) when the goal lies in
  // a tight spot (its first expansion finds it constrained), and, once the plain search's open
  // list is empty, from the start again; both with the fine moves at constrained nodes
  // (min_primitive_length). Getting out of a tight spot is found where a search begins, where
  // every short move is tried; getting into one from far away means hitting a small target
  // (bench/RESULTS.md: TPCAP case 7, parallel parking; case 20, a maze whose start pocket needs
  // short moves). The plain search pays nothing for them where it is not stuck.
  const bool fine = config_.min_primitive_length > 0.0;
  const bool from_goal = config_.use_back && config_.search_from_goal;
  const double near_goal =
      kNearGoalCells * (config_.xy_resolution > 0.0 ? config_.xy_resolution : config_.primitive_length);
  struct Slot {
    std::unique_ptr<Search> search;
    bool done{false};
  };
  std::array<Slot, 3> slots;  // plain from the start, from the goal, fine from the start
  Slot& plain = slots[0];
  Slot& goal_side = slots[1];
  Slot& fine_start = slots[2];
  plain.search = std::make_unique<Search>(checker_, config_, start, goal, false, false);
  plain.search->begin(stop, start_clearance);
  goal_side.done = !from_goal || !fine;  // min_primitive_length 0: the plain search alone
  fine_start.done = !fine;
  Search::State state = Search::State::kRunning;
  Search* found = nullptr;
  bool node_limit = false;
  std::size_t next = 0;
  for (std::size_t turn = 0;; ++turn) {
    if (turn % kStopCheckInterval == 0 && (result.stopped = stop.check()) != StopReason::kNone) break;
    // The rescue searches, once the plain one is stuck.
    const bool exhausted = plain.done;
    const bool stuck = exhausted || (plain.search->best_distance() <= near_goal &&
                                     plain.search->since_progress() >= config_.stall_expansions);
    if (stuck && !goal_side.done && goal_side.search == nullptr) {
      goal_side.search = std::make_unique<Search>(checker_, config_, goal, start, true, true);
      goal_side.search->begin(stop, goal_clearance);
    }
    if (exhausted && !fine_start.done && fine_start.search == nullptr) {
      fine_start.search = std::make_unique<Search>(checker_, config_, start, goal, false, true);
      fine_start.search->begin(stop, start_clearance);
    }
    // The next running search, in turn.
    Slot* slot = nullptr;
    for (std::size_t k = 0; k < slots.size() && slot == nullptr; ++k) {
      Slot& s = slots[(next + k) % slots.size()];
      if (s.search != nullptr && !s.done) {
        slot = &s;
        next = (next + k + 1) % slots.size();
      }
    }
    if (slot == nullptr) break;  // every search ended without a path
    Search& search = *slot->search;
    state = search.step();
    if (state == Search::State::kFound) {
      found = &search;
      break;
    }
    if (state == Search::State::kStopped) {
      result.stopped = search.heuristic_stopped();
      break;
    }
    if (state != Search::State::kRunning) {
      node_limit = node_limit || state == Search::State::kNodeLimit;
      slot->done = true;
    }
    // The goal is open: no search from it (its root expanded by now).
    if (slot == &goal_side && search.expansions() == 1 && !search.root_constrained()) goal_side.done = true;
  }
  for (const Slot& s : slots) {
    if (s.search == nullptr) continue;
    result.expansions += s.search->expansions();
    result.nodes += s.search->nodes();
    result.shots += s.search->shots();
  }
  if (found == nullptr) {
    result.status = result.stopped == StopReason::kCancelled ? HybridAStarResult::Status::kCancelled
                    : result.stopped != StopReason::kNone    ? HybridAStarResult::Status::kTimeout
                    : node_limit                             ? HybridAStarResult::Status::kNodeLimit
                                                             : HybridAStarResult::Status::kNoPath;
    return result;
  }
  result.status = HybridAStarResult::Status::kSuccess;
  found->result(result);
  return result;
}

}  // namespace pullout
