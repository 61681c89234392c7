#include "pullout/lane_planners/geometric_pull_out.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "geometric_internal.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/lane_planners/two_turn_path.hpp"
#include "turn_candidate.hpp"

namespace pullout {

namespace {
constexpr int kEndOffsets = 10;    // 0..9 m, as Autoware's end-pose offsets
constexpr double kSameEnd = 0.25;  // [m] end poses closer along the centerline are not tried twice
constexpr double kInfinity = std::numeric_limits<double>::infinity();

constexpr double kEdgeReach = 50.0;  // [m] outline pieces this close to the start are looked at
// [m] How far beyond lane_departure_margin the room on the kerb side is measured (more than any
// first arc's swing).
constexpr double kKerbReach = 1.0;
// [m] Left between the swing of a first arc at R_min and the kerb-side margin that yields to it.
constexpr double kSwingSlack = 0.01;
constexpr int kClearanceBisections = 14;  // a bracket of 1.2 m shrinks below 0.1 mm
// A tilted start whose first arc at R_min swings over the kerb-side edge: radii tried, each this
// factor above the last, up to kMaxFirstRadius [m].
constexpr double kFirstRadiusGrowth = 1.05;
constexpr double kMaxFirstRadius = 200.0;
// Curvatures (x 1 / R_min) of the gentler two-turn exits from a tilted start (see below).
constexpr std::array<double, 2> kGentleTurns{0.5, 0.3};

using Edges = std::vector<std::pair<Vec2, Vec2>>;

// The pieces of the lanes' outline with an end within kEdgeReach of p (along x or y): the
// manoeuvre (two arcs and a 9 m offset) stays well inside that.
Edges edges_near(const LaneWorld& world, const Vec2& p) {
  Edges out;
  const auto near = [&p](const Vec2& q) {
    return std::abs(q.x() - p.x()) <= kEdgeReach && std::abs(q.y() - p.y()) <= kEdgeReach;
  };
  for (const auto& e : world.outer_edges()) {
    if (near(e.first) || near(e.second)) out.push_back(e);
  }
  return out;
}

// Distance [m] from p along the unit direction `dir` to the outline of the union of the lanes
// (the first outer edge the ray meets); +inf when it meets none.
double distance_to_lane_edge(const Edges& edges, const Vec2& p, const Vec2& dir) {
  double best = kInfinity;
  for (const auto& [a, b] : edges) {
    // p + t dir = a + u (b - a), t >= 0, u in [0, 1].
    const Vec2 ab = b - a;
    const double den = dir.x() * ab.y() - dir.y() * ab.x();
    if (std::abs(den) < 1e-12) continue;
    const Vec2 ap = a - p;
    const double t = (ap.x() * ab.y() - ap.y() * ab.x()) / den;
    const double u = (ap.x() * dir.y() - ap.y() * dir.x()) / den;
    if (t >= 0.0 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
  }
  return best;
}

}  // namespace

double side_clearance(const LaneWorld& world, const Footprint& base, double Footprint::*side, const Pose2& pose,
                      double cap, int bisections) {
  const auto inside = [&](double e) {
    Footprint f = base;
    f.*side += e;
    return world.footprint_inside(footprint_corners(f, pose));
  };
  if (!inside(0.0)) return -1.0;
  if (inside(cap)) return cap;
  double lo = 0.0;
  double hi = cap;
  for (int i = 0; i < bisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    (inside(mid) ? lo : hi) = mid;
  }
  return lo;
}

PlannerCandidates arc_pair_candidates(const PlanningContext& ctx, const Pose2& start, const StopCondition& stop,
                                      double usable_margin, std::vector<CurvaturePath>* turn_paths,
                                      bool turn_candidates) {
  // One path per candidate (empty for those with no geometry), when asked for.
  const auto keep = [turn_paths](const CurvaturePath& path) {
    if (turn_paths != nullptr) turn_paths->push_back(path);
  };
  const auto& p = ctx.parameters;
  PlannerCandidates out;
  const double steer = ctx.vehicle.max_steer_angle_rad * p.geometric_pull_out_max_steer_angle_margin_scale;
  const double r_min = ctx.vehicle.wheel_base_m / std::tan(steer);
  const double kappa = 1.0 / r_min;
  const Polyline window = turn_window(ctx, start);
  const double v = p.geometric_pull_out_velocity;

  // The footprint the lane check keeps inside the lanes (see the header): lane_departure_margin
  // on the road side; at the front and the rear as much of it as the start pose has; on the kerb
  // side as much as the start has beyond the swing of a first arc at R_min, never less than
  // lane_departure_check_expansion_margin.
  const double margin = p.lane_departure_margin;
  const double kerb_floor = std::min(p.lane_departure_check_expansion_margin, margin);
  const Footprint plain = vehicle_footprint(ctx.vehicle);
  const Polyline& center = ctx.road.centerline;
  const auto start_on_road = center.project(to_vec(start));
  const double side = start_on_road.lateral < 0.0 ? 1.0 : -1.0;  // +1: the road is to the left
  // How far the start is turned towards the road (0: parallel to it; a shunting manoeuvre's
  // later start poses). The lanes' edge on the kerb side runs along the road.
  const double tilt = std::max(0.0, side * normalize_angle(start.yaw - center.pose_at(start_on_road.s).yaw));
  double Footprint::*const road_side = side > 0.0 ? &Footprint::left : &Footprint::right;
  double Footprint::*const kerb_side = side > 0.0 ? &Footprint::right : &Footprint::left;
  Footprint fp = plain;
  fp.front += std::max(0.0, side_clearance(ctx.world, plain, &Footprint::front, start, margin, kClearanceBisections));
  fp.rear += std::max(0.0, side_clearance(ctx.world, plain, &Footprint::rear, start, margin, kClearanceBisections));
  // Room beside the kerb side at the start (with the front and rear margins: the corners count).
  const double kerb_cap = margin + kKerbReach;
  const double kerb_gap =
      std::max(0.0, side_clearance(ctx.world, fp, kerb_side, start, kerb_cap, kClearanceBisections));
  const double swing_at_r_min = corner_swing(r_min, fp.rear, plain.*kerb_side, kPi, tilt);
  const double kerb_margin = std::clamp(kerb_gap - swing_at_r_min - kSwingSlack, kerb_floor, margin);
  fp.*road_side += margin;
  fp.*kerb_side += kerb_margin;
  const Edges edges = edges_near(ctx.world, to_vec(start));
  const double road_side_half_width = fp.*road_side;
  const double kerb_side_half_width = fp.*kerb_side;
  // Room between the lane-check footprint and the lane edge on the kerb side, at the start
  // (unbounded when no edge is within reach).
  // (The gap is measured across the vehicle; across the tilted edge it is cos(tilt) of that.)
  const double kerb_room = kerb_gap >= kerb_cap ? kInfinity : (kerb_gap - kerb_margin) * std::cos(tilt);
  // The first arc (around a centre on the road side) swings the rear corner on the kerb side
  // outwards by up to hypot(R + w, rear) - (R + w). R_min unless that crosses the kerb-side edge;
  // then the smallest radius whose swing fits: hypot(u, rear) <= u + room, u = R + w.
  double r_first = r_min;
  if (kerb_room > 0.0 && std::isfinite(kerb_room) &&
      corner_swing(r_min, fp.rear, kerb_side_half_width, kPi, tilt) > kerb_room) {
    // Parallel start: hypot(u, rear) <= u + room. Tilted: the swing shrinks with the radius too;
    // raised in steps until it fits (the closed form is the first step's floor). The closed form
    // aims kSwingSlack inside the room: solved for the room itself, the swing equals it and exceeds
    // it by rounding (2e-16 m), so the check below rejected every candidate (Autoware's shoulders
    // 10993, 13518 turned 10 degrees towards the kerb).
    const double fit = std::max(kerb_room - kSwingSlack, 0.5 * kerb_room);
    r_first = std::max(r_min, (fp.rear * fp.rear - fit * fit) / (2.0 * fit) - kerb_side_half_width);
    if (tilt > 0.0) {
      r_first = r_min;
      while (r_first < kMaxFirstRadius && corner_swing(r_first, fp.rear, kerb_side_half_width, kPi, tilt) > kerb_room) {
        r_first *= kFirstRadiusGrowth;
      }
    }
  }
  // The end poses of the S: where two arcs of r_first end on the centerline from a parallel
  // start, dx = 2 sqrt(R^2 - (R - d/2)^2) ahead along it, then 0..9 m further. On a straight road
  // that is also Autoware's point (dx ahead of and d beside the start in the start's own frame,
  // taken to the centerline). Where the road bends away from the shoulder, dx along the
  // centerline lies far round the bend (shoulder 520 of Autoware's map, the vehicle turned 10
  // degrees towards the road: 59 degrees round, where no S of R_min reaches); Autoware's point
  // lies earlier (35 degrees round, where its S does). The end poses from it up to the first one
  // along the centerline follow the 10 (tried after them, so nothing found before changes).
  const double half_offset = 0.5 * std::abs(start_on_road.lateral);
  const double q = r_first * r_first - (r_first - half_offset) * (r_first - half_offset);
  const double dx = 2.0 * std::sqrt(std::max(q, 0.0));
  const double s_along = start_on_road.s + dx;
  std::vector<double> s_ends;
  s_ends.reserve(2 * static_cast<std::size_t>(kEndOffsets));
  for (int k = 0; k < kEndOffsets; ++k) s_ends.push_back(s_along + k);
  const Vec2 in_start_frame = to_vec(start) + dx * heading(start.yaw) +
                              side * std::abs(start_on_road.lateral) * left_normal(heading(start.yaw));
  const double s_frame = std::max(center.project(in_start_frame).s, start_on_road.s);
  for (int k = 0; k < kEndOffsets && s_frame + k < s_along - kSameEnd; ++k) s_ends.push_back(s_frame + k);
  const int s_rounds = static_cast<int>(s_ends.size());

  // Tilted starts (a shunting manoeuvre's): after the S candidates, two turns at R_min joined by
  // a tangent of 0..9 m (which may turn away from the road first: a counter-arc onto the lane),
  // then the same at the gentler curvatures of kGentleTurns: from a pose turned across a single
  // road lane the front corner on the road side swings over the far edge by up to
  // hypot(R + w, front) - (R + w) while the vehicle straightens (1.1 m at R_min 5.06 m, 0.64 m
  // at 10 m), so a larger radius is what fits the road's width.
  const int rounds = turn_candidates ? s_rounds + (1 + static_cast<int>(kGentleTurns.size())) * kEndOffsets : s_rounds;
  for (int round = 0; round < rounds; ++round) {
    out.stopped = stop.check();
    if (out.stopped != StopReason::kNone) break;
    const bool tangent_round = round >= s_rounds;
    const bool earlier_end = !tangent_round && round >= kEndOffsets;  // from Autoware's point
    const int k = tangent_round ? (round - s_rounds) % kEndOffsets : round % kEndOffsets;
    // index into kGentleTurns, < 0: R_min
    const int gentle = tangent_round ? (round - s_rounds) / kEndOffsets - 1 : -1;
    // An S of two arcs to the end pose on the centerline: the first arc at r_first, the second's
    // radius solved (Vorobieva). Where no S reaches it (a start across the road, out of a
    // perpendicular bay), two turns at R_min joined by a k m tangent.
    std::optional<TwoTurnPath> turns;
    if (!tangent_round && q >= 0.0 && s_ends[static_cast<std::size_t>(round)] <= center.length()) {
      const Pose2 end = center.pose_at(s_ends[static_cast<std::size_t>(round)]);
      turns = solve_arc_pair(start, end, r_first, r_min);
      // The end beside the kerb side of the start's heading (a start turned towards the road,
      // the road bending back): the S still turns towards the road first, as Autoware's.
      if (!turns) turns = solve_arc_pair(start, end, r_first, r_min, side);
    }
    const bool arc_pair = turns.has_value();
    if (!arc_pair && !earlier_end) {  // the two turns with a k m tangent were tried in round k
      const double kappa_turn = gentle < 0 ? kappa : kappa * kGentleTurns[static_cast<std::size_t>(gentle)];
      turns = solve_two_turn(start, window, {kappa_turn, 0.0, static_cast<double>(k)});
    }
    if (!turns) {
      PathCandidate none;
      none.rejection = Failure{AttemptOutcome::kNoGeometry, "no two-arc path to the centerline"};
      out.candidates.push_back(std::move(none));
      keep({});
      continue;
    }
    if (arc_pair) {
      // The swing of the outermost corners, analytically, before the footprint check: the front
      // corner on the road side on the second arc against the lane edge beyond the end pose, the
      // rear corner on the kerb side on the first arc against the kerb-side edge.
      const auto& arcs = turns->path.pieces();
      const Pose2 end = turns->path.end();
      const double r_second = 1.0 / std::abs(arcs[1].k0);
      const double far_room =
          distance_to_lane_edge(edges, to_vec(end), side * left_normal(heading(end.yaw))) - road_side_half_width;
      const double far_swing = corner_swing(r_second, fp.front, road_side_half_width, arcs[1].length / r_second);
      const double kerb_swing = corner_swing(r_first, fp.rear, kerb_side_half_width, arcs[0].length / r_first, tilt);
      if (far_swing > far_room || kerb_swing > kerb_room) {
        PathCandidate swing;
        swing.rejection = Failure{AttemptOutcome::kLaneDeparture,
                                  far_swing > far_room ? "the front corner swings over the far lane edge"
                                                       : "the rear corner swings over the kerb-side edge"};
        out.candidates.push_back(std::move(swing));
        keep({});
        continue;
      }
    }
    // The stop to re-steer is needed where the steering swaps sides (an S-shaped path); two turns
    // the same way (out of a perpendicular bay) flow into each other.
    const auto& pieces = turns->path.pieces();
    const bool s_shaped = turns->first_turn_pieces > 0 && turns->first_turn_pieces < pieces.size() &&
                          pieces.front().k0 * pieces.back().k0 < 0.0;
    const bool divide = p.divide_pull_out_path && s_shaped;
    const std::size_t first_turn = turns->first_turn_pieces;
    double first_turn_length = 0.0;
    for (std::size_t i = 0; i < first_turn; ++i) first_turn_length += pieces[i].length;
    // A short first arc cannot reach v comfortably before stopping: cruise at what
    // maximum_longitudinal_acc reaches over half of it.
    const double v1 = divide ? std::min(v, std::sqrt(p.maximum_longitudinal_acc * first_turn_length)) : v;
    auto segment = [divide, first_turn, v, v1](const std::vector<Pose2>& pts,
                                               const std::vector<std::size_t>& junctions) {
      TurnSegmentation seg;
      const auto length_between = [&pts](std::size_t a, std::size_t b) {
        double len = 0.0;
        for (std::size_t i = a + 1; i <= b; ++i) len += std::hypot(pts[i].x - pts[i - 1].x, pts[i].y - pts[i - 1].y);
        return len;
      };
      const std::size_t last = pts.size() - 1;
      if (divide && first_turn > 0 && first_turn <= junctions.size() && junctions[first_turn - 1] < last) {
        const std::size_t split = junctions[first_turn - 1];
        const double l1 = length_between(0, split);
        const double l2 = length_between(split, last);
        seg.splits = {split};
        seg.pairs = {{v1, v1 * v1 / l1}, {v, v * v / (2.0 * l2)}};
      } else {
        seg.pairs = {{v, v * v / (2.0 * length_between(0, last))}};
      }
      return seg;
    };
    TurnCandidateOptions options;
    options.check_lanes = true;
    options.departure_footprint = fp;
    options.collision_distance_from_end = p.geometric_collision_check_distance_from_end;
    options.output_interval = p.arc_path_interval;
    const auto velocity = [divide, first_turn_length, v, v1](double d) {
      return divide && d < 0.99 * first_turn_length ? v1 : v;  // chords are shorter than arcs
    };
    out.candidates.push_back(make_turn_candidate(ctx, *turns, options, velocity, segment));
    keep(turns->path);
    const PathCandidate& added = out.candidates.back();
    if (std::isfinite(usable_margin) && !added.rejection && added.clearance >= usable_margin) break;
  }
  return out;
}

PlannerCandidates GeometricPullOut::plan(const PlanningContext& ctx, const Pose2& start,
                                         const StopCondition& stop) const {
  return arc_pair_candidates(ctx, start, stop, kInfinity, nullptr, false);
}

}  // namespace pullout
