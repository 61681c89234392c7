// The geometric planner's shunting manoeuvre (see geometric_pull_out.hpp): moves at full lock,
// alternating forward and reverse, each until just clear, then the S.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "geometric_internal.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/lane_planners/geometric_pull_out.hpp"
#include "turn_candidate.hpp"

namespace pullout {

namespace {

// [m] Added to the smallest collision margin where a move stops: the clearance between samples
// can fall below a sampled one by at most (Lipschitz constant <= 1.6) x half the largest step.
constexpr double kStopSlack = 0.02;
// [m] Added to the smallest margin for the dense clearance of the S: between samples 1 cm apart
// the clearance falls by at most 1.6 x 0.5 cm below them.
constexpr double kDenseSlack = 0.01;
constexpr double kMinStep = 0.02;    // [m] sampling of a move where the clearance is near the limit
constexpr double kMaxStep = 0.1;     // [m] and where it is not (and of the lane check)
constexpr int kEndBisections = 10;   // a bracket of 0.1 m shrinks to 0.1 mm
constexpr double kMinMove = 0.01;    // [m] a move shorter than this is a dead end
constexpr double kLaneSlack = 0.01;  // [m] footprint growth of the moves' lane check
// [rad] A move turns the vehicle by at most this (then the S is tried again: a forward arc that
// has passed the car ahead would otherwise turn on until the far lane edge stops it); a vehicle
// turned further than kMaxTilt from the road is not leaving a parallel spot any more.
constexpr double kMaxMoveTurn = kPi / 8.0;
constexpr double kMaxTilt = kPi / 2.0;
// [rad] Where every try got turned across the road, the moves of the last tries turn at most
// this much (5, then 3 degrees): a forward and a reverse move of kMaxMoveTurn turn the vehicle by
// 35-40 degrees between two tries of the exit, and on one road lane round a 30 m bend the turns
// whose exit passes the car ahead with the smallest margin and still fits the lane lie in between
// (right-hand, 0.5 m from the kerb: 0.06 m from the car ahead at 31 degrees, over the far edge at
// 71). Which of the two sizes leaves a spot differs from spot to spot (both stop after
// geometric_pull_out_max_shunts), so both are tried.
constexpr std::array<double, 2> kFineMoveTurns{kPi / 36.0, kPi / 60.0};
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kOutputInterval = 0.1;  // [m] points of a move: chords within 0.3 mm of a 5 m arc
// [m] Creeping away from the kerb (see plan_multi_move) goes on until the lane check's footprint
// has this much room on the kerb side (where the shunts get out from: every spot 0.3 m from the
// kerb with 1.0 m of slack or more and two road lanes is left), at most kMaxCreeps times, while
// each gains kMinCreep or more.
constexpr double kCreepTarget = 0.3;
// [m] The second try's target, where creeping to kCreepTarget was not enough or shunting got stuck
// otherwise (turned across a single road lane: from further out less turn passes the car ahead).
constexpr double kCreepFar = 0.6;
// [m] Room on the kerb side below which creeping comes first (see plan_multi_move).
constexpr double kCreepFirst = 0.2;
constexpr int kMaxCreeps = 8;
constexpr double kMinCreep = 0.01;

struct Move {
  Pose2 from;
  double curvature{0.0};  // [1/m] of the path driven, left positive
  double direction{1.0};  // +1 forward, -1 reverse
  double length{0.0};     // [m] > 0

  // The pose after driving s [m] (0 <= s <= length) in the move's direction.
  Pose2 at(double s) const { return CurvaturePath::advance(from, {1.0, curvature, curvature}, direction * s); }
  // Its poses as a path driven forward (a reverse move's from its end).
  CurvaturePath path() const {
    const CurvaturePiece piece{length, curvature, curvature};
    return CurvaturePath(direction > 0.0 ? from : at(length), {piece});
  }
};

struct MoveLimit {
  double length{0.0};
  bool lanes{false};  // stopped by the lanes (else by an obstacle or the cap)
};

// How far the vehicle can drive from `from` with curvature k in `direction`, up to `cap` [m]:
// every pose keeps `lane_fp` inside the lanes, and the clearance never falls below `limit` while
// it falls (driving away from an obstacle already closer than `limit` is allowed).
MoveLimit drive_until_clear(const PlanningContext& ctx, const Pose2& from, double k, double direction, double cap,
                            const Footprint& lane_fp, double limit) {
  const Move m{from, k, direction, cap};
  const double lipschitz = 1.0 + std::abs(k) * ctx.objects.footprint().bounding_radius();
  const double horizon = limit + lipschitz * kMaxStep + 1.0;
  const auto clearance = [&](double s) { return ctx.objects.clearance(m.at(s), horizon).distance; };
  const auto inside = [&](double s) { return ctx.world.footprint_inside(footprint_corners(lane_fp, m.at(s))); };
  // Whether s is reachable from the last good sample (clearance c_good there).
  const auto good = [&](double s, double c_good, bool& lanes, double& c) {
    lanes = !inside(s);
    if (lanes) return false;
    c = clearance(s);
    return !(c < limit && c < c_good);
  };
  double s = 0.0;
  double c = clearance(0.0);
  MoveLimit out;
  while (s < cap) {
    const double step = std::clamp((c - limit) / lipschitz, kMinStep, kMaxStep);
    const double next = std::min(cap, s + step);
    bool lanes = false;
    double c_next = 0.0;
    if (good(next, c, lanes, c_next)) {
      s = next;
      c = c_next;
      continue;
    }
    // The end lies in (s, next]: bisect.
    double lo = s;
    double hi = next;
    for (int i = 0; i < kEndBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      bool mid_lanes = false;
      double c_mid = 0.0;
      if (good(mid, c, mid_lanes, c_mid)) {
        lo = mid;
      } else {
        hi = mid;
        lanes = mid_lanes;
      }
    }
    out.length = lo;
    out.lanes = lanes;
    return out;
  }
  out.length = cap;
  return out;
}

// The smallest clearance [m] to the static obstacles over the first `length` [m] of `path`, by
// conservative advancement: from a pose with clearance c the next sample is (c - floor) / L
// further (L bounds how fast any point of the footprint moves per metre driven), so nothing
// between two samples comes closer than `floor`; where that step is below 1 cm it is 1 cm, and
// the clearance between those samples can fall below them by at most L x 0.5 cm (0.8 cm at
// R_min 5 m). Returns at the first sample below `floor` (then not the minimum: a value below
// `floor` means "closer than floor somewhere").
ObjectChecker::Clearance dense_clearance(const PlanningContext& ctx, const CurvaturePath& path, double length,
                                         double floor) {
  const double lipschitz = 1.0 + path.max_abs_curvature() * ctx.objects.footprint().bounding_radius();
  const double horizon = floor + lipschitz * kMaxStep * 5.0 + 1.0;
  ObjectChecker::Clearance best;
  double s = 0.0;
  for (;;) {
    Pose2 q = path.start();
    double rest = std::min(s, length);
    for (const CurvaturePiece& piece : path.pieces()) {
      if (rest <= piece.length) {
        q = CurvaturePath::advance(q, piece, rest);
        rest = 0.0;
        break;
      }
      q = CurvaturePath::advance(q, piece, piece.length);
      rest -= piece.length;
    }
    const auto c = ctx.objects.clearance(q, horizon);
    if (c.distance < best.distance) best = c;
    if (best.distance < floor || s >= length) return best;
    s += std::clamp((c.distance - floor) / lipschitz, 0.5 * kMinStep, 5.0 * kMaxStep);
  }
}

// The partial path of one move: points every kOutputInterval at `speed` (signed), 0 at its end.
PathWithLaneId move_points(const PlanningContext& ctx, const Move& m, double speed) {
  PathWithLaneId seg;
  const int n = std::max(1, static_cast<int>(std::ceil(m.length / kOutputInterval)));
  const Polyline& center = ctx.road.centerline;
  for (int i = 0; i <= n; ++i) {
    PathPoint p;
    p.pose = m.at(m.length * i / n);
    p.longitudinal_velocity_mps = i == n ? 0.0 : speed;
    p.lane_ids = lane_ids_at(ctx, to_vec(p.pose), road_lane_id_at(ctx, center.project(to_vec(p.pose)).s));
    seg.points.push_back(std::move(p));
  }
  return seg;
}

}  // namespace

PlannerCandidates GeometricPullOut::plan_multi_move(const PlanningContext& ctx, const Pose2& start,
                                                    const StopCondition& stop) const {
  const auto& p = ctx.parameters;
  PlannerCandidates out;
  if (p.geometric_pull_out_max_shunts <= 0) return out;
  const auto fail = [&out](AttemptOutcome outcome, std::string detail) {
    out.failure = Failure{outcome, "shunting: " + std::move(detail)};
    return out;
  };
  const double steer = ctx.vehicle.max_steer_angle_rad * p.geometric_pull_out_max_steer_angle_margin_scale;
  const double kappa = std::tan(steer) / ctx.vehicle.wheel_base_m;
  const Polyline& center = ctx.road.centerline;
  const auto on_road = center.project(to_vec(start));
  const double side = on_road.lateral < 0.0 ? 1.0 : -1.0;  // +1: the road is to the left
  const double limit = ctx.smallest_margin + kStopSlack;
  // The moves' lane check: the footprint grown by lane_departure_check_expansion_margin (and 1 cm
  // where the start has it).
  Footprint lane_fp = vehicle_footprint(ctx.vehicle, p.lane_departure_check_expansion_margin + kLaneSlack);
  if (!ctx.world.footprint_inside(footprint_corners(lane_fp, start))) {
    lane_fp = vehicle_footprint(ctx.vehicle, p.lane_departure_check_expansion_margin);
    if (!ctx.world.footprint_inside(footprint_corners(lane_fp, start))) {
      return fail(AttemptOutcome::kLaneDeparture,
                  "the start's footprint (with lane_departure_check_expansion_margin) leaves the lanes");
    }
  }

  std::vector<Move> moves;
  Pose2 pose = start;
  const double r_min = 1.0 / kappa;
  double Footprint::*const kerb_side = side > 0.0 ? &Footprint::right : &Footprint::left;
  const auto tilt_at = [&](const Pose2& q) {
    return side * normalize_angle(q.yaw - center.pose_at(center.project(to_vec(q)).s).yaw);
  };
  const auto add = [&](double k, double direction, double cap) {
    Footprint fp = lane_fp;
    if (direction < 0.0 && k != 0.0) {
      // A reverse arc takes the rear towards the kerb; it leaves the room the next forward arc's
      // rear corner swings out by (less as the vehicle turns further, so the start's tilt bounds
      // it), where the start has that room.
      fp.*kerb_side += corner_swing(r_min, fp.rear, fp.*kerb_side, kPi, std::max(0.0, tilt_at(pose)));
      if (!ctx.world.footprint_inside(footprint_corners(fp, pose))) fp = lane_fp;
    }
    const MoveLimit lim = drive_until_clear(ctx, pose, k, direction, cap, fp, limit);
    if (lim.length < kMinMove) return false;
    moves.push_back({pose, k, direction, lim.length});
    pose = moves.back().at(lim.length);
    return true;
  };
  // The room [m] beside the kerb side of lane_fp at q, up to kCreepTarget (bisection).
  double creep_target = 0.0;  // [m] 0: no creeping
  const auto kerb_room = [&](const Pose2& q) {
    return std::max(0.0, side_clearance(ctx.world, lane_fp, kerb_side, q, creep_target, kEndBisections));
  };
  double move_cap = kMaxMoveTurn / kappa;
  std::optional<PathCandidate> exit;
  std::string stuck;
  // 1. (of each shunt) The S from `pose`, into `exit` when one is usable.
  const auto try_exit = [&]() {
    // The candidates in order up to the first usable one (the rest are not needed when its dense
    // check passes); all of them only where it does not: the same exit as taking all at once.
    for (const double usable : {ctx.smallest_margin, kInfinity}) {
      std::vector<CurvaturePath> turn_paths;
      PlannerCandidates s = arc_pair_candidates(ctx, pose, stop, usable, &turn_paths, moves.size() > 1);
      bool usable_found = false;
      for (std::size_t i = 0; i < s.candidates.size(); ++i) {
        PathCandidate& c = s.candidates[i];
        if (c.rejection || c.clearance < ctx.smallest_margin) continue;
        usable_found = true;
        // The S's own clearance samples every 0.5 m and refines around minima; from a tilted
        // start the corners pass the cars within centimetres of the start, so it is taken
        // densely here.
        const CurvaturePath& turns = turn_paths[i];
        const auto dense = dense_clearance(ctx, turns, turns.length(), ctx.smallest_margin + kDenseSlack);
        if (dense.distance < ctx.smallest_margin + kDenseSlack) continue;
        exit = std::move(c);
        break;
      }
      // Without a usable candidate the first call has looked at all of them.
      if (exit || !usable_found) break;
    }
  };
  // The manoeuvre, with moves of at most `turn` [rad]; with `target` > 0, first edge away from the
  // kerb to that much room (see kCreepTarget). False when it got stuck (`stuck` says where).
  const auto manoeuvre = [&](double target, double turn) {
    creep_target = target;
    move_cap = turn / kappa;
    moves.clear();
    pose = start;
    exit.reset();
    // 0. Straight back until just clear of what is behind.
    if (ctx.max_back_distance > 0.0) add(0.0, -1.0, ctx.max_back_distance);
    // Creeping: forward at full lock towards the road over half the room ahead, at full lock the
    // other way back to the heading it started with, straight back until just clear: the vehicle
    // ends beside where it was, 2 R (1 - cos(L / 2R)) further from the kerb for L [m] of room (3 cm
    // at 0.76 m, 8 cm at 1.26 m). The rear corner on the kerb side dips by about rear x L / 2R on
    // the way and is back above its start at the end.
    for (int c = 0; target > 0.0 && c < kMaxCreeps && kerb_room(pose) < target; ++c) {
      const double before = kerb_room(pose);
      const std::size_t kept = moves.size();
      const Pose2 kept_pose = pose;
      const MoveLimit ahead = drive_until_clear(ctx, pose, 0.0, 1.0, 2.0 * target + 2.0, lane_fp, limit);
      const double yaw0 = pose.yaw;
      bool ok = ahead.length >= 2.0 * kMinCreep && add(side * kappa, 1.0, 0.5 * ahead.length);
      ok = ok && add(-side * kappa, 1.0, std::abs(normalize_angle(pose.yaw - yaw0)) / kappa);
      ok = ok && add(0.0, -1.0, ctx.max_back_distance);
      if (!ok || kerb_room(pose) < before + kMinCreep) {
        moves.resize(kept);
        pose = kept_pose;
        break;
      }
    }
    for (int shunt = 0;; ++shunt) {
      out.stopped = stop.check();
      if (out.stopped != StopReason::kNone) return false;
      try_exit();
      if (exit) break;
      if (shunt >= p.geometric_pull_out_max_shunts) {
        stuck = "no S onto the road after " + std::to_string(shunt) + " shunts";
        break;
      }
      if (tilt_at(pose) > kMaxTilt) {
        stuck = "turned across the road after " + std::to_string(shunt) + " shunts";
        break;
      }
      // 2. Forward at full lock towards the road, reverse at full lock the other way.
      if (!add(side * kappa, 1.0, move_cap)) {
        stuck = "no room to move forward after " + std::to_string(shunt) + " shunts";
        break;
      }
      // Where the rear has reached the kerb at full lock, straight back still makes room ahead (it
      // takes the rear corner towards the kerb less than a reverse arc up to about 60 degrees).
      if (!add(-side * kappa, -1.0, move_cap) && !add(0.0, -1.0, move_cap)) {
        stuck = "no room to reverse after " + std::to_string(shunt) + " shunts and a forward move";
        break;
      }
    }
    return exit.has_value();
  };
  // Where the reverse moves have taken the rear corner to the kerb, again after creeping away
  // from it (a car parked 0.15 m from the kerb); where that or the first try got stuck otherwise,
  // again after creeping further.
  // Closer to the kerb than kCreepFirst the full-lock shunts get stuck (almost) always: creep
  // first there, and only then try without.
  creep_target = kCreepTarget;
  const bool close = kerb_room(start) < kCreepFirst;
  struct Try {
    double creep;  // [m] creep_target
    double turn;   // [rad] of a move at most
  };
  std::vector<Try> tries;
  if (close) {
    tries = {{kCreepTarget, kMaxMoveTurn}, {0.0, kMaxMoveTurn}, {kCreepFar, kMaxMoveTurn}};
  } else {
    tries = {{0.0, kMaxMoveTurn}, {kCreepTarget, kMaxMoveTurn}, {kCreepFar, kMaxMoveTurn}};
  }
  for (const double fine : kFineMoveTurns) {
    tries.push_back({0.0, fine});
    tries.push_back({kCreepFar, fine});
  }
  std::string why;
  bool turned_across = false;
  for (std::size_t t = 0; t < tries.size(); ++t) {
    // Without creeping first, creeping to kCreepTarget helps only where the rear corner got stuck.
    if (!close && t == 1 && stuck.rfind("no room to reverse", 0) != 0) continue;
    if (tries[t].turn < kMaxMoveTurn && !turned_across) break;
    const bool left = manoeuvre(tries[t].creep, tries[t].turn);
    if (out.stopped != StopReason::kNone) return out;
    if (left) break;
    turned_across = turned_across || stuck.rfind("turned across", 0) == 0;
    why += (why.empty() ? "" : "; ") +
           (tries[t].turn < kMaxMoveTurn
                ? "moves of " + std::to_string(static_cast<int>(std::lround(tries[t].turn * 180.0 / kPi))) + " deg, "
                : std::string()) +
           (tries[t].creep > 0.0 ? "after creeping to " + std::to_string(tries[t].creep).substr(0, 3) + " m: "
                                 : std::string()) +
           stuck;
  }
  stuck = why;
  if (!exit) return fail(AttemptOutcome::kNoGeometry, stuck);

  // The moves' exact clearance (sampled while driving; the S's is the candidate's).
  PathCandidate candidate;
  candidate.clearance = exit->clearance;
  candidate.nearest_obstacle = exit->nearest_obstacle;
  for (const Move& m : moves) {
    const auto c = dense_clearance(ctx, m.path(), m.length, ctx.smallest_margin + kDenseSlack);
    if (c.distance < ctx.smallest_margin + kDenseSlack) {
      // Closer than the smallest margin allows somewhere (dense_clearance stopped there).
      candidate.rejection = Failure{AttemptOutcome::kCollision, "object " + std::to_string(c.obstacle_id) +
                                                                    " closer than the smallest margin on a move"};
      candidate.clearance = c.distance;
      candidate.nearest_obstacle = c.obstacle_id;
      break;
    }
    if (c.distance < candidate.clearance) {
      candidate.clearance = c.distance;
      candidate.nearest_obstacle = c.obstacle_id;
    }
  }
  auto shared_moves = std::make_shared<const std::vector<Move>>(std::move(moves));
  candidate.build = [&ctx, shared_moves, exit_build = exit->build, start]() {
    const auto& prm = ctx.parameters;
    PullOutPath path;
    for (const Move& m : *shared_moves) {
      // Cruise at what maximum_longitudinal_acc reaches over half the move (a = v^2 / L then
      // brings it to a stop at the end).
      const double cruise = m.direction > 0.0 ? prm.geometric_pull_out_velocity : ctx.reverse_speed;
      const double v = std::min(cruise, std::sqrt(prm.maximum_longitudinal_acc * m.length));
      path.partial_paths.push_back(move_points(ctx, m, m.direction * v));
      path.pairs_terminal_velocity_and_accel.push_back({m.direction * v, m.direction * v * v / m.length});
    }
    PullOutPath s = exit_build();
    for (auto& seg : s.partial_paths) path.partial_paths.push_back(std::move(seg));
    for (const auto& pair : s.pairs_terminal_velocity_and_accel) path.pairs_terminal_velocity_and_accel.push_back(pair);
    path.start_pose = start;
    path.end_pose = s.end_pose;
    path.shift_length_m = ctx.road.centerline.project(to_vec(start)).lateral;
    return path;
  };
  out.candidates.push_back(std::move(candidate));
  return out;
}

}  // namespace pullout
