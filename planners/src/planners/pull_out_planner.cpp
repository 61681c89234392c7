#include "pullout/planners/pull_out_planner.hpp"

#include <map>
#include <sstream>

#include "pullout/collision/footprint.hpp"

namespace pullout {

namespace {
constexpr double kTouchingDistance = 1e-6;  // [m] clearance below this is contact
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
                                                std::size_t first, std::size_t last) {
  const Footprint fp = vehicle_footprint(ctx.vehicle, ctx.parameters.lane_departure_check_expansion_margin);
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

void check_candidate(const PlanningContext& ctx, const std::vector<Pose2>& poses, bool check_lanes,
                     std::size_t departure_last, std::size_t section_last, std::size_t contact_last,
                     PathCandidate& candidate) {
  if (check_lanes) {
    if (const auto i = first_lane_departure(ctx, poses, 0, departure_last)) {
      candidate.rejection = "lane departure";
      return;
    }
  }
  const auto c = section_clearance(ctx, poses, 0, section_last);
  candidate.clearance = c.distance;
  candidate.nearest_obstacle = c.obstacle_id;
  for (std::size_t i = section_last + 1; i <= contact_last && i < poses.size(); ++i) {
    const auto hit = ctx.objects.clearance(poses[i], kTouchingDistance);
    if (hit.distance < kTouchingDistance) {
      candidate.rejection = "collision with object " + std::to_string(hit.obstacle_id) + " near the end pose";
      return;
    }
  }
}

std::vector<std::int64_t> lane_ids_at(const PlanningContext& ctx, const Vec2& p, std::int64_t fallback) {
  std::vector<std::int64_t> ids;
  for (std::size_t i : ctx.world.lanes_containing(p)) ids.push_back(ctx.world.lanes()[i].id);
  if (ids.empty()) ids.push_back(fallback);
  return ids;
}

}  // namespace pullout
