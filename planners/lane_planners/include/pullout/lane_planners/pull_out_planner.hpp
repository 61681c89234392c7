// The interface every lane-based pull-out planner implements, what it is given, and the checks
// they share.
//
// A planner turns one start pose into candidate paths, in its order of preference, and checks each
// one once: lane departure (a verdict) and the clearance to static obstacles over its collision
// section (a number). None of that depends on the collision margin, so the pipeline runs a planner
// once per start pose and walks the margin ladder over the results: a candidate is usable at
// margin m when it has no rejection and clearance >= m.
#pragma once

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/collision/object_checker.hpp"
#include "pullout/lane_planners/lane_planner_parameters.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/model/types.hpp"
#include "pullout/search/stop_condition.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout {

// Everything a planner reads; built once per request by the pipeline and shared by all attempts.
struct PlanningContext {
  const LaneWorld& world;
  const LaneChain& road;         // the road lanes the vehicle pulls out onto, in driving order
  const LaneChain& pull_out;     // the lanes the vehicle stands in (shoulder chain, or `road`)
  const ObjectChecker& objects;  // static obstacles
  const VehicleInfo& vehicle;
  const LanePlannerParameters& parameters;
  Pose2 goal;
  double clearance_horizon{std::numeric_limits<double>::infinity()};  // largest margin of the ladder [m]
  // For the freespace planner: the vehicle's current pose, the request's occupancy grid (null
  // when none) and the static obstacles' polygons (map frame).
  Pose2 ego;
  const OccupancyGrid* occupancy_grid{nullptr};
  const std::vector<Polygon>* obstacle_polygons{nullptr};
  // The smallest margin of the ladder [m]: how close a multi-move manoeuvre drives to an obstacle
  // before it stops to change direction ("just clear").
  double smallest_margin{0.0};
  // How far [m] a multi-move manoeuvre may reverse straight before it turns (max_back_distance;
  // 0 without enable_back), and the speed [m/s] > 0 of its reverse moves (|backward_velocity|).
  double max_back_distance{0.0};
  double reverse_speed{1.0};
};

// Why an attempt or a candidate failed: the typed outcome and a detail for people ("object 7",
// "no two-arc path to the centerline"; may be empty).
struct Failure {
  AttemptOutcome outcome{AttemptOutcome::kNoPath};
  std::string detail;
};

struct PathCandidate {
  // Why this candidate cannot be used at any margin (lane departure, contact, ...); none when usable.
  std::optional<Failure> rejection;
  // Smallest distance [m] from the footprint to a static obstacle over the collision-checked
  // section; +inf when no obstacle is within the context's clearance_horizon.
  double clearance{std::numeric_limits<double>::infinity()};
  std::int64_t nearest_obstacle{0};
  // Builds the full path (partial paths with velocities and lane ids, pairs, start/end pose,
  // shift length). Only called for the candidate that wins.
  std::function<PullOutPath()> build;
};

struct PlannerCandidates {
  std::vector<PathCandidate> candidates;  // in order of preference
  std::optional<Failure> failure;         // why there is no candidate at all, if known
  // Why the planner stopped before it was done (kNone: it was not cut short). kBudget is the
  // planner's own budget: the caller's deadline and cancellation still hold.
  StopReason stopped{StopReason::kNone};
};

class PullOutPlanner {
 public:
  virtual ~PullOutPlanner() = default;
  virtual PlannerType type() const = 0;
  // Candidates from `start`, each checked. Must check `stop` between candidates and return
  // promptly once it says stop (PlannerCandidates::stopped set to its reason). Never throws for
  // geometric failure.
  virtual PlannerCandidates plan(const PlanningContext& context, const Pose2& start,
                                 const StopCondition& stop) const = 0;
  // Multi-move manoeuvres from `start` (several partial paths with changes of direction, the
  // vehicle stopped at each): what a driver does where no single move gets out. The pipeline asks
  // for them only after plan() found nothing usable at any margin from any start candidate, and
  // uses them at context.smallest_margin. Same contract as plan(); by default a planner has none
  // (no candidates, no failure).
  virtual PlannerCandidates plan_multi_move(const PlanningContext& /*context*/, const Pose2& /*start*/,
                                            const StopCondition& /*stop*/) const {
    return {};
  }
};

// The first candidate usable at `margin` (nullptr if none), and the evaluation-table outcome:
// kSuccess; or, when none is usable, the outcome of most candidates (the first one's on a tie;
// kTimeout / kCancelled when the planner was cut short) with every reason and its count in the
// detail ("object 7 (3/4 candidates); lane_departure (1/4 candidates)").
struct Selection {
  const PathCandidate* chosen{nullptr};
  AttemptOutcome outcome{AttemptOutcome::kNoPath};
  std::string detail;
};
Selection select_candidate(const PlannerCandidates& candidates, double margin);

// The attempt outcome of a search stopped for `reason` (kTimeout, or kCancelled), and its detail.
Failure stopped_failure(StopReason reason);

// ---- checks shared by the planners ----

// Index of the first pose in [first, last] whose footprint `footprint` (the vehicle's, each side
// expanded as the planner's lane check requires) leaves the union of the lanes.
std::optional<std::size_t> first_lane_departure(const PlanningContext& context, const std::vector<Pose2>& poses,
                                                std::size_t first, std::size_t last, const Footprint& footprint);

// Clearance over poses [first, last] (see PathCandidate::clearance).
ObjectChecker::Clearance section_clearance(const PlanningContext& context, const std::vector<Pose2>& poses,
                                           std::size_t first, std::size_t last);

// Fills candidate.rejection / clearance from the standard checks: lane departure over
// [0, departure_last] of `departure_footprint` (when `check_lanes`; rejection
// kLaneDeparture), clearance over [0, section_last], and no contact at all over
// (section_last, contact_last] (rejection kCollision, detail naming the object).
struct CandidateChecks {
  bool check_lanes{true};
  Footprint departure_footprint;
  std::size_t departure_last{0};
  std::size_t section_last{0};
  std::size_t contact_last{0};
};
void check_candidate(const PlanningContext& context, const std::vector<Pose2>& poses, const CandidateChecks& checks,
                     PathCandidate& candidate);

// Lane ids of a path point: the lanes containing it, else `fallback`.
std::vector<std::int64_t> lane_ids_at(const PlanningContext& context, const Vec2& p, std::int64_t fallback);

std::string format_fixed(double value, int precision);

// Where a path starting at road arc length s_from ends: at the goal when it lies on the road
// centerline ahead within forward_path_length, else forward_path_length ahead (or the road's end).
struct RoadEnd {
  double s{0.0};
  bool is_goal{false};
};
RoadEnd find_path_end(const PlanningContext& context, double s_from);
double speed_limit_at(const PlanningContext& context, double s);  // of the road lane at s
std::int64_t road_lane_id_at(const PlanningContext& context, double s);
// The road centerline between s0 and s1 (clamped), resampled every `interval`.
Polyline centerline_window(const PlanningContext& context, double s0, double s1, double interval);
// Road centerline points from s0 (excluded) to end.s (included) every center_line_path_interval,
// with lane ids and the lane speed limit (0 at the goal).
std::vector<PathPoint> centerline_points(const PlanningContext& context, double s0, const RoadEnd& end);

}  // namespace pullout
