#include "pullout/execution/execution_tracker.hpp"

#include <gtest/gtest.h>

#include <chrono>

namespace pullout {
namespace {

constexpr std::int64_t kSecond = 1'000'000'000;

PathWithLaneId segment(double x0, double x1, double v) {
  PathWithLaneId s;
  for (double x = x0; (x1 > x0) ? x <= x1 + 1e-9 : x >= x1 - 1e-9; x += (x1 > x0 ? 1.0 : -1.0)) {
    PathPoint p;
    p.pose = {x, 0.0, 0.0};
    p.longitudinal_velocity_mps = v;
    s.points.push_back(p);
  }
  s.points.back().longitudinal_velocity_mps = 0.0;
  return s;
}

// Reverse from x = 10 to 5, then forward to 30 (end pose at 25).
PullOutPath two_segment_path() {
  PullOutPath p;
  p.request_id = 42;
  p.found = true;
  p.partial_paths = {segment(10, 5, -1.0), segment(5, 30, 2.0)};
  p.pairs_terminal_velocity_and_accel = {{0.0, -0.5}, {2.0, 0.5}};
  p.start_pose = {10, 0, 0};
  p.end_pose = {25, 0, 0};
  return p;
}

ExecutionProgress at(double x, double v, double t_s, std::uint64_t request_id = 42) {
  ExecutionProgress p;
  p.request_id = request_id;
  p.stamp_ns = static_cast<std::int64_t>(t_s * kSecond);
  p.pose = {x, 0.0, 0.0};
  p.velocity_mps = v;
  return p;
}

// A sample received when it is stamped: the service's clock runs with the vehicle's.
ExecutionTracker::Update feed(ExecutionTracker& t, const ExecutionProgress& p) {
  return t.on_progress(p, std::chrono::steady_clock::time_point(std::chrono::nanoseconds(p.stamp_ns)));
}

TEST(ExecutionTracker, AdvancesOnlyAfterStoppingNearTheSegmentEnd) {
  ExecutionTracker t{ExecutionParameters{}};
  t.start(two_segment_path());
  EXPECT_FALSE(feed(t, at(8.0, -1.0, 0.0)).changed);
  // Arrived near the end of the reverse leg but still moving.
  EXPECT_FALSE(feed(t, at(5.3, -0.5, 1.0)).changed);
  // Stopped, but not yet for th_stopped_time (1 s).
  EXPECT_FALSE(feed(t, at(5.2, 0.0, 2.0)).changed);
  EXPECT_FALSE(feed(t, at(5.2, 0.0, 2.5)).changed);
  const auto u = feed(t, at(5.2, 0.0, 3.0));
  EXPECT_TRUE(u.changed);
  EXPECT_EQ(u.current_path_idx, 1u);
  EXPECT_FALSE(u.completed);
}

TEST(ExecutionTracker, StoppingFarFromTheEndDoesNotAdvance) {
  ExecutionTracker t{ExecutionParameters{}};
  t.start(two_segment_path());
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(feed(t, at(7.0, 0.0, i)).changed);
  EXPECT_EQ(t.current_path_idx(), 0u);
}

TEST(ExecutionTracker, CompletesWhenPassingTheEndPoseOfTheLastSegment) {
  ExecutionTracker t{ExecutionParameters{}};
  t.start(two_segment_path());
  feed(t, at(5.0, 0.0, 0.0));
  ASSERT_TRUE(feed(t, at(5.0, 0.0, 1.5)).changed);
  EXPECT_FALSE(feed(t, at(20.0, 2.0, 5.0)).changed);
  EXPECT_FALSE(feed(t, at(24.9, 2.0, 6.0)).changed);
  const auto u = feed(t, at(25.1, 2.0, 6.1));
  EXPECT_TRUE(u.changed);
  EXPECT_TRUE(u.completed);
  EXPECT_EQ(u.current_path_idx, 1u);
  // Later samples change nothing.
  EXPECT_FALSE(feed(t, at(28.0, 2.0, 7.0)).changed);
}

TEST(ExecutionTracker, IgnoresOtherRequestsAndClampsTheIndex) {
  ExecutionTracker t{ExecutionParameters{}};
  PullOutPath single = two_segment_path();
  single.partial_paths.erase(single.partial_paths.begin());
  single.pairs_terminal_velocity_and_accel.erase(single.pairs_terminal_velocity_and_accel.begin());
  t.start(single);
  // Stopped at the end of the only segment for long: the index stays at the last segment.
  feed(t, at(24.0, 0.0, 0.0));
  feed(t, at(24.0, 0.0, 3.0));
  EXPECT_EQ(t.current_path_idx(), 0u);
  EXPECT_FALSE(t.completed());
  EXPECT_FALSE(feed(t, at(26.0, 1.0, 4.0, /*request_id=*/7)).changed);
  EXPECT_TRUE(feed(t, at(26.0, 1.0, 4.0)).completed);
}

TEST(ExecutionTracker, ReverseLastSegmentCompletesBehindTheEndPose) {
  ExecutionTracker t{ExecutionParameters{}};
  PullOutPath p;
  p.request_id = 1;
  p.partial_paths = {segment(10, 2, -1.0)};
  p.end_pose = {4, 0, 0};
  t.start(p);
  EXPECT_FALSE(feed(t, at(6.0, -1.0, 0.0, 1)).changed);
  EXPECT_TRUE(feed(t, at(3.9, -1.0, 1.0, 1)).completed);
}

TEST(ExecutionTracker, StandstillIsNotCreditedBeyondTheReceivingClock) {
  ExecutionTracker t{ExecutionParameters{}};
  t.start(two_segment_path());
  const auto received = std::chrono::steady_clock::time_point(std::chrono::seconds(100));
  // Stamps claim 3 s of standstill at the end of the reverse leg; 50 ms passed where it was received.
  EXPECT_FALSE(t.on_progress(at(5.2, 0.0, 1.0), received).changed);
  EXPECT_FALSE(t.on_progress(at(5.2, 0.0, 4.0), received + std::chrono::milliseconds(50)).changed);
  EXPECT_EQ(t.current_path_idx(), 0u);
  // 1 s later on both clocks (th_stopped_time): done.
  EXPECT_TRUE(t.on_progress(at(5.2, 0.0, 5.0), received + std::chrono::milliseconds(1050)).changed);
  EXPECT_EQ(t.current_path_idx(), 1u);
}

}  // namespace
}  // namespace pullout
