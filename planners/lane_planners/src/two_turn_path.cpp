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

}  // namespace

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
