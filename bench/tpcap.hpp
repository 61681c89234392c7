// Loader for the TPCAP benchmark cases (Trajectory Planning Competition for Automated Parking,
// IEEE ITSC 2022): one comma-separated line per file, as ../shared/benchmarks/tpcap/README.md
// describes (1-based): x0, y0, yaw0, xf, yf, yawf (rear-axle poses), N, N vertex counts, then
// the vertices (x, y) obstacle by obstacle. Cases 13-15 lie ~5e9 m from the origin: every
// coordinate is re-centred on the start pose in double before anything else sees it (the
// difference keeps the ulp of 5e9, ~1e-6 m). Yaws are normalised to (-pi, pi].
#pragma once

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pullout/geometry/angle.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/model/types.hpp"

namespace pullout::bench {

struct TpcapCase {
  Pose2 start;                     // re-centred: the start's rear axle is (0, 0)
  Pose2 goal;                      // same frame
  std::vector<Polygon> obstacles;  // same frame, not closed, any orientation, may be non-convex
  double offset_x{0.0};            // [m] what was subtracted (the file's start x, y)
  double offset_y{0.0};
};

// The organisers' vehicle (RunMe.m): rear axle to front 3.76 m, to rear 0.929 m, width 1.942 m,
// wheelbase 2.8 m; max steering 0.75 rad is the participants' demo value (not official).
constexpr double kTpcapFront = 3.76;
constexpr double kTpcapRear = 0.929;
constexpr double kTpcapHalfWidth = 0.971;
constexpr double kTpcapWheelbase = 2.8;
constexpr double kTpcapMaxSteer = 0.75;

// Reads a case file; false with `error` naming the problem (field and position) otherwise.
inline bool load_tpcap(const std::string& path, TpcapCase& out, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = path + ": cannot open";
    return false;
  }
  std::vector<double> v;
  std::string token;
  std::stringstream all;
  all << in.rdbuf();
  while (std::getline(all, token, ',')) {
    std::size_t used = 0;
    try {
      v.push_back(std::stod(token, &used));
    } catch (const std::exception&) {
      error = path + ": value " + std::to_string(v.size() + 1) + " is not a number";
      return false;
    }
    if (!std::isfinite(v.back())) {
      error = path + ": value " + std::to_string(v.size()) + " is not finite";
      return false;
    }
  }
  if (v.size() < 7) {
    error = path + ": fewer than 7 values (start, goal, obstacle count)";
    return false;
  }
  const double n = v[6];
  if (n < 0 || n != std::floor(n) || 7 + n > static_cast<double>(v.size())) {
    error = path + ": obstacle count (value 7) invalid";
    return false;
  }
  const auto count = static_cast<std::size_t>(n);
  std::size_t at = 7 + count;
  out = {};
  out.offset_x = v[0];
  out.offset_y = v[1];
  out.start = {0.0, 0.0, normalize_angle(v[2])};
  out.goal = {v[3] - v[0], v[4] - v[1], normalize_angle(v[5])};
  for (std::size_t i = 0; i < count; ++i) {
    const double k = v[7 + i];
    if (k < 1 || k != std::floor(k) || at + 2 * k > static_cast<double>(v.size())) {
      error = path + ": vertex count of obstacle " + std::to_string(i + 1) + " invalid";
      return false;
    }
    Polygon poly;
    for (std::size_t j = 0; j < static_cast<std::size_t>(k); ++j, at += 2) {
      poly.push_back({v[at] - v[0], v[at + 1] - v[1]});
    }
    out.obstacles.push_back(std::move(poly));
  }
  if (at != v.size()) {
    error = path + ": " + std::to_string(v.size() - at) + " values after the last obstacle";
    return false;
  }
  return true;
}

}  // namespace pullout::bench
