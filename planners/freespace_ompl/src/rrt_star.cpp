#include "pullout/freespace_ompl/rrt_star.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <utility>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/ReedsSheppStateSpace.h>
#include <ompl/datastructures/NearestNeighborsSqrtApprox.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>

#include "pullout/freespace/motion_check.hpp"
#include "pullout/freespace/reeds_shepp.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {

namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

constexpr double kGoalThreshold = 0.05;  // [m] (Reeds-Shepp distance) an exact solution ends this close
constexpr double kZeroLength = 1e-9;     // [m]
// [turning radii] the longest motion RRT* adds to its tree at once (OMPL default: a fifth of the
// space's extent, tens of metres in a lot, each such motion a long collision test).
constexpr double kRangeRadii = 2.0;

Pose2 pose_of(const ob::State* s) {
  const auto* st = s->as<ob::SE2StateSpace::StateType>();
  return {st->getX(), st->getY(), st->getYaw()};
}

bool pose_less(const Pose2& a, const Pose2& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.yaw < b.yaw;
}

// The path of the tree's motion from `a` to `b`. OMPL's RRT* reuses the test of a motion for the
// opposite direction when it rewires, so the path between two poses must not depend on the order
// they are asked in: the shortest Reeds-Shepp path from the smaller pose (x, y, yaw in that order)
// to the larger, driven backwards in time when a is the larger (segments in reverse order, each
// with the same steering and the opposite direction of travel).
ReedsSheppPath motion_path(const ReedsShepp& rs, const Pose2& a, const Pose2& b) {
  if (!pose_less(b, a)) return rs.shortest(a, b);
  ReedsSheppPath p = rs.shortest(b, a);
  std::reverse(p.segments.begin(), p.segments.begin() + p.count);
  for (int i = 0; i < p.count; ++i) p.segments[static_cast<std::size_t>(i)].length *= -1.0;
  return p;
}

// Uniform poses over the space's bounds from a generator seeded by the search (OMPL's samplers
// take their seeds from the process-wide sequence). Each draw in its own statement: the order
// of function arguments' evaluation is unspecified.
class SeededPoseSampler : public ob::StateSampler {
 public:
  SeededPoseSampler(const ob::StateSpace* space, std::uint32_t seed) : ob::StateSampler(space) {
    rng_.setLocalSeed(seed);
  }

  void sampleUniform(ob::State* state) override {
    const ob::RealVectorBounds& b = space_->as<ob::SE2StateSpace>()->getBounds();
    const double x = rng_.uniformReal(b.low[0], b.high[0]);
    const double y = rng_.uniformReal(b.low[1], b.high[1]);
    const double yaw = rng_.uniformReal(-kPi, kPi);
    set(state, x, y, yaw);
  }
  void sampleUniformNear(ob::State* state, const ob::State* near, double distance) override {
    const ob::RealVectorBounds& b = space_->as<ob::SE2StateSpace>()->getBounds();
    const Pose2 c = pose_of(near);
    const double x = rng_.uniformReal(std::max(b.low[0], c.x - distance), std::min(b.high[0], c.x + distance));
    const double y = rng_.uniformReal(std::max(b.low[1], c.y - distance), std::min(b.high[1], c.y + distance));
    const double yaw = rng_.uniformReal(-kPi, kPi);
    set(state, x, y, yaw);
  }
  void sampleGaussian(ob::State* state, const ob::State* mean, double stddev) override {
    const ob::RealVectorBounds& b = space_->as<ob::SE2StateSpace>()->getBounds();
    const Pose2 c = pose_of(mean);
    const double x = std::clamp(rng_.gaussian(c.x, stddev), b.low[0], b.high[0]);
    const double y = std::clamp(rng_.gaussian(c.y, stddev), b.low[1], b.high[1]);
    const double yaw = normalize_angle(rng_.gaussian(c.yaw, stddev));
    set(state, x, y, yaw);
  }

 private:
  static void set(ob::State* state, double x, double y, double yaw) {
    auto* st = state->as<ob::SE2StateSpace::StateType>();
    st->setXY(x, y);
    st->setYaw(yaw);
  }
};

// A motion is valid when its whole Reeds-Shepp path (motion_path) is free (motion_check.hpp).
class ReedsSheppMotionValidator : public ob::MotionValidator {
 public:
  ReedsSheppMotionValidator(ob::SpaceInformation* si, const GridCollisionChecker& checker, double turning_radius)
      : ob::MotionValidator(si), checker_(checker), rs_(turning_radius) {}

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool ok = free(pose_of(s1), pose_of(s2));
    ++(ok ? valid_ : invalid_);
    return ok;
  }
  bool free(const Pose2& a, const Pose2& b) const {
    return reeds_shepp_path_free(checker_, rs_.turning_radius(), a, motion_path(rs_, a, b));
  }
  const GridCollisionChecker& checker() const { return checker_; }
  const ReedsShepp& reeds_shepp() const { return rs_; }
  // Not used by RRT*; answers conservatively (the last valid state is the first one).
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override {
    if (checkMotion(s1, s2)) return true;
    if (last_valid.first != nullptr) si_->copyState(last_valid.first, s1);
    last_valid.second = 0.0;
    return false;
  }

 private:
  const GridCollisionChecker& checker_;
  ReedsShepp rs_;
};

// OMPL's RRT* with its goal-bias generator seeded by the search and a nearest-neighbour structure
// without randomness (the default GNAT seeds its pivot choice from the process-wide sequence).
class SeededRrtStar : public og::RRTstar {
 public:
  SeededRrtStar(const ob::SpaceInformationPtr& si, std::uint32_t seed, double goal_bias, double range)
      : og::RRTstar(si), seed_(seed) {
    setGoalBias(goal_bias);
    setRange(range);
  }

  void setup() override {
    nn_ = std::make_shared<ompl::NearestNeighborsSqrtApprox<Motion*>>();
    og::RRTstar::setup();
    rng_.setLocalSeed(seed_);
  }
  std::size_t tree_size() const { return nn_ ? nn_->size() : 0; }

 private:
  std::uint32_t seed_;
};

// The costmap's extent in the map frame (its corners' bounding box; outside the grid is occupied).
ob::RealVectorBounds costmap_bounds(const Costmap& map) {
  double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi[2] = {-lo[0], -lo[1]};
  for (const Vec2& c : {Vec2(0, 0), Vec2(map.width(), 0), Vec2(0, map.height()), Vec2(map.width(), map.height())}) {
    const Vec2 p = map.to_map(c);
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  ob::RealVectorBounds bounds(2);
  for (unsigned k = 0; k < 2; ++k) {
    bounds.setLow(k, lo[k]);
    bounds.setHigh(k, hi[k]);
  }
  return bounds;
}

void set_state(ob::ScopedState<>& s, const Pose2& p) {
  s[0] = p.x;
  s[1] = p.y;
  s[2] = normalize_angle(p.yaw);  // OMPL's SO(2) bounds are [-pi, pi]
}

// The solution's states (s_0 = start ... s_n), shortened deterministically: from each kept state
// the farthest later state whose motion_path is free is the next one (RRT*'s first solution
// zigzags between the samples it happened to draw; each jump removes detours and cusps). The
// motions of the solution itself are free, so the chain always reaches s_n.
std::vector<Pose2> shortcut(const ReedsSheppMotionValidator& motions, const og::PathGeometric& path) {
  std::vector<Pose2> states;
  for (std::size_t i = 0; i < path.getStateCount(); ++i) states.push_back(pose_of(path.getState(i)));
  std::vector<Pose2> kept{states.front()};
  std::size_t i = 0;
  while (i + 1 < states.size()) {
    std::size_t next = i + 1;
    for (std::size_t j = states.size() - 1; j > i + 1; --j) {
      if (motions.free(states[i], states[j])) {
        next = j;
        break;
      }
    }
    kept.push_back(states[next]);
    i = next;
  }
  return kept;
}

// The waypoints through `states` (the first is the start), each motion's path tested again;
// false when one is not free.
bool solution_waypoints(const ReedsSheppMotionValidator& motions, double interval, const std::vector<Pose2>& states,
                        const Pose2& start, const Pose2& goal, HybridAStarResult& out) {
  const ReedsShepp& rs = motions.reeds_shepp();
  std::vector<Waypoint> w{{start, 1}};
  double length = 0.0;
  for (std::size_t i = 1; i < states.size(); ++i) {
    const Pose2& a = states[i - 1];
    const Pose2& b = states[i];
    const ReedsSheppPath piece = motion_path(rs, a, b);
    if (!motions.free(a, b)) return false;
    append_reeds_shepp_waypoints(rs.turning_radius(), a, piece, interval, w);
    w.back().pose = b;
    length += piece.length;
  }
  // The last state lies within kGoalThreshold of the goal: joined to it when that path is free.
  const Pose2 last = w.back().pose;
  const ReedsSheppPath to_goal = rs.shortest(last, goal);
  out.reached_exact_goal =
      to_goal.length < kZeroLength || reeds_shepp_path_free(motions.checker(), rs.turning_radius(), last, to_goal);
  if (out.reached_exact_goal && to_goal.length >= kZeroLength) {
    append_reeds_shepp_waypoints(rs.turning_radius(), last, to_goal, interval, w);
    w.back().pose = goal;
    length += to_goal.length;
  }
  if (w.size() < 2) w.push_back({goal, 1});
  // Headings continuous along the path (OMPL's states are normalised to [-pi, pi]).
  for (std::size_t i = 1; i < w.size(); ++i) {
    w[i].pose.yaw = w[i - 1].pose.yaw + normalize_angle(w[i].pose.yaw - w[i - 1].pose.yaw);
  }
  w.front().direction = w[1].direction;
  out.waypoints = std::move(w);
  out.length = length;
  return true;
}

}  // namespace

namespace {

// One attempt's search on `checker`: true with the waypoints in `out` when it found a path.
// `iterations` receives the iterations it ran.
bool attempt(const GridCollisionChecker& checker, const HybridAStarConfig& config, const RrtStarConfig& rrt,
             std::uint32_t seed, std::size_t cap, const Pose2& start, const Pose2& goal, const StopCondition& stop,
             HybridAStarResult& out, std::size_t& iterations) {
  const double interval = config.waypoint_interval > 0.0 ? config.waypoint_interval : 0.25;
  auto space = std::make_shared<ob::ReedsSheppStateSpace>(config.turning_radius);
  space->setBounds(costmap_bounds(checker.costmap()));
  space->setStateSamplerAllocator(
      [seed](const ob::StateSpace* s) { return std::make_shared<SeededPoseSampler>(s, seed); });
  og::SimpleSetup setup(space);
  const ob::SpaceInformationPtr& si = setup.getSpaceInformation();
  setup.setStateValidityChecker([&checker](const ob::State* s) { return !checker.collides(pose_of(s)); });
  const auto motions = std::make_shared<ReedsSheppMotionValidator>(si.get(), checker, config.turning_radius);
  si->setMotionValidator(motions);
  ob::ScopedState<> from(space), to(space);
  set_state(from, start);
  set_state(to, goal);
  setup.setStartAndGoalStates(from, to, kGoalThreshold);
  // Any solution satisfies the objective: the planner returns its first one.
  auto objective = std::make_shared<ob::PathLengthOptimizationObjective>(si);
  objective->setCostThreshold(ob::Cost(std::numeric_limits<double>::infinity()));
  setup.setOptimizationObjective(objective);
  const auto planner = std::make_shared<SeededRrtStar>(si, seed, rrt.goal_bias, kRangeRadii * config.turning_radius);
  setup.setPlanner(planner);
  setup.setup();
  // Evaluated once per iteration of RRT*; the count, not the clock, bounds an attempt.
  iterations = 0;
  const ob::ProblemDefinitionPtr& pdef = setup.getProblemDefinition();
  const ob::PlannerTerminationCondition ptc([&] {
    if (stop.should_stop() || pdef->hasExactSolution() || iterations >= cap) return true;
    ++iterations;
    return false;
  });
  if (setup.solve(ptc) != ob::PlannerStatus::EXACT_SOLUTION) return false;
  out.nodes = planner->tree_size();
  return solution_waypoints(*motions, interval, shortcut(*motions, setup.getSolutionPath()), start, goal, out);
}

}  // namespace

RrtStarResult run_rrt_star(const GridCollisionChecker& checker, const HybridAStarConfig& config,
                           const RrtStarConfig& rrt, const Pose2& start, const Pose2& goal, const StopCondition& stop) {
  RrtStarResult result;
  HybridAStarResult& out = result.search;
  if (checker.collides(start)) {
    out.status = HybridAStarResult::Status::kStartOccupied;
    return result;
  }
  if (checker.collides(goal)) {
    out.status = HybridAStarResult::Status::kGoalOccupied;
    return result;
  }
  static std::once_flag quiet;
  std::call_once(quiet, [] { ompl::msg::setLogLevel(ompl::msg::LOG_NONE); });
  out.status = HybridAStarResult::Status::kNoPath;
  std::size_t cap = std::max<std::size_t>(1, rrt.first_iterations);
  for (int k = 0; k < std::max(1, rrt.max_attempts); ++k, cap *= 2) {
    out.stopped = stop.check();
    if (out.stopped != StopReason::kNone) break;
    result.attempts += 1;
    result.seed = rrt.seed + static_cast<std::uint32_t>(k);
    const bool found = attempt(checker, config, rrt, result.seed, cap, start, goal, stop, out, result.iterations);
    out.expansions += result.iterations;
    if (found) {
      out.status = HybridAStarResult::Status::kSuccess;
      out.stopped = StopReason::kNone;
      return result;
    }
  }
  out.stopped = stop.check();
  if (out.stopped != StopReason::kNone) {
    out.status = out.stopped == StopReason::kCancelled ? HybridAStarResult::Status::kCancelled
                                                       : HybridAStarResult::Status::kTimeout;
  }
  return result;
}

HybridAStarResult plan_rrt_star(const GridCollisionChecker& checker, const HybridAStarConfig& config,
                                const Pose2& start, const Pose2& goal, const StopCondition& stop) {
  return run_rrt_star(checker, config, RrtStarConfig{}, start, goal, stop).search;
}

}  // namespace pullout
