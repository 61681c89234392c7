#include "pullout/geometry/angle.hpp"

#include <cmath>

namespace pullout {

double normalize_angle(double angle) {
  // Most angles are already in range or one turn off: avoid fmod for them.
  if (angle >= -kPi && angle < kPi) return angle;
  if (angle >= kPi && angle < 3.0 * kPi) return angle - kTwoPi;
  if (angle < -kPi && angle >= -3.0 * kPi) return angle + kTwoPi;
  double a = std::fmod(angle + kPi, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  return a - kPi;
}

}  // namespace pullout
