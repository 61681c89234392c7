// Reeds-Shepp curves: the shortest paths between two poses for a car that drives forwards and
// backwards with a minimum turning radius.
//
// J. A. Reeds and L. A. Shepp, "Optimal paths for a car that goes both forwards and backwards",
// Pacific Journal of Mathematics 145(2), 1990. The paper shows that a shortest path is one of 48
// words of at most five segments (arcs C of the minimum radius, straight lines S, and cusps |),
// in the families CSC, CCC, CCCC, CCSC and CCSCC, and gives each family's closed-form solution
// (its section 8); the other words follow from those by the time-flip and reflection symmetries.
// This implementation enumerates every family and keeps the shortest.
//
// Units: poses in the map frame ([m], [rad]); segment lengths signed, in metres of rear-axle
// travel (negative = reverse). Failure modes: none; a path always exists (and has length 0 when
// the poses coincide).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pullout/model/types.hpp"

namespace pullout {

struct ReedsSheppSegment {
  enum class Kind : std::int8_t { kRight = -1, kStraight = 0, kLeft = 1 };
  Kind kind{Kind::kStraight};
  double length{0.0};  // [m] signed: negative when driven in reverse
};

struct ReedsSheppPath {
  std::array<ReedsSheppSegment, 5> segments{};
  int count{0};
  double length{0.0};  // [m] sum of |segment lengths|

  // Number of changes of driving direction (cusps) along the path.
  int cusps() const;
  // Length [m] driven in reverse.
  double reverse_length() const;
};

// Weights of a path cost: each segment costs |length| x (1 + curve_weight if it is an arc) x
// (1 + reverse_weight if it is driven in reverse); each change of direction adds
// direction_change_weight [m]. All zero: the cost is the length.
struct ReedsSheppWeights {
  double curve_weight{0.0};
  double reverse_weight{0.0};
  double direction_change_weight{0.0};
};

// The weighted cost of `path`; a first segment whose direction differs from `initial_direction`
// (+1 / -1; 0 = none) counts as a change of direction too.
double weighted_cost(const ReedsSheppPath& path, const ReedsSheppWeights& weights, int initial_direction = 0);

class ReedsShepp {
 public:
  // turning_radius > 0 [m]: the radius of every arc.
  explicit ReedsShepp(double turning_radius);

  double turning_radius() const { return radius_; }

  // The shortest path from `from` to `to`.
  ReedsSheppPath shortest(const Pose2& from, const Pose2& to) const;
  // Its length [m]; the same as shortest().length without building the path.
  double distance(const Pose2& from, const Pose2& to) const;
  // Every word that solves the problem (at most one per word), in no particular order.
  std::vector<ReedsSheppPath> all(const Pose2& from, const Pose2& to) const;

  // The pose after driving `s` metres (0 <= s <= path.length) along `path` from `from`, and the
  // direction of travel there (+1 forward, -1 reverse).
  Pose2 interpolate(const Pose2& from, const ReedsSheppPath& path, double s, int* direction = nullptr) const;

 private:
  double radius_;
};

}  // namespace pullout
