#include "pullout/lane_planners/two_turn_path.hpp"
#include "pullout/geometry/angle.hpp"

#include <algorithm>
#include <cmath>

namespace pullout {

namespace {

constexpr double kLateralTolerance = 1e-4;   // [m] root accuracy
constexpr double kJoinTolerance = 0.05;      // [m] accepted distance of the end to the centerline
constexpr double kHeadingTolerance = 0.035;  // [rad] (2 deg) accepted heading mismatch at the end
constexpr double kParallelStart = 0.05;      // [rad] start counts as parallel to the road below this
constexpr int kMaxHeadingIterations = 4;
constexpr int kMaxRootIterations = 40;

struct Evaluation {
  double lateral{0.0};
  double s_end{0.0};
  Pose2 end;
};

std::vector<CurvaturePiece> two_turns(double d1, double d2, const TwoTurnSpec& spec, std::size_t* first_turn) {
  std::vector<CurvaturePiece> pieces;
  append_turn(pieces, d1, spec.kappa, spec.sharpness);
  if (first_turn != nullptr) *first_turn = pieces.size();
  if (spec.straight > 1e-9) pieces.push_back({spec.straight, 0.0, 0.0});
  append_turn(pieces, d2, spec.kappa, spec.sharpness);
  return pieces;
}

Evaluation evaluate(const Pose2& start, double d1, double psi_target, const Polyline& center, const TwoTurnSpec& spec) {
  const double d2 = normalize_angle(psi_target - start.yaw - d1);
  // Called tens of times per solve: the pieces go into a reused buffer, not a new vector.
  thread_local std::vector<CurvaturePiece> pieces;
  pieces.clear();
  append_turn(pieces, d1, spec.kappa, spec.sharpness);
  if (spec.straight > 1e-9) pieces.push_back({spec.straight, 0.0, 0.0});
  append_turn(pieces, d2, spec.kappa, spec.sharpness);
  Pose2 p = start;
  for (const CurvaturePiece& piece : pieces) p = CurvaturePath::advance(p, piece, piece.length);
  const auto proj = center.project(to_vec(p));
  return {proj.lateral, proj.s, p};
}

// Closed form of the two-arc S-curve with a straight: lateral displacement
// 2R(1 - cos d) + l sin d, increasing in d on [0, pi/2]. Returns d for |offset|, or nullopt.
std::optional<double> arc_s_curve_angle(double offset, double radius, double straight) {
  const auto disp = [&](double d) { return 2.0 * radius * (1.0 - std::cos(d)) + straight * std::sin(d); };
  if (disp(kPi / 2) < offset) return std::nullopt;
  double lo = 0.0;
  double hi = kPi / 2;
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (lo + hi);
    (disp(mid) < offset ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Illinois (modified regula falsi) on [a, b] with f(a), f(b) of opposite signs.
template <typename F>
std::optional<double> refine(const F& f, double a, double fa, double b, double fb) {
  int side = 0;
  for (int i = 0; i < kMaxRootIterations; ++i) {
    const double c = (a * fb - b * fa) / (fb - fa);
    const double fc = f(c);
    if (std::abs(fc) < kLateralTolerance) return c;
    if ((fc > 0.0) == (fb > 0.0)) {
      b = c;
      fb = fc;
      if (side == -1) fa /= 2.0;
      side = -1;
    } else {
      a = c;
      fa = fc;
      if (side == 1) fb /= 2.0;
      side = 1;
    }
  }
  return std::nullopt;
}

// Turning angle in (0, 2 pi) from radius vector a to b going round in direction `side` (+1:
// counter-clockwise).
double turning_angle(const Vec2& a, const Vec2& b, double side) {
  double w = side * std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
  if (w <= 0.0) w += kTwoPi;
  return w;
}

}  // namespace

std::optional<TwoTurnPath> solve_arc_pair(const Pose2& start, const Pose2& end, double r1, double min_radius,
                                          double first_side) {
  constexpr double kMinLateral = 1e-3;    // [m] an end closer to the start's line needs no S
  constexpr double kMinTurn = 1e-6;       // [rad]
  constexpr double kEndTolerance = 1e-6;  // [m] the constructed path must end on `end`
  if (r1 <= 0.0) return std::nullopt;
  const Vec2 s = to_vec(start);
  const Vec2 e = to_vec(end);
  const Vec2 n_start = left_normal(heading(start.yaw));
  const double lateral = (e - s).dot(n_start);
  if (std::abs(lateral) < kMinLateral) return std::nullopt;
  // +1: the first arc turns left.
  const double side = first_side != 0.0 ? (first_side > 0.0 ? 1.0 : -1.0) : (lateral > 0.0 ? 1.0 : -1.0);
  const Vec2 c1 = s + side * r1 * n_start;
  const Vec2 n = -side * left_normal(heading(end.yaw));  // from the end towards the second centre
  const Vec2 d = c1 - e;
  const double denom = 2.0 * (r1 + d.dot(n));
  if (denom <= 1e-12) return std::nullopt;
  const double r2 = (d.squaredNorm() - r1 * r1) / denom;
  if (r2 <= 0.0 || r2 < min_radius * (1.0 - 1e-9)) return std::nullopt;
  const Vec2 c2 = e + r2 * n;
  const Vec2 c12 = c2 - c1;
  if (c12.norm() < 1e-12) return std::nullopt;
  const Vec2 t = c1 + r1 * c12.normalized();  // where the arcs touch
  const double w1 = turning_angle(s - c1, t - c1, side);
  const double w2 = turning_angle(t - c2, e - c2, -side);
  // Forward S only: each arc turns by less than half a circle (a full angle means no turn).
  if (w1 >= kPi || w2 >= kPi || w1 < kMinTurn || w2 < kMinTurn) return std::nullopt;
  TwoTurnPath out;
  out.path = CurvaturePath(start, {{r1 * w1, side / r1, side / r1}, {r2 * w2, -side / r2, -side / r2}});
  out.first_turn_pieces = 1;
  const Pose2 reached = out.path.end();
  out.lateral_error = (to_vec(reached) - e).dot(left_normal(heading(end.yaw)));
  out.heading_error = normalize_angle(reached.yaw - end.yaw);
  if ((to_vec(reached) - e).norm() > kEndTolerance || std::abs(out.heading_error) > kEndTolerance) {
    return std::nullopt;
  }
  return out;
}

std::optional<TwoTurnPath> solve_two_turn(const Pose2& start, const Polyline& center, const TwoTurnSpec& spec) {
  if (center.size() < 2 || spec.kappa <= 0.0) return std::nullopt;
  const auto start_proj = center.project(to_vec(start));
  double psi = center.yaw_at(start_proj.s);
  std::optional<double> d1;
  for (int iter = 0; iter < kMaxHeadingIterations; ++iter) {
    const auto f = [&](double d) { return evaluate(start, d, psi, center, spec).lateral; };
    const double offset = start_proj.lateral;
    const double towards = offset > 0.0 ? -1.0 : 1.0;  // turn towards the centerline first
    std::optional<double> root;
    const double dpsi = normalize_angle(psi - start.yaw);
    if (std::abs(dpsi) < kParallelStart) {
      // Bracket from the closed form for arcs of the same peak curvature: clothoid turns need a
      // slightly larger angle, so expand until the sign changes.
      const double guess = arc_s_curve_angle(std::abs(offset), 1.0 / spec.kappa, spec.straight).value_or(kPi / 2);
      const double fa = f(0.0);
      double b = std::max(guess * 1.2, 1e-3);
      double fb = f(towards * b);
      for (int k = 0; k < 6 && (fb > 0.0) == (fa > 0.0) && b < kPi / 2; ++k) {
        b = std::min(b * 1.3, kPi / 2);
        fb = f(towards * b);
      }
      if ((fb > 0.0) != (fa > 0.0)) root = refine(f, 0.0, fa, towards * b, fb);
    } else {
      // General start heading: scan d1 over the turns that keep moving forward and keep the root
      // with the least total turning.
      constexpr int kSteps = 24;
      const double range = std::min(kPi, kPi / 2 + std::abs(dpsi));
      double best_turn = 1e9;
      double a = -range;
      double fa = f(a);
      for (int i = 1; i <= kSteps; ++i) {
        const double b = -range + 2.0 * range * i / kSteps;
        const double fb = f(b);
        const double a_prev = a;
        const double fa_prev = fa;
        a = b;
        fa = fb;
        if ((fa_prev > 0.0) == (fb > 0.0)) continue;
        const auto r = refine(f, a_prev, fa_prev, b, fb);
        if (!r || evaluate(start, *r, psi, center, spec).s_end <= start_proj.s) continue;
        const double total = std::abs(*r) + std::abs(normalize_angle(psi - start.yaw - *r));
        if (total < best_turn) {
          best_turn = total;
          root = r;
        }
      }
    }
    if (!root) return std::nullopt;
    d1 = root;
    const Evaluation e = evaluate(start, *d1, psi, center, spec);
    const double psi_new = center.yaw_at(e.s_end);
    const bool settled = std::abs(normalize_angle(psi_new - psi)) < 1e-4;
    psi = psi_new;
    if (settled) break;
  }
  TwoTurnPath out;
  const double d2 = normalize_angle(psi - start.yaw - *d1);
  out.path = CurvaturePath(start, two_turns(*d1, d2, spec, &out.first_turn_pieces));
  const Pose2 end = out.path.end();
  const auto proj = center.project(to_vec(end));
  out.lateral_error = proj.lateral;
  out.heading_error = normalize_angle(end.yaw - center.yaw_at(proj.s));
  // Forward progress only, and the end must really sit on the centerline.
  if (proj.s <= start_proj.s || std::abs(out.lateral_error) > kJoinTolerance ||
      std::abs(out.heading_error) > kHeadingTolerance) {
    return std::nullopt;
  }
  return out;
}

}  // namespace pullout
