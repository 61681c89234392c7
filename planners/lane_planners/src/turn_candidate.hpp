// Internal: checks and path building shared by the geometric and clothoid planners.
#pragma once

#include <functional>

#include "pullout/lane_planners/pull_out_planner.hpp"
#include "pullout/lane_planners/two_turn_path.hpp"

namespace pullout {

struct TurnCandidateOptions {
  bool check_lanes{true};
  Footprint departure_footprint;            // the footprint the lane check keeps inside the lanes
  double collision_distance_from_end{0.0};  // [m] collision section end relative to the end pose
  double output_interval{1.0};              // [m] point spacing on the turns
};

// Velocity of the turn points: given the distance from the start along the turns [m].
using TurnVelocity = std::function<double(double distance)>;
// Partial paths of the turn points: the indices (into the sampled turn points) where a new
// partial path starts, the pair of each partial path.
struct TurnSegmentation {
  std::vector<std::size_t> splits;  // sorted, each in (0, last]
  std::vector<TerminalVelocityAccel> pairs;
  bool stop_at_splits{true};
};

// The smallest clearance to the static obstacles over the first `length` [m] of `path`, exact to
// about 1 cm (samples every 0.5 m, refined around the local minima; see the .cpp).
ObjectChecker::Clearance refined_clearance(const PlanningContext& context, const CurvaturePath& path, double length);

// The window of the road centerline a two-turn path from `start` is solved on.
Polyline turn_window(const PlanningContext& context, const Pose2& start);

// Checks `turns` and returns the candidate; build() composes the partial paths: the turn points,
// split as `segmentation` says, then the road centerline to the goal or forward_path_length.
PathCandidate make_turn_candidate(
    const PlanningContext& context, const TwoTurnPath& turns, const TurnCandidateOptions& options,
    TurnVelocity velocity,
    std::function<TurnSegmentation(const std::vector<Pose2>&, const std::vector<std::size_t>&)> segment);

}  // namespace pullout
