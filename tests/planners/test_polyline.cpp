// Polyline: arc-length lookups stay on the line for every input, NaN included (fuzz_request found
// a lane whose arc length overflowed to infinity; 0 * inf = NaN then indexed past the end).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "pullout/geometry/polyline.hpp"

namespace pullout {
namespace {

TEST(Polyline, SegmentAtStaysOnTheLineForEveryArcLength) {
  const Polyline line({Vec2(0.0, 0.0), Vec2(1.0, 0.0), Vec2(3.0, 0.0)});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double s : {-inf, -1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 9.0, inf, nan}) {
    EXPECT_LE(line.segment_at(s), line.size() - 2) << "s = " << s;
  }
  EXPECT_EQ(line.segment_at(0.5), 0u);
  EXPECT_EQ(line.segment_at(2.0), 1u);
  EXPECT_EQ(line.segment_at(nan), 0u);  // the start, like any arc length not above 0
}

TEST(Polyline, PointAtNanIsNotAVertexPastTheEnd) {
  const Polyline line({Vec2(0.0, 0.0), Vec2(1.0, 0.0), Vec2(3.0, 0.0)});
  const Vec2 p = line.point_at(std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(std::isnan(p.x()));  // NaN in, NaN out: never a read past the arrays
}

}  // namespace
}  // namespace pullout
