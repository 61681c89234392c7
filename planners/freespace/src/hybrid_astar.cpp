#include "pullout/freespace/hybrid_astar.hpp"

#include <algorithm>
#include <cmath>
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
constexpr double kSweepGrowth = 0.5;              // [cells] footprint growth between tested poses
constexpr double kFineSweepGrowth = 0.125;        // [cells] the same where kSweepGrowth refuses

struct Node {
  Pose2 pose;
  double g{0.0};
  std::int32_t parent{-1};
  float clearance{0.0F};     // [m] clearance lower bound of the footprint at `pose` (0: near)
  std::int8_t steer{0};      // steer index of the primitive that led here
  std::int8_t direction{0};  // +1 / -1 of that primitive, 0 at the start
  bool closed{false};
};

// How the last piece (goal region or shot) was reached.
struct Finish {
  std::int32_t node{-1};
  bool shot{false};
  ReedsSheppPath path;
};

class Search {
 public:
  Search(const GridCollisionChecker& checker, const HybridAStarConfig& config, const Pose2& start, const Pose2& goal)
      : checker_(checker),
        costmap_(checker.costmap()),
        config_(config),
        start_(start),
        goal_(goal),
        rs_(config.turning_radius),
        weights_{config.curve_weight, config.reverse_weight, config.direction_change_weight},
        heuristic_(costmap_, heuristic_config(checker, config), goal),
        swept_checker_(costmap_, grown(checker.footprint(), kSweepGrowth * costmap_.resolution())),
        fine_checker_(costmap_, grown(checker.footprint(), kFineSweepGrowth * costmap_.resolution())),
        sweep_{checker_, swept_checker_, kSweepGrowth * costmap_.resolution(), fine_checker_,
               kFineSweepGrowth * costmap_.resolution()} {}

  HybridAStarResult run(const StopCondition& stop) {
    HybridAStarResult result;
    heuristic_.watch(stop);
    double start_clearance = 0.0;
    if (checker_.collides(start_, start_clearance)) {
      result.status = HybridAStarResult::Status::kStartOccupied;
      return result;
    }
    if (checker_.collides(goal_)) {
      result.status = HybridAStarResult::Status::kGoalOccupied;
      return result;
    }
    Node start_node;
    start_node.pose = start_;
    start_node.clearance = static_cast<float>(start_clearance);
    add_node(start_node);
    Finish finish;
    std::size_t since_shot = 0;
    bool node_limit = false;
    while (!open_.empty()) {
      if (result.expansions % kStopCheckInterval == 0) {
        result.stopped = stop.check();
        if (result.stopped != StopReason::kNone) break;
      }
      if (heuristic_.stopped() != StopReason::kNone) {  // it stopped inside a flood of the grid
        result.stopped = heuristic_.stopped();
        break;
      }
      const auto [f, index] = open_.top();
      open_.pop();
      if (nodes_[static_cast<std::size_t>(index)].closed) continue;
      nodes_[static_cast<std::size_t>(index)].closed = true;
      ++result.expansions;
      const Node node = nodes_[static_cast<std::size_t>(index)];
      if (config_.expanded_poses != nullptr) config_.expanded_poses->push_back(node.pose);
      if (in_goal_region(node.pose)) {
        finish.node = index;
        break;
      }
      // Analytic expansion: every expansion near the goal, less often far from it.
      const double h2d = heuristic_.distance(node.pose);
      const auto interval = static_cast<std::size_t>(std::max(1.0, h2d / kShotDistancePerInterval));
      if (++since_shot >= interval) {
        since_shot = 0;
        ++result.shots;
        if (shoot(node, finish.path)) {
          finish.node = index;
          finish.shot = true;
          break;
        }
      }
      if (nodes_.size() >= config_.max_nodes) {
        node_limit = true;
        break;
      }
      expand(index);
    }
    result.nodes = nodes_.size();
    // A heuristic stopped inside a flood answers nothing useful: what followed is no verdict.
    if (result.stopped == StopReason::kNone && finish.node < 0) result.stopped = heuristic_.stopped();
    if (finish.node < 0) {
      result.status = result.stopped == StopReason::kCancelled ? HybridAStarResult::Status::kCancelled
                      : result.stopped != StopReason::kNone    ? HybridAStarResult::Status::kTimeout
                      : node_limit                             ? HybridAStarResult::Status::kNodeLimit
                                                               : HybridAStarResult::Status::kNoPath;
      return result;
    }
    result.status = HybridAStarResult::Status::kSuccess;
    result.reached_exact_goal = finish.shot;
    build_waypoints(finish, result);
    return result;
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

  std::uint64_t key(const Pose2& p) const {
    const Vec2 g = costmap_.to_grid({p.x, p.y}) * (costmap_.resolution() / xy_resolution());
    const auto ix = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(g.x())) + (1 << 20));
    const auto iy = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(g.y())) + (1 << 20));
    const double bin = kTwoPi / config_.theta_size;
    auto it = static_cast<std::int64_t>(std::floor((normalize_angle(p.yaw) + kPi) / bin));
    it = ((it % config_.theta_size) + config_.theta_size) % config_.theta_size;
    return (ix << 42) | (iy << 20) | static_cast<std::uint64_t>(it);
  }

  // Plain Reeds-Shepp length: the cost weights make the true cost larger still, but a weighted
  // Reeds-Shepp bound steers the search into obstacles the 2D distance goes around (measured:
  // 20x more expansions around a wall).
  // Far from the goal the 2D distance dominates (a Reeds-Shepp path exceeds the straight line by
  // at most a few turning radii, and obstacles lengthen the 2D distance): the Reeds-Shepp term,
  // the costliest part of an expansion, is only computed within kReedsSheppRange radii.
  double heuristic(const Pose2& p) const {
    const double h2d = heuristic_.distance(p);
    if (!std::isfinite(h2d)) return h2d;
    if (h2d > kReedsSheppRange * config_.turning_radius) return config_.distance_heuristic_weight * h2d;
    return config_.distance_heuristic_weight * std::max(h2d, rs_.distance(p, goal_));
  }

  bool in_goal_region(const Pose2& p) const {
    const double c = std::cos(goal_.yaw);
    const double s = std::sin(goal_.yaw);
    const double dx = p.x - goal_.x;
    const double dy = p.y - goal_.y;
    const double lon = c * dx + s * dy;
    const double lat = -s * dx + c * dy;
    return std::abs(lon) <= 0.5 * config_.longitudinal_goal_range &&
           std::abs(lat) <= 0.5 * config_.lateral_goal_range &&
           std::abs(normalize_angle(p.yaw - goal_.yaw)) <= 0.5 * config_.angle_goal_range;
  }

  // Adds a node unless its lattice cell holds a cheaper one; pushes it on the open list.
  void add_node(const Node& node) {
    std::int32_t* slot = table_.find_or_insert(key(node.pose));
    if (*slot >= 0) {
      Node& existing = nodes_[static_cast<std::size_t>(*slot)];
      if (existing.closed || existing.g <= node.g) return;
      existing.closed = true;  // superseded: its heap entry is skipped when popped
    }
    const double h = heuristic(node.pose);
    if (!std::isfinite(h)) return;
    *slot = static_cast<std::int32_t>(nodes_.size());
    nodes_.push_back(node);
    open_.push({node.g + h, *slot});
  }

  void expand(std::int32_t index) {
    const Node parent = nodes_[static_cast<std::size_t>(index)];
    const std::uint64_t parent_key = key(parent.pose);
    const int steps = config_.turning_steps;
    const double length = config_.primitive_length;
    const double c = std::cos(parent.pose.yaw);
    const double s = std::sin(parent.pose.yaw);
    for (const int direction : {1, -1}) {
      if (direction < 0 && !config_.use_back) continue;
      for (int steer = -steps; steer <= steps; ++steer) {
        const fd::Arc arc(parent.pose, c, s, static_cast<double>(steer) / steps / config_.turning_radius);
        const double distance = direction * length;
        const Pose2 child_pose = arc.at(distance);
        if (key(child_pose) == parent_key) continue;
        double clearance = 0.0;
        if (!fd::arc_free(sweep_, arc, parent.clearance, distance, clearance)) continue;
        double cost = length * (1.0 + config_.curve_weight * std::abs(steer) / steps);
        if (direction < 0) cost *= 1.0 + config_.reverse_weight;
        if (parent.direction != 0 && parent.direction != direction) cost += config_.direction_change_weight;
        Node child;
        child.pose = child_pose;
        child.g = parent.g + cost;
        child.parent = index;
        child.clearance = static_cast<float>(clearance);
        child.steer = static_cast<std::int8_t>(steer);
        child.direction = static_cast<std::int8_t>(direction);
        add_node(child);
      }
    }
  }

  bool shoot(const Node& node, ReedsSheppPath& out) const {
    if (!config_.use_back) return false;  // Reeds-Shepp words reverse; a forward-only search never shoots
    std::vector<ReedsSheppPath> words = rs_.all(node.pose, goal_);
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
        const bool free = fine ? fd::arc_free(sweep_, fd::Arc(pose, k), clearance, seg.length, clearance)
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

  void build_waypoints(const Finish& finish, HybridAStarResult& result) const {
    std::vector<std::int32_t> chain;
    for (std::int32_t i = finish.node; i >= 0; i = nodes_[static_cast<std::size_t>(i)].parent) chain.push_back(i);
    std::reverse(chain.begin(), chain.end());
    std::vector<Waypoint>& w = result.waypoints;
    w.push_back({start_, 1});
    for (std::size_t c = 1; c < chain.size(); ++c) {
      const Node& n = nodes_[static_cast<std::size_t>(chain[c])];
      const Node& parent = nodes_[static_cast<std::size_t>(n.parent)];
      const double k = static_cast<double>(n.steer) / config_.turning_steps / config_.turning_radius;
      append_arc(parent.pose, k, n.direction * config_.primitive_length, w);
      result.length += config_.primitive_length;
    }
    if (finish.shot) {
      Pose2 pose = nodes_[static_cast<std::size_t>(finish.node)].pose;
      for (int i = 0; i < finish.path.count; ++i) {
        const ReedsSheppSegment& seg = finish.path.segments[static_cast<std::size_t>(i)];
        if (std::abs(seg.length) < 1e-9) continue;
        const double k = static_cast<double>(static_cast<int>(seg.kind)) / config_.turning_radius;
        append_arc(pose, k, seg.length, w);
        pose = fd::drive(pose, k, seg.length);
      }
      result.length += finish.path.length;
      w.back().pose = goal_;  // removes the rounding of the integration
    }
    if (w.size() >= 2) w.front().direction = w[1].direction;
    if (w.size() == 1) w.push_back(w.front());  // start already in the goal region: a zero-length path
  }

  static Footprint grown(Footprint f, double by) {
    f.front += by;
    f.rear += by;
    f.left += by;
    f.right += by;
    return f;
  }

  const GridCollisionChecker& checker_;
  const Costmap& costmap_;
  const HybridAStarConfig& config_;
  Pose2 start_;
  Pose2 goal_;
  ReedsShepp rs_;
  ReedsSheppWeights weights_;
  mutable fd::ObstacleHeuristic heuristic_;  // computed lazily, as the search asks
  GridCollisionChecker swept_checker_;       // the footprint grown for the motion between tested poses
  GridCollisionChecker fine_checker_;        // grown less, where swept_checker_ refuses
  fd::SweepCheckers sweep_;
  std::vector<Node> nodes_;
  fd::NodeTable table_;
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
    : checker_(checker), config_(config) {}

HybridAStarResult HybridAStar::plan(const Pose2& start, const Pose2& goal, const StopCondition& stop) const {
  // Stopped before it starts: no heuristic grid either (the costliest part of the set-up).
  if (const StopReason reason = stop.check(); reason != StopReason::kNone) {
    HybridAStarResult result;
    result.stopped = reason;
    result.status =
        reason == StopReason::kCancelled ? HybridAStarResult::Status::kCancelled : HybridAStarResult::Status::kTimeout;
    return result;
  }
  Search search(checker_, config_, start, goal);
  return search.run(stop);
}

}  // namespace pullout
