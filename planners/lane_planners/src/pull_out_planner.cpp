#include "pullout/lane_planners/pull_out_planner.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "pullout/collision/footprint.hpp"

namespace pullout {

namespace {
constexpr double kTouchingDistance = 1e-6;    // [m] clearance below this is contact
constexpr double kGoalOnRoadTolerance = 0.5;  // [m] lateral offset of a goal on the centerline
}  // namespace

RoadEnd find_path_end(const PlanningContext& ctx, double s_from) {
  const Polyline& center = ctx.road.centerline;
  RoadEnd end{std::min(s_from + ctx.parameters.forward_path_length, center.length()), false};
  const auto g = center.project(to_vec(ctx.goal));
  if (std::abs(g.lateral) <= kGoalOnRoadTolerance && g.s > s_from && g.s <= end.s) end = {g.s, true};
  return end;
}

double speed_limit_at(const PlanningContext& ctx, double s) {
  return ctx.world.lanes()[ctx.road.lanes[ctx.road.lane_at(s)]].speed_limit_mps;
}

std::int64_t road_lane_id_at(const PlanningContext& ctx, double s) {
  return ctx.world.lanes()[ctx.road.lanes[ctx.road.lane_at(s)]].id;
}

Polyline centerline_window(const PlanningContext& ctx, double s0, double s1, double interval) {
  const Polyline& center = ctx.road.centerline;
  return center.resampled(interval, std::clamp(s0, 0.0, center.length()), std::clamp(s1, 0.0, center.length()));
}

std::vector<PathPoint> centerline_points(const PlanningContext& ctx, double s0, const RoadEnd& end) {
  std::vector<PathPoint> out;
  const double step = ctx.parameters.center_line_path_interval;
  // Skip a first point closer than half a step to s0: it would duplicate the joint.
  for (double s = s0 + step; s < end.s + 0.5 * step; s += step) {
    const double si = std::min(s, end.s);
    PathPoint p;
    p.pose = ctx.road.centerline.pose_at(si);
    p.longitudinal_velocity_mps = speed_limit_at(ctx, si);
    p.lane_ids = lane_ids_at(ctx, to_vec(p.pose), road_lane_id_at(ctx, si));
    out.push_back(std::move(p));
    if (si >= end.s) break;
  }
  if (!out.empty() && end.is_goal) out.back().longitudinal_velocity_mps = 0.0;
  return out;
}

std::string format_fixed(double value, int precision) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(precision);
  os << value;
  return os.str();
}

Selection select_candidate(const PlannerCandidates& pc, double margin) {
  Selection sel;
  if (pc.candidates.empty()) {
    sel.outcome = pc.timed_out ? "timeout" : (pc.failure.empty() ? "no path found" : pc.failure);
    return sel;
  }
  std::map<std::string, int> reasons;
  for (const PathCandidate& c : pc.candidates) {
    if (!c.rejection.empty()) {
      ++reasons[c.rejection];
    } else if (c.clearance < margin) {
      ++reasons["collision with object " + std::to_string(c.nearest_obstacle)];
    } else {
      sel.chosen = &c;
      sel.outcome = "success";
      return sel;
    }
  }
  const auto total = pc.candidates.size();
  for (const auto& [reason, count] : reasons) {
    if (!sel.outcome.empty()) sel.outcome += "; ";
    sel.outcome += reason;
    if (total > 1) sel.outcome += " (" + std::to_string(count) + "/" + std::to_string(total) + " candidates)";
  }
  if (pc.timed_out) sel.outcome += "; timeout";
  return sel;
}

std::optional<std::size_t> first_lane_departure(const PlanningContext& ctx, const std::vector<Pose2>& poses,
                                                std::size_t first, std::size_t last, double expansion) {
  const Footprint fp = vehicle_footprint(ctx.vehicle, expansion);
  for (std::size_t i = first; i <= last && i < poses.size(); ++i) {
    if (!ctx.world.footprint_inside(footprint_corners(fp, poses[i]))) return i;
  }
  return std::nullopt;
}

ObjectChecker::Clearance section_clearance(const PlanningContext& ctx, const std::vector<Pose2>& poses,
                                           std::size_t first, std::size_t last) {
  ObjectChecker::Clearance best;
  for (std::size_t i = first; i <= last && i < poses.size(); ++i) {
    const auto c = ctx.objects.clearance(poses[i], std::min(best.distance, ctx.clearance_horizon));
    if (c.distance < best.distance) best = c;
    if (best.distance <= 0.0) break;
  }
  return best;
}

void check_candidate(const PlanningContext& ctx, const std::vector<Pose2>& poses, const CandidateChecks& checks,
                     PathCandidate& candidate) {
  // Obstacles first: a candidate in contact is rejected whatever the lanes say, and finding the
  // contact stops early, while the lane check of a good candidate has to look at every pose.
  const auto c = section_clearance(ctx, poses, 0, checks.section_last);
  candidate.clearance = c.distance;
  candidate.nearest_obstacle = c.obstacle_id;
  if (c.distance < kTouchingDistance) {
    candidate.rejection = "collision with object " + std::to_string(c.obstacle_id);
    return;
  }
  for (std::size_t i = checks.section_last + 1; i <= checks.contact_last && i < poses.size(); ++i) {
    const auto hit = ctx.objects.clearance(poses[i], kTouchingDistance);
    if (hit.distance < kTouchingDistance) {
      candidate.rejection = "collision with object " + std::to_string(hit.obstacle_id) + " near the end pose";
      return;
    }
  }
  if (checks.check_lanes && first_lane_departure(ctx, poses, 0, checks.departure_last, checks.expansion)) {
    candidate.rejection = "lane departure";
  }
}

std::vector<std::int64_t> lane_ids_at(const PlanningContext& ctx, const Vec2& p, std::int64_t fallback) {
  std::vector<std::int64_t> ids;
  for (std::size_t i : ctx.world.lanes_containing(p)) ids.push_back(ctx.world.lanes()[i].id);
  if (ids.empty()) ids.push_back(fallback);
  return ids;
}

}  // namespace pullout
