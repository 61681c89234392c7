// A TPCAP case (bench/tpcap.hpp) as a scenario file for `pullout plan` and the tests: a pure
// freespace problem (a grid, no lanes) in the case's re-centred frame (the start's rear axle at
// the origin: cases 13-15 lie ~5e9 m out), the map the organisers' demo draws (start and goal box
// +-15 m) as an empty grid, every obstacle polygon as it is as a static object (objects are
// checked against their true polygons, as bench_freespace --tpcap does; a grid's own obstacles
// are cells, which close case 7's slot), the organisers' vehicle, no shape margin, full steer,
// and a deadline as long as the search's budget.
//
//   build/bench/tpcap_to_scenario ../shared/benchmarks/tpcap/Case1.csv case1.yaml [--resolution 0.1]
//
// The cases are read at run time and never committed (their licence is the organisers').
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "pullout/geometry/angle.hpp"
#include "tpcap.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: tpcap_to_scenario CASE.csv OUT.yaml [--resolution M]\n");
    return 2;
  }
  double resolution = 0.1;
  for (int i = 3; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--resolution") == 0) {
      resolution = std::atof(argv[i + 1]);
    } else {
      std::fprintf(stderr, "unknown argument: %s\n", argv[i]);
      return 2;
    }
  }
  pullout::bench::TpcapCase c;
  std::string error;
  if (!pullout::bench::load_tpcap(argv[1], c, error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  constexpr double kBox = 15.0;  // [m] as bench_freespace --tpcap
  const double x0 = std::min(c.start.x, c.goal.x) - kBox;
  const double y0 = std::min(c.start.y, c.goal.y) - kBox;
  const double w = std::max(c.start.x, c.goal.x) + kBox - x0;
  const double h = std::max(c.start.y, c.goal.y) + kBox - y0;
  std::ofstream out(argv[2]);
  if (!out) {
    std::fprintf(stderr, "%s: cannot write\n", argv[2]);
    return 1;
  }
  out.precision(12);
  out << "# TPCAP " << argv[1] << ", re-centred on the start (subtracted: x " << c.offset_x << ", y " << c.offset_y
      << ").\n# Written by bench/tpcap_to_scenario.\n";
  out << "description: \"TPCAP " << argv[1] << "\"\nvehicle_id: tpcap\n";
  using namespace pullout::bench;
  out << "vehicle: {wheel_base: " << kTpcapWheelbase << ", wheel_tread: " << 2.0 * kTpcapHalfWidth
      << ", front_overhang: " << kTpcapFront - kTpcapWheelbase << ", rear_overhang: " << kTpcapRear
      << ", left_overhang: 0.0, right_overhang: 0.0, max_steer_angle: " << kTpcapMaxSteer << "}\n";
  out << "grid:\n  resolution: " << resolution << "\n  origin: {x: " << x0 << ", y: " << y0
      << ", yaw_deg: 0.0}\n  size: [" << w << ", " << h << "]\n";
  out << "objects:  # the obstacles, at rest, their polygons in the map frame\n";
  for (std::size_t k = 0; k < c.obstacles.size(); ++k) {
    const auto& poly = c.obstacles[k];
    out << "  - {id: " << k + 1 << ", class: unknown, x: 0.0, y: 0.0, yaw: 0.0, velocity: 0.0, polygon: [";
    for (std::size_t i = 0; i < poly.size(); ++i)
      out << (i ? ", " : "") << "[" << poly[i].x() << ", " << poly[i].y() << "]";
    out << "]}\n";
  }
  out << "start: {x: " << c.start.x << ", y: " << c.start.y << ", yaw_deg: " << c.start.yaw * pullout::kRadToDeg
      << "}\n";
  out << "goal: {x: " << c.goal.x << ", y: " << c.goal.y << ", yaw_deg: " << c.goal.yaw * pullout::kRadToDeg << "}\n";
  // The budget of bench_freespace --tpcap; the request's deadline (the most a request may ask
  // for) would otherwise cut it to the service's default.
  out << "planner:\n  freespace_planner:\n    vehicle_shape_margin: 0.0\n    max_turning_ratio: 1.0\n"
         "    time_limit: 10000.0\n    costmap_configs: {resolution: "
      << resolution << "}\ndeadline_ms: 10000\n";
  return out ? 0 : 1;
}
