#include "start_candidates.hpp"

#include <algorithm>
#include <cmath>

#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {

namespace {

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
  for (double back = p.backward_search_resolution; back <= allowed + 1e-9; back += p.backward_search_resolution) {
    const Pose2 pose = backed_pose(lanes, at, back);
    const std::string what = "start candidate";
    const auto hit = ctx.objects.clearance(pose, last_margin);
    if (hit.distance < last_margin) {
      out.skipped.push_back({back, what + " within " + format_fixed(last_margin, 2) + " m of object " +
                                       std::to_string(hit.obstacle_id) + ": backward search ends"});
      break;
    }
    const auto front = ctx.objects.clearance_ahead(pose, p.collision_check_margin_from_front_object);
    // 1 um below the margin: a candidate exactly at it (up to rounding) counts as clear.
    if (front.distance < p.collision_check_margin_from_front_object - 1e-6) {
      out.skipped.push_back({back, what + " skipped: " + format_fixed(front.distance, 2) + " m from object " +
                                       std::to_string(front.obstacle_id) +
                                       " ahead (collision_check_margin_from_front_object " +
                                       format_fixed(p.collision_check_margin_from_front_object, 1) + " m)"});
      continue;
    }
    const double s_back = at.s - at.facing * back;
    const double to_end = at.facing > 0.0 ? lanes.centerline.length() - s_back : s_back;
    if (to_end < p.ignore_distance_from_lane_end) {
      out.skipped.push_back({back, what + " skipped: closer than ignore_distance_from_lane_end to the lanes' end"});
      continue;
    }
    out.candidates.push_back({pose, back});
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
