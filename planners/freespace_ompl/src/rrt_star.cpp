#include "pullout/freespace_ompl/rrt_star.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <ompl/base/ScopedState.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/ReedsSheppStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/util/Console.h>

#include "pullout/freespace/reeds_shepp.hpp"

namespace pullout {

namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

constexpr double kMotionStep = 0.05;     // [m] OMPL's motion check resolution
constexpr double kGoalThreshold = 0.05;  // [m] (Reeds-Shepp distance) an exact solution ends this close

Pose2 pose_of(const ob::State* s) {
  const auto* st = s->as<ob::SE2StateSpace::StateType>();
  return {st->getX(), st->getY(), st->getYaw()};
}

}  // namespace

HybridAStarResult plan_rrt_star(const GridCollisionChecker& checker, const HybridAStarConfig& config,
                                const Pose2& start, const Pose2& goal, const StopCondition& stop) {
  HybridAStarResult out;
  if (checker.collides(start)) {
    out.status = HybridAStarResult::Status::kStartOccupied;
    return out;
  }
  if (checker.collides(goal)) {
    out.status = HybridAStarResult::Status::kGoalOccupied;
    return out;
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  // The costmap's extent in the map frame (its corners' bounding box; outside the grid is occupied).
  const Costmap& map = checker.costmap();
  double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi[2] = {-lo[0], -lo[1]};
  for (const Vec2& c : {Vec2(0, 0), Vec2(map.width(), 0), Vec2(0, map.height()), Vec2(map.width(), map.height())}) {
    const Vec2 p = map.to_map(c);
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  auto space = std::make_shared<ob::ReedsSheppStateSpace>(config.turning_radius);
  ob::RealVectorBounds bounds(2);
  for (int k = 0; k < 2; ++k) {
    bounds.setLow(static_cast<unsigned>(k), lo[k]);
    bounds.setHigh(static_cast<unsigned>(k), hi[k]);
  }
  space->setBounds(bounds);
  og::SimpleSetup setup(space);
  setup.setStateValidityChecker([&checker](const ob::State* s) { return !checker.collides(pose_of(s)); });
  setup.getSpaceInformation()->setStateValidityCheckingResolution(kMotionStep / space->getMaximumExtent());
  ob::ScopedState<> from(space), to(space);
  from[0] = start.x;
  from[1] = start.y;
  from[2] = start.yaw;
  to[0] = goal.x;
  to[1] = goal.y;
  to[2] = goal.yaw;
  setup.setStartAndGoalStates(from, to, kGoalThreshold);
  // Any solution satisfies the objective: the planner returns its first one.
  auto objective = std::make_shared<ob::PathLengthOptimizationObjective>(setup.getSpaceInformation());
  objective->setCostThreshold(ob::Cost(std::numeric_limits<double>::infinity()));
  setup.setOptimizationObjective(objective);
  setup.setPlanner(std::make_shared<og::InformedRRTstar>(setup.getSpaceInformation()));
  setup.setup();
  const ob::PlannerTerminationCondition ptc =
      ob::plannerOrTerminationCondition(ob::PlannerTerminationCondition([&stop] { return stop.should_stop(); }),
                                        ob::exactSolnPlannerTerminationCondition(setup.getProblemDefinition()));
  const ob::PlannerStatus status = setup.solve(ptc);
  if (status != ob::PlannerStatus::EXACT_SOLUTION) {
    out.stopped = stop.check();
    out.status = out.stopped == StopReason::kCancelled ? HybridAStarResult::Status::kCancelled
                 : out.stopped != StopReason::kNone    ? HybridAStarResult::Status::kTimeout
                                                       : HybridAStarResult::Status::kNoPath;
    return out;
  }
  // The Reeds-Shepp pieces between the solution's states, sampled into waypoints.
  const og::PathGeometric& path = setup.getSolutionPath();
  const ReedsShepp rs(config.turning_radius);
  const double step = config.waypoint_interval > 0.0 ? config.waypoint_interval : 0.25;
  out.waypoints.push_back({start, 1});
  for (std::size_t i = 1; i < path.getStateCount(); ++i) {
    const Pose2 a = i == 1 ? start : pose_of(path.getState(i - 1));
    const Pose2 b = pose_of(path.getState(i));
    const ReedsSheppPath piece = rs.shortest(a, b);
    // Each Reeds-Shepp segment sampled on its own, so that every cusp is a waypoint.
    double along = 0.0;
    for (int seg = 0; seg < piece.count; ++seg) {
      const double length = piece.segments[static_cast<std::size_t>(seg)].length;
      if (std::abs(length) < 1e-9) continue;
      const int direction = length > 0.0 ? 1 : -1;
      const int samples = std::max(1, static_cast<int>(std::ceil(std::abs(length) / step)));
      for (int k = 1; k <= samples; ++k) {
        const double s_k = std::min(piece.length, along + std::abs(length) * k / samples);
        const Pose2 p = rs.interpolate(a, piece, s_k);
        if (checker.collides(p)) {
          out.status = HybridAStarResult::Status::kNoPath;
          out.waypoints.clear();
          return out;
        }
        out.waypoints.push_back({p, direction});
      }
      along += std::abs(length);
    }
    out.length += piece.length;
    out.waypoints.back().pose = b;
  }
  if (out.waypoints.size() > 1) out.waypoints.front().direction = out.waypoints[1].direction;
  out.status = HybridAStarResult::Status::kSuccess;
  out.reached_exact_goal = false;
  return out;
}

}  // namespace pullout
