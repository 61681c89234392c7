#include "pullout/geometry/curvature_path.hpp"

#include <algorithm>
#include <cmath>

namespace pullout {

namespace {
constexpr int kSimpsonIntervals = 16;  // even
constexpr double kStraightCurvature = 1e-9;
}  // namespace

Pose2 CurvaturePath::advance(const Pose2& from, const CurvaturePiece& piece, double s) {
  const double dk = piece.length > 0.0 ? (piece.k1 - piece.k0) / piece.length : 0.0;
  const double theta = from.yaw + piece.k0 * s + 0.5 * dk * s * s;
  if (std::abs(dk) < 1e-12) {
    if (std::abs(piece.k0) < kStraightCurvature) {
      return {from.x + s * std::cos(from.yaw), from.y + s * std::sin(from.yaw), normalize_angle(theta)};
    }
    // Arc: exact chord.
    const double r = 1.0 / piece.k0;
    return {from.x + r * (std::sin(theta) - std::sin(from.yaw)), from.y - r * (std::cos(theta) - std::cos(from.yaw)),
            normalize_angle(theta)};
  }
  // Clothoid: Simpson's rule on cos/sin of the quadratic heading.
  const double h = s / kSimpsonIntervals;
  double sx = 0.0;
  double sy = 0.0;
  for (int i = 0; i <= kSimpsonIntervals; ++i) {
    const double u = i * h;
    const double th = from.yaw + piece.k0 * u + 0.5 * dk * u * u;
    const double w = (i == 0 || i == kSimpsonIntervals) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    sx += w * std::cos(th);
    sy += w * std::sin(th);
  }
  return {from.x + sx * h / 3.0, from.y + sy * h / 3.0, normalize_angle(theta)};
}

CurvaturePath::CurvaturePath(const Pose2& start, std::vector<CurvaturePiece> pieces)
    : start_(start), pieces_(std::move(pieces)) {
  Pose2 p = start_;
  junctions_.reserve(pieces_.size());
  for (const CurvaturePiece& piece : pieces_) {
    p = advance(p, piece, piece.length);
    junctions_.push_back(p);
  }
}

double CurvaturePath::length() const {
  double len = 0.0;
  for (const auto& p : pieces_) len += p.length;
  return len;
}

Pose2 CurvaturePath::end() const { return junctions_.empty() ? start_ : junctions_.back(); }

Pose2 CurvaturePath::piece_end(std::size_t i) const { return junctions_.at(i); }

double CurvaturePath::max_abs_curvature() const {
  double k = 0.0;
  for (const auto& p : pieces_) k = std::max({k, std::abs(p.k0), std::abs(p.k1)});
  return k;
}

std::vector<Pose2> CurvaturePath::sample(double interval) const {
  std::vector<std::size_t> unused;
  return sample(interval, unused);
}

std::vector<Pose2> CurvaturePath::sample(double interval, std::vector<std::size_t>& junction_indices) const {
  std::vector<Pose2> out{start_};
  junction_indices.clear();
  Pose2 from = start_;
  for (std::size_t i = 0; i < pieces_.size(); ++i) {
    const CurvaturePiece& piece = pieces_[i];
    const int steps = std::max(1, static_cast<int>(std::ceil(piece.length / interval - 1e-9)));
    for (int k = 1; k < steps; ++k) out.push_back(advance(from, piece, piece.length * k / steps));
    out.push_back(junctions_[i]);
    junction_indices.push_back(out.size() - 1);
    from = junctions_[i];
  }
  return out;
}

void append_turn(std::vector<CurvaturePiece>& pieces, double dtheta, double kappa, double sharpness) {
  const double mag = std::abs(dtheta);
  if (mag < 1e-12) return;
  const double sign = dtheta > 0.0 ? 1.0 : -1.0;
  if (sharpness <= 0.0) {
    pieces.push_back({mag / kappa, sign * kappa, sign * kappa});
    return;
  }
  const double l_clothoid = kappa / sharpness;
  // Each clothoid from 0 to kappa turns by kappa * L / 2.
  if (mag >= kappa * l_clothoid) {
    pieces.push_back({l_clothoid, 0.0, sign * kappa});
    const double arc = (mag - kappa * l_clothoid) / kappa;
    if (arc > 1e-9) pieces.push_back({arc, sign * kappa, sign * kappa});
    pieces.push_back({l_clothoid, sign * kappa, 0.0});
  } else {
    // Two clothoids meeting at a lower peak k: heading change k^2 / sharpness.
    const double peak = std::sqrt(mag * sharpness);
    const double len = peak / sharpness;
    pieces.push_back({len, 0.0, sign * peak});
    pieces.push_back({len, sign * peak, 0.0});
  }
}

}  // namespace pullout
