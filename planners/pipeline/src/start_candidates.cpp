#include "start_candidates.hpp"

#include <algorithm>
#include <cmath>

#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {

namespace {

constexpr double kMinCandidateSpacing = 0.05;  // [m] a last, shortened step shorter than this is not taken
constexpr double kBisectionTolerance = 1e-3;   // [m] of the pose just clear of the obstacle behind

// Where the vehicle stands on the pull-out lanes, and which way it faces along them: +1 with the
// lanes' direction, -1 against it (a vehicle parked nose-in in a bay drawn towards the road).
struct LanePosition {
  double s{0.0};
  double lateral{0.0};
  double facing{1.0};
};

LanePosition lane_position(const LaneChain& lanes, const Pose2& ego) {
  const auto proj = lanes.centerline.project(to_vec(ego));
  const double yaw = lanes.centerline.yaw_at(proj.s);
  return {proj.s, proj.lateral, std::cos(normalize_angle(ego.yaw - yaw)) >= 0.0 ? 1.0 : -1.0};
}

// The pose `back` metres behind the vehicle on the line through it parallel to the pull-out
// lanes' centerline, facing the way the vehicle faces along the lanes.
Pose2 backed_pose(const LaneChain& lanes, const LanePosition& at, double back) {
  const Pose2 base = lanes.centerline.pose_at(at.s - at.facing * back);
  const Vec2 p = to_vec(base) + left_normal(heading(base.yaw)) * at.lateral;
  return {p.x(), p.y(), at.facing > 0.0 ? base.yaw : normalize_angle(base.yaw + kPi)};
}

}  // namespace

StartCandidateSearch search_start_candidates(const PlanningContext& ctx, const StartPlannerParameters& p,
                                             const Pose2& ego) {
  StartCandidateSearch out;
  if (!p.enable_back) {
    out.candidates.push_back({ego, 0.0});
    return out;
  }
  const LaneChain& lanes = ctx.pull_out;
  const LanePosition at = lane_position(lanes, ego);
  // Room behind the vehicle on the lanes, keeping its rear inside them.
  const double room = at.facing > 0.0 ? at.s : lanes.centerline.length() - at.s;
  const double allowed = std::clamp(room - ctx.vehicle.base_to_rear_m(), 0.0, p.max_back_distance);
  const double last_margin = p.collision_check_margins.back();
  // The current pose is always candidate 0, whatever is ahead (Autoware MAIN also puts the ego
  // pose first); the checks below pick the poses worth reversing to.
  out.candidates.push_back({ego, 0.0});
  const std::string what = "start candidate";
  // The reverse to a candidate runs along the lanes from the vehicle's own heading: the vehicle
  // must turn its deviation from them out within the reverse's first step at full steer, or the
  // path is one it cannot drive (standing across the lane it would reverse sideways: 80 degrees
  // within a metre). Beyond that, no candidate behind it.
  const double lane_yaw = lanes.centerline.yaw_at(at.s) + (at.facing > 0.0 ? 0.0 : kPi);
  const double deviation = normalize_angle(ego.yaw - lane_yaw);
  const double turnable = p.center_line_path_interval / ctx.vehicle.min_turning_radius_m();  // [rad], first step
  if (allowed > kMinCandidateSpacing && std::abs(deviation) > turnable) {
    out.skipped.push_back({std::min(p.backward_search_resolution, allowed),
                           what + "s behind skipped: the vehicle's heading deviates " +
                               format_fixed(deviation * kRadToDeg, 1) + " deg from the lanes; reversing along them, " +
                               "it turns at most " + format_fixed(turnable * kRadToDeg, 1) + " deg in the first " +
                               format_fixed(p.center_line_path_interval, 2) + " m at full steer"});
    return out;
  }
  // Whether a pose `back` behind keeps the smallest margin to every obstacle.
  const auto clear_at = [&](double back) {
    return ctx.objects.clearance(backed_pose(lanes, at, back), last_margin).distance >= last_margin;
  };
  // Adds the candidate `back` behind unless an object ahead or the lanes' end rule it out.
  const auto consider = [&](double back) {
    const Pose2 pose = backed_pose(lanes, at, back);
    const auto front = ctx.objects.clearance_ahead(pose, p.collision_check_margin_from_front_object);
    // 1 um below the margin: a candidate exactly at it (up to rounding) counts as clear.
    if (front.distance < p.collision_check_margin_from_front_object - 1e-6) {
      out.skipped.push_back({back, what + " skipped: " + format_fixed(front.distance, 2) + " m from object " +
                                       std::to_string(front.obstacle_id) +
                                       " ahead (collision_check_margin_from_front_object " +
                                       format_fixed(p.collision_check_margin_from_front_object, 1) + " m)"});
      return;
    }
    const double s_back = at.s - at.facing * back;
    const double to_end = at.facing > 0.0 ? lanes.centerline.length() - s_back : s_back;
    if (to_end < p.ignore_distance_from_lane_end) {
      out.skipped.push_back({back, what + " skipped: closer than ignore_distance_from_lane_end to the lanes' end"});
      return;
    }
    out.candidates.push_back({pose, back});
  };
  // Steps of backward_search_resolution, the last one shortened to end where the room behind
  // ends (the lanes, max_back_distance, or the first obstacle within the smallest margin).
  double previous = 0.0;
  while (previous < allowed - kMinCandidateSpacing) {
    const double back = std::min(previous + p.backward_search_resolution, allowed);
    if (clear_at(back)) {
      consider(back);
      previous = back;
      continue;
    }
    // Blocked within this step: the pose just clear of the obstacle (bisection; clearance falls
    // as the vehicle backs towards it) is the last candidate.
    double lo = previous;
    double hi = back;
    while (hi - lo > kBisectionTolerance) {
      const double mid = 0.5 * (lo + hi);
      (clear_at(mid) ? lo : hi) = mid;
    }
    if (lo > previous + kMinCandidateSpacing) consider(lo);
    const auto hit = ctx.objects.clearance(backed_pose(lanes, at, back), last_margin);
    out.skipped.push_back({back, what + " within " + format_fixed(last_margin, 2) + " m of object " +
                                     std::to_string(hit.obstacle_id) + ": backward search ends"});
    break;
  }
  return out;
}

PathWithLaneId reverse_segment(const PlanningContext& ctx, const StartPlannerParameters& p, const Pose2& ego,
                               const StartCandidate& candidate) {
  const LaneChain& lanes = ctx.pull_out;
  const LanePosition at = lane_position(lanes, ego);
  PathWithLaneId seg;
  const double step = p.center_line_path_interval;
  const auto n =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(candidate.backward_distance / step - 1e-9)));
  for (std::size_t i = 0; i <= n; ++i) {
    const double back = candidate.backward_distance * static_cast<double>(i) / static_cast<double>(n);
    PathPoint pt;
    pt.pose = i == 0 ? ego : (i == n ? candidate.pose : backed_pose(lanes, at, back));
    pt.longitudinal_velocity_mps = i == n ? 0.0 : p.backward_velocity;
    const double s = at.s - at.facing * back;
    pt.lane_ids = lane_ids_at(ctx, to_vec(pt.pose), ctx.world.lanes()[lanes.lanes[lanes.lane_at(s)]].id);
    seg.points.push_back(std::move(pt));
  }
  return seg;
}

}  // namespace pullout
