// Angles: pi, degree conversions and wrapping. The one place these are spelled (M_PI is POSIX, not
// C++).
#pragma once

namespace pullout {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

// Wraps to [-pi, pi).
double normalize_angle(double angle);

}  // namespace pullout
