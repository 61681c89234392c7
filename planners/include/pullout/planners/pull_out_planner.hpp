// The interface every lane-based pull-out planner implements, and what it is given.
#pragma once

#include <optional>
#include <string>

#include "pullout/collision/object_checker.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/model/types.hpp"
#include "pullout/pipeline/deadline.hpp"
#include "pullout/pipeline/parameters.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout {

// Everything a planner reads; built once per request by the pipeline and shared by all attempts.
struct PlanningContext {
  const LaneWorld& world;
  const LaneChain& road;         // the road lanes the vehicle pulls out onto, in driving order
  const ObjectChecker& objects;  // static obstacles
  const VehicleInfo& vehicle;
  const StartPlannerParameters& parameters;
  Pose2 goal;
};

struct PlannerOutput {
  // A candidate path: partial_paths, pairs, start/end pose, shift length filled in; the pipeline
  // fills the request identity, planner type and turn signal.
  std::optional<PullOutPath> path;
  std::string outcome;  // "success", or why not (e.g. "collision with object 7")
};

class PullOutPlanner {
 public:
  virtual ~PullOutPlanner() = default;
  virtual PlannerType type() const = 0;
  // Plans from `start` with static-object clearance `margin` [m]. Must return promptly once the
  // deadline has expired (outcome "timeout"). Never throws for geometric failure.
  virtual PlannerOutput plan(const PlanningContext& context, const Pose2& start, double margin,
                             const Deadline& deadline) const = 0;
};

}  // namespace pullout
