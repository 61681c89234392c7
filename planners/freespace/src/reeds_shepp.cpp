// Reeds-Shepp families, following the section numbers of Reeds & Shepp (1990).
//
// Every formula works in the frame of the start pose scaled by the turning radius: the goal is
// (x, y, phi), arcs have unit radius and their lengths are angles. A family's base formula solves
// one word (e.g. L+ R- L); the symmetries give the rest:
//   time flip (-x, y, -phi): the same word driven in the other direction (lengths negated),
//   reflection (x, -y, -phi): left and right swapped,
//   both (-x, -y, phi),
// and for the families that are not symmetric in time, the "backwards" goal
// (x cos phi + y sin phi, x sin phi - y cos phi, phi) solves the word read in reverse order.
#include "pullout/freespace/reeds_shepp.hpp"
#include "pullout/geometry/angle.hpp"

#include <cmath>
#include <limits>

namespace pullout {

namespace {

constexpr double kHalfPi = kPi / 2.0;
constexpr double kTolerance = 1e-10;

using Kind = ReedsSheppSegment::Kind;
// The paper's letters, so that the word tables below read as in Reeds & Shepp (1990).
constexpr Kind L = Kind::kLeft;      // NOLINT(readability-identifier-naming)
constexpr Kind S = Kind::kStraight;  // NOLINT(readability-identifier-naming)
constexpr Kind R = Kind::kRight;     // NOLINT(readability-identifier-naming)

void polar(double x, double y, double& r, double& theta) {
  r = std::hypot(x, y);
  theta = std::atan2(y, x);
}

// A solution of a base formula: up to five lengths (unit radius, signed).
struct Lengths {
  std::array<double, 5> v{};
  int n{0};
};

// ---- base formulas (section 8) ----

// 8.1  L+ S+ L+
bool lp_sp_lp(double x, double y, double phi, Lengths& out) {
  double u = 0.0;
  double t = 0.0;
  polar(x - std::sin(phi), y - 1.0 + std::cos(phi), u, t);
  if (t < -kTolerance) return false;
  const double v = normalize_angle(phi - t);
  if (v < -kTolerance) return false;
  out = {{t, u, v}, 3};
  return true;
}

// 8.2  L+ S+ R+
bool lp_sp_rp(double x, double y, double phi, Lengths& out) {
  double u1 = 0.0;
  double t1 = 0.0;
  polar(x + std::sin(phi), y - 1.0 - std::cos(phi), u1, t1);
  const double u1_sq = u1 * u1;
  if (u1_sq < 4.0) return false;
  const double u = std::sqrt(u1_sq - 4.0);
  const double t = normalize_angle(t1 + std::atan2(2.0, u));
  const double v = normalize_angle(t - phi);
  if (t < -kTolerance || v < -kTolerance) return false;
  out = {{t, u, v}, 3};
  return true;
}

// 8.3  L+ R- L
bool lp_rm_l(double x, double y, double phi, Lengths& out) {
  const double xi = x - std::sin(phi);
  const double eta = y - 1.0 + std::cos(phi);
  double u1 = 0.0;
  double theta = 0.0;
  polar(xi, eta, u1, theta);
  if (u1 > 4.0) return false;
  const double u = -2.0 * std::asin(0.25 * u1);
  const double t = normalize_angle(theta + 0.5 * u + kPi);
  const double v = normalize_angle(phi - t + u);
  if (t < -kTolerance || u > kTolerance) return false;
  out = {{t, u, v}, 3};
  return true;
}

// The two headings of the CCCC words (section 8, formulas 8.7 and 8.8).
void tau_omega(double u, double v, double xi, double eta, double phi, double& tau, double& omega) {
  const double delta = normalize_angle(u - v);
  const double a = std::sin(u) - std::sin(delta);
  const double b = std::cos(u) - std::cos(delta) - 1.0;
  const double t1 = std::atan2(eta * a - xi * b, xi * a + eta * b);
  const double t2 = 2.0 * (std::cos(delta) - std::cos(v) - std::cos(u)) + 3.0;
  tau = t2 < 0.0 ? normalize_angle(t1 + kPi) : normalize_angle(t1);
  omega = normalize_angle(tau - u + v - phi);
}

// 8.7  L+ R+u | L-u R-
bool lp_rup_lum_rm(double x, double y, double phi, Lengths& out) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  const double rho = 0.25 * (2.0 + std::hypot(xi, eta));
  if (rho > 1.0) return false;
  const double u = std::acos(rho);
  double t = 0.0;
  double v = 0.0;
  tau_omega(u, -u, xi, eta, phi, t, v);
  if (t < -kTolerance || v > kTolerance) return false;
  out = {{t, u, -u, v}, 4};
  return true;
}

// 8.8  L+ R-u L-u R+
bool lp_rum_lum_rp(double x, double y, double phi, Lengths& out) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  const double rho = (20.0 - xi * xi - eta * eta) / 16.0;
  if (rho < 0.0 || rho > 1.0) return false;
  const double u = -std::acos(rho);
  if (u < -kHalfPi) return false;
  double t = 0.0;
  double v = 0.0;
  tau_omega(u, u, xi, eta, phi, t, v);
  if (t < -kTolerance || v < -kTolerance) return false;
  out = {{t, u, u, v}, 4};
  return true;
}

// 8.9  L+ R-pi/2 S- L-
bool lp_rm_sm_lm(double x, double y, double phi, Lengths& out) {
  // Driving the word from the origin gives x - sin(phi) = (2 - u) sin t - 2 cos t and
  // y - 1 + cos(phi) = -(2 - u) cos t - 2 sin t: a rotation by t - pi/2 of (2 - u, -2).
  const double xi = x - std::sin(phi);
  const double eta = y - 1.0 + std::cos(phi);
  double rho = 0.0;
  double theta = 0.0;
  polar(xi, eta, rho, theta);
  if (rho < 2.0) return false;
  const double r = std::sqrt(rho * rho - 4.0);
  const double u = 2.0 - r;
  const double t = normalize_angle(theta + std::atan2(r, -2.0));
  const double v = normalize_angle(phi - kHalfPi - t);
  if (t < -kTolerance || u > kTolerance || v > kTolerance) return false;
  out = {{t, -kHalfPi, u, v}, 4};
  return true;
}

// 8.10  L+ R-pi/2 S- R-
bool lp_rm_sm_rm(double x, double y, double phi, Lengths& out) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  double rho = 0.0;
  double theta = 0.0;
  polar(-eta, xi, rho, theta);
  if (rho < 2.0) return false;
  const double t = theta;
  const double u = 2.0 - rho;
  const double v = normalize_angle(t + kHalfPi - phi);
  if (t < -kTolerance || u > kTolerance || v > kTolerance) return false;
  out = {{t, -kHalfPi, u, v}, 4};
  return true;
}

// 8.11  L+ R-pi/2 S- L-pi/2 R+
bool lp_rm_s_lm_rp(double x, double y, double phi, Lengths& out) {
  const double xi = x + std::sin(phi);
  const double eta = y - 1.0 - std::cos(phi);
  double rho = 0.0;
  double theta = 0.0;
  polar(xi, eta, rho, theta);
  if (rho < 2.0) return false;
  const double u = 4.0 - std::sqrt(rho * rho - 4.0);
  if (u > kTolerance) return false;
  const double t = normalize_angle(std::atan2((4.0 - u) * xi - 2.0 * eta, -2.0 * xi + (u - 4.0) * eta));
  const double v = normalize_angle(t - phi);
  if (t < -kTolerance || v < -kTolerance) return false;
  out = {{t, -kHalfPi, u, -kHalfPi, v}, 5};
  return true;
}

using Formula = bool (*)(double, double, double, Lengths&);

// Visits every solution: visit(kinds, lengths, n) with unit-radius lengths.
template <typename Visit>
class Enumerator {
 public:
  explicit Enumerator(Visit& visit) : visit_(visit) {}

  void all(double x, double y, double phi) {
    // CSC
    symmetric(lp_sp_lp, {L, S, L}, x, y, phi);
    symmetric(lp_sp_rp, {L, S, R}, x, y, phi);
    // CCC, and read backwards
    symmetric(lp_rm_l, {L, R, L}, x, y, phi);
    const double xb = x * std::cos(phi) + y * std::sin(phi);
    const double yb = x * std::sin(phi) - y * std::cos(phi);
    symmetric(lp_rm_l, {L, R, L}, xb, yb, phi, true);
    // CCCC
    symmetric(lp_rup_lum_rm, {L, R, L, R}, x, y, phi);
    symmetric(lp_rum_lum_rp, {L, R, L, R}, x, y, phi);
    // CCSC, and read backwards (CSCC)
    symmetric(lp_rm_sm_lm, {L, R, S, L}, x, y, phi);
    symmetric(lp_rm_sm_rm, {L, R, S, R}, x, y, phi);
    symmetric(lp_rm_sm_lm, {L, R, S, L}, xb, yb, phi, true);
    symmetric(lp_rm_sm_rm, {L, R, S, R}, xb, yb, phi, true);
    // CCSCC
    symmetric(lp_rm_s_lm_rp, {L, R, S, L, R}, x, y, phi);
  }

 private:
  // The base word and its time-flipped, reflected and doubly transformed variants.
  void symmetric(Formula f, std::initializer_list<Kind> word, double x, double y, double phi, bool reversed = false) {
    std::array<Kind, 5> kinds{};
    int n = 0;
    for (Kind k : word) kinds[static_cast<std::size_t>(n++)] = k;
    Lengths len;
    if (f(x, y, phi, len)) emit(kinds, len, false, false, reversed);
    if (f(-x, y, -phi, len)) emit(kinds, len, true, false, reversed);
    if (f(x, -y, -phi, len)) emit(kinds, len, false, true, reversed);
    if (f(-x, -y, phi, len)) emit(kinds, len, true, true, reversed);
  }

  void emit(std::array<Kind, 5> kinds, const Lengths& len, bool flip_time, bool reflect, bool reversed) {
    std::array<double, 5> lengths{};
    for (int i = 0; i < len.n; ++i) {
      const auto k = static_cast<std::size_t>(reversed ? len.n - 1 - i : i);
      lengths[static_cast<std::size_t>(i)] = flip_time ? -len.v[k] : len.v[k];
    }
    if (reversed) {
      for (int i = 0; i < len.n / 2; ++i) std::swap(kinds[static_cast<std::size_t>(i)], kinds[len.n - 1 - i]);
    }
    if (reflect) {
      for (int i = 0; i < len.n; ++i)
        kinds[static_cast<std::size_t>(i)] = static_cast<Kind>(-static_cast<int>(kinds[i]));
    }
    visit_(kinds, lengths, len.n);
  }

  Visit& visit_;
};

// The goal in the start frame, scaled by 1 / radius.
void relative(const Pose2& from, const Pose2& to, double radius, double& x, double& y, double& phi) {
  const double dx = to.x - from.x;
  const double dy = to.y - from.y;
  const double c = std::cos(from.yaw);
  const double s = std::sin(from.yaw);
  x = (c * dx + s * dy) / radius;
  y = (-s * dx + c * dy) / radius;
  phi = normalize_angle(to.yaw - from.yaw);
}

}  // namespace

int ReedsSheppPath::cusps() const {
  int n = 0;
  double last = 0.0;
  for (int i = 0; i < count; ++i) {
    const double l = segments[static_cast<std::size_t>(i)].length;
    if (std::abs(l) < 1e-9) continue;
    if (last != 0.0 && (l > 0.0) != (last > 0.0)) ++n;
    last = l;
  }
  return n;
}

double ReedsSheppPath::reverse_length() const {
  double r = 0.0;
  for (int i = 0; i < count; ++i) r += std::max(0.0, -segments[static_cast<std::size_t>(i)].length);
  return r;
}

double weighted_cost(const ReedsSheppPath& path, const ReedsSheppWeights& w, int initial_direction) {
  double cost = 0.0;
  int last = initial_direction;
  for (int i = 0; i < path.count; ++i) {
    const ReedsSheppSegment& seg = path.segments[static_cast<std::size_t>(i)];
    if (std::abs(seg.length) < 1e-9) continue;
    const int dir = seg.length > 0.0 ? 1 : -1;
    double c = std::abs(seg.length);
    if (seg.kind != Kind::kStraight) c *= 1.0 + w.curve_weight;
    if (dir < 0) c *= 1.0 + w.reverse_weight;
    if (last != 0 && last != dir) c += w.direction_change_weight;
    last = dir;
    cost += c;
  }
  return cost;
}

ReedsShepp::ReedsShepp(double turning_radius) : radius_(turning_radius) {}

std::vector<ReedsSheppPath> ReedsShepp::all(const Pose2& from, const Pose2& to) const {
  double x = 0.0;
  double y = 0.0;
  double phi = 0.0;
  relative(from, to, radius_, x, y, phi);
  std::vector<ReedsSheppPath> out;
  auto visit = [&](const std::array<Kind, 5>& kinds, const std::array<double, 5>& lengths, int n) {
    ReedsSheppPath p;
    p.count = n;
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      p.segments[k] = {kinds[k], lengths[k] * radius_};
      p.length += std::abs(lengths[k]) * radius_;
    }
    out.push_back(p);
  };
  Enumerator<decltype(visit)>(visit).all(x, y, phi);
  return out;
}

ReedsSheppPath ReedsShepp::shortest(const Pose2& from, const Pose2& to) const {
  double x = 0.0;
  double y = 0.0;
  double phi = 0.0;
  relative(from, to, radius_, x, y, phi);
  ReedsSheppPath best;
  double best_len = std::numeric_limits<double>::infinity();
  auto visit = [&](const std::array<Kind, 5>& kinds, const std::array<double, 5>& lengths, int n) {
    double len = 0.0;
    for (int i = 0; i < n; ++i) len += std::abs(lengths[static_cast<std::size_t>(i)]);
    if (len >= best_len) return;
    best_len = len;
    best.count = n;
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      best.segments[k] = {kinds[k], lengths[k] * radius_};
    }
  };
  Enumerator<decltype(visit)>(visit).all(x, y, phi);
  best.length = best_len * radius_;
  return best;
}

double ReedsShepp::distance(const Pose2& from, const Pose2& to) const {
  double x = 0.0;
  double y = 0.0;
  double phi = 0.0;
  relative(from, to, radius_, x, y, phi);
  double best = std::numeric_limits<double>::infinity();
  auto visit = [&](const std::array<Kind, 5>&, const std::array<double, 5>& lengths, int n) {
    double len = 0.0;
    for (int i = 0; i < n; ++i) len += std::abs(lengths[static_cast<std::size_t>(i)]);
    best = std::min(best, len);
  };
  Enumerator<decltype(visit)>(visit).all(x, y, phi);
  return best * radius_;
}

Pose2 ReedsShepp::interpolate(const Pose2& from, const ReedsSheppPath& path, double s, int* direction) const {
  Pose2 p = from;
  double remaining = std::max(0.0, s);
  int dir = 1;
  for (int i = 0; i < path.count; ++i) {
    const ReedsSheppSegment& seg = path.segments[static_cast<std::size_t>(i)];
    const double len = std::abs(seg.length);
    if (len < 1e-12) continue;
    dir = seg.length > 0.0 ? 1 : -1;
    const double d = std::min(remaining, len) * dir;  // signed travel on this segment [m]
    if (seg.kind == Kind::kStraight) {
      p.x += d * std::cos(p.yaw);
      p.y += d * std::sin(p.yaw);
    } else {
      // Arc about the centre on the turning side: heading changes by d / r (left) or -d / r.
      const double k = seg.kind == Kind::kLeft ? 1.0 : -1.0;
      const double dyaw = k * d / radius_;
      p.x += k * radius_ * (std::sin(p.yaw + dyaw) - std::sin(p.yaw));
      p.y += k * radius_ * (-std::cos(p.yaw + dyaw) + std::cos(p.yaw));
      p.yaw += dyaw;
    }
    remaining -= len;
    if (remaining <= 0.0) break;
  }
  p.yaw = normalize_angle(p.yaw);
  if (direction != nullptr) *direction = dir;
  return p;
}

}  // namespace pullout
