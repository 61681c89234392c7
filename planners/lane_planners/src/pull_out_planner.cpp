#include "pullout/lane_planners/pull_out_planner.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "pullout/collision/footprint.hpp"
#include "pullout/model/names.hpp"

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

Failure stopped_failure(StopReason reason) {
  switch (reason) {
    case StopReason::kCancelled:
      return {AttemptOutcome::kCancelled, ""};
    case StopReason::kBudget:
      return {AttemptOutcome::kTimeout, "the planner's time budget"};
    default:
      return {AttemptOutcome::kTimeout, "the planning deadline"};
  }
}

Selection select_candidate(const PlannerCandidates& pc, double margin) {
  Selection sel;
  if (pc.candidates.empty()) {
    if (pc.stopped != StopReason::kNone) {
      const Failure f = stopped_failure(pc.stopped);
      sel.outcome = f.outcome;
      sel.detail = f.detail;
    } else if (pc.failure) {
      sel.outcome = pc.failure->outcome;
      sel.detail = pc.failure->detail;
    } else {
      sel.outcome = AttemptOutcome::kNoPath;
    }
    return sel;
  }
  // The reasons in order of first appearance (the preferred candidate's first), with counts.
  struct Reason {
    Failure failure;
    int count{0};
  };
  std::vector<Reason> reasons;
  const auto count = [&reasons](AttemptOutcome outcome, const std::string& detail) {
    for (Reason& r : reasons) {
      if (r.failure.outcome == outcome && r.failure.detail == detail) {
        ++r.count;
        return;
      }
    }
    reasons.push_back({{outcome, detail}, 1});
  };
  for (const PathCandidate& c : pc.candidates) {
    if (c.rejection) {
      count(c.rejection->outcome, c.rejection->detail);
    } else if (c.clearance < margin) {
      count(AttemptOutcome::kCollision, "object " + std::to_string(c.nearest_obstacle));
    } else {
      sel.chosen = &c;
      sel.outcome = AttemptOutcome::kSuccess;
      return sel;
    }
  }
  // The outcome of most candidates (summed over details), the first met on a tie.
  std::vector<std::pair<AttemptOutcome, int>> totals;
  for (const Reason& r : reasons) {
    auto it = std::find_if(totals.begin(), totals.end(), [&r](const auto& t) { return t.first == r.failure.outcome; });
    if (it == totals.end()) {
      totals.emplace_back(r.failure.outcome, r.count);
    } else {
      it->second += r.count;
    }
  }
  const auto top =
      std::max_element(totals.begin(), totals.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  sel.outcome = top->first;
  const auto total = pc.candidates.size();
  for (const Reason& r : reasons) {
    std::string text = r.failure.outcome == sel.outcome ? r.failure.detail : to_string(r.failure.outcome);
    if (r.failure.outcome != sel.outcome && !r.failure.detail.empty()) text += ": " + r.failure.detail;
    if (total > 1) {
      std::string counted = std::to_string(r.count);
      counted.append("/").append(std::to_string(total)).append(" candidates");
      if (text.empty()) {
        text = std::move(counted);
      } else {
        text.append(" (").append(counted).append(")");
      }
    }
    if (text.empty()) continue;
    if (!sel.detail.empty()) sel.detail += "; ";
    sel.detail += text;
  }
  if (pc.stopped != StopReason::kNone) {
    // Cut short: the candidates checked so far are the detail, the stop is the outcome.
    const Failure f = stopped_failure(pc.stopped);
    const std::string checked = sel.detail.empty() ? std::string(to_string(sel.outcome))
                                                   : std::string(to_string(sel.outcome)) + ": " + sel.detail;
    sel.outcome = f.outcome;
    sel.detail = (f.detail.empty() ? std::string() : f.detail + "; ") + "checked before: " + checked;
  }
  return sel;
}

std::optional<std::size_t> first_lane_departure(const PlanningContext& ctx, const std::vector<Pose2>& poses,
                                                std::size_t first, std::size_t last, const Footprint& fp) {
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
    candidate.rejection = Failure{AttemptOutcome::kCollision, "object " + std::to_string(c.obstacle_id)};
    return;
  }
  for (std::size_t i = checks.section_last + 1; i <= checks.contact_last && i < poses.size(); ++i) {
    const auto hit = ctx.objects.clearance(poses[i], kTouchingDistance);
    if (hit.distance < kTouchingDistance) {
      candidate.rejection =
          Failure{AttemptOutcome::kCollision, "object " + std::to_string(hit.obstacle_id) + " near the end pose"};
      return;
    }
  }
  if (checks.check_lanes && first_lane_departure(ctx, poses, 0, checks.departure_last, checks.departure_footprint)) {
    candidate.rejection = Failure{AttemptOutcome::kLaneDeparture, ""};
  }
}

std::vector<std::int64_t> lane_ids_at(const PlanningContext& ctx, const Vec2& p, std::int64_t fallback) {
  std::vector<std::int64_t> ids;
  for (std::size_t i : ctx.world.lanes_containing(p)) ids.push_back(ctx.world.lanes()[i].id);
  if (ids.empty()) ids.push_back(fallback);
  return ids;
}

}  // namespace pullout
