// Paths made of pieces whose curvature varies linearly with arc length: straight lines (k = 0),
// circular arcs (k constant) and clothoids (k from k0 to k1). Integrated exactly for lines and
// arcs and with composite Simpson quadrature for clothoids (16 intervals: error below 1e-6 m for
// a 3 m clothoid turning by 0.45 rad, tests/planners/test_two_turn_path.cpp).
#pragma once

#include <vector>

#include "pullout/geometry/polyline.hpp"

namespace pullout {

struct CurvaturePiece {
  double length{0.0};  // [m] > 0
  double k0{0.0};      // [1/m] curvature at the start, left turn positive
  double k1{0.0};      // [1/m] curvature at the end
};

class CurvaturePath {
 public:
  CurvaturePath() = default;
  CurvaturePath(const Pose2& start, std::vector<CurvaturePiece> pieces);

  const Pose2& start() const { return start_; }
  const std::vector<CurvaturePiece>& pieces() const { return pieces_; }
  double length() const;
  Pose2 end() const;
  // Pose at the end of piece i.
  Pose2 piece_end(std::size_t i) const;
  // Largest |curvature| over the path.
  double max_abs_curvature() const;

  // Poses at most `interval` apart along the path, including the start, every piece junction and
  // the end.
  std::vector<Pose2> sample(double interval) const;
  // The same samples, with the index of the piece each sample ends (a junction), for splitting.
  std::vector<Pose2> sample(double interval, std::vector<std::size_t>& junction_indices) const;

  // Pose reached from `from` after distance s along one piece (0 <= s <= piece.length).
  static Pose2 advance(const Pose2& from, const CurvaturePiece& piece, double s);

 private:
  Pose2 start_;
  std::vector<CurvaturePiece> pieces_;
  std::vector<Pose2> junctions_;  // pose at the end of each piece
};

// Appends one turn of signed heading change `dtheta` [rad] with peak curvature `kappa` [1/m] (> 0)
// and curvature rate `sharpness` [1/m^2]: clothoid - arc - clothoid, or two clothoids with a
// lower peak when the turn is too small to reach kappa. sharpness <= 0 means arcs only.
void append_turn(std::vector<CurvaturePiece>& pieces, double dtheta, double kappa, double sharpness);

}  // namespace pullout
