// Execution through several segments over DDS: the real service follows a simulated vehicle
// through reverse, arc 1 and arc 2 of a tight parallel spot (tests/scenarios/
// parallel_spot_reverse.yaml), and through reverse + shift (car_close_ahead.yaml). Every
// current_path_idx change and the completion are checked on the received statuses.
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "integration_support.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

class MultiSegmentExecution : public ServiceTest {
 protected:
  // Drives the vehicle along every segment of `path`: one odometry sample per path point with
  // the path's (signed) velocity; at the end of each segment but
  // the last it stands still (th_stopped_time is 1 s on the stamps) and expects the service to
  // move to the next segment; on the last it drives on past the end pose and expects completion.
  void drive(Client& client, std::uint64_t id, const PullOutPath& path) {
    std::int64_t stamp_ns = 1'000'000'000;
    const auto report = [&](const Pose2& pose, double v) {
      client.report_progress(progress_sample(id, stamp_ns, pose, v, true));
    };
    const std::size_t n = path.partial_paths.size();
    for (std::size_t k = 0; k < n; ++k) {
      const auto& points = path.partial_paths[k].points;
      for (std::size_t i = 0; i < points.size(); ++i) {
        // 20 ms per point on the vehicle's clock: samples sent in a burst must not run ahead of
        // the service's clock by more than the session's stamp tolerance (kMaxStampLead).
        if (i > 0) stamp_ns += 20'000'000;
        // Moving until the last point of the segment, where it has stopped.
        const bool last_point = i + 1 == points.size();
        const double v = last_point && k + 1 < n
                             ? 0.0
                             : (points[i].longitudinal_velocity_mps == 0.0 ? 0.5 : points[i].longitudinal_velocity_mps);
        report(points[i].pose, v);
        if (k + 1 < n && !last_point) {
          // Still on segment k: the index has not moved on.
          const auto st = client.latest_status();
          if (st && st->request_id == id) {
            EXPECT_EQ(st->current_path_idx, k) << "segment " << k << " point " << i;
          }
        }
      }
      if (k + 1 < n) {
        // Stand still at the segment end. The progress topic keeps the last sample per vehicle,
        // so samples sent in a burst may reach the service as one: send one every 50 ms (each
        // 0.5 s later on the vehicle's clock) until the service moves on.
        std::optional<PullOutStatus> st;
        for (int j = 0; j < 40 && !st; ++j) {
          stamp_ns += 500'000'000;
          report(points.back().pose, 0.0);
          st = client.wait_for_status(
              id, [k](const PullOutStatus& s) { return s.current_path_idx == k + 1; }, 50ms);
        }
        ASSERT_TRUE(st) << "the service did not advance past segment " << k;
        EXPECT_EQ(st->state, ExecutionState::kExecuting);
        EXPECT_EQ(client.current_segment(), std::optional<std::uint32_t>(static_cast<std::uint32_t>(k + 1)));
      }
    }
    // Drive on along the last segment past the end pose (the path continues on the road).
    const auto done = client.wait_for_status(
        id, [](const PullOutStatus& s) { return s.state == ExecutionState::kCompleted; }, kReplyTimeout);
    ASSERT_TRUE(done) << "not completed after driving the whole path";
    EXPECT_EQ(done->current_path_idx, n - 1);
  }
};

TEST_F(MultiSegmentExecution, ReverseThenTwoArcsOutOfATightParallelSpot) {
  const Sent p = start_and_send("parallel_spot_reverse", "int-multi-arc");
  ASSERT_TRUE(p.path);
  ASSERT_EQ(p.path->planner_type, PlannerType::kGeometric);
  ASSERT_EQ(p.path->partial_paths.size(), 3u) << "reverse, arc 1, arc 2";
  EXPECT_LT(p.path->partial_paths[0].points.front().longitudinal_velocity_mps, 0.0);
  EXPECT_LT(p.path->pairs_terminal_velocity_and_accel[0].velocity_mps, 0.0);
  EXPECT_GT(p.path->pairs_terminal_velocity_and_accel[1].velocity_mps, 0.0);
  // Found, not yet approved: the vehicle stands until its first approved progress sample.
  const auto executing = p.client->wait_for_status(
      p.id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout);
  ASSERT_TRUE(executing);
  EXPECT_EQ(executing->current_path_idx, 0u);
  EXPECT_EQ(executing->segment_count, 3u);
  drive(*p.client, p.id, *p.path);
}

TEST_F(MultiSegmentExecution, ReverseThenShiftWhenACarIsCloseAhead) {
  const Sent p = start_and_send("car_close_ahead", "int-multi-shift");
  ASSERT_TRUE(p.path);
  ASSERT_EQ(p.path->partial_paths.size(), 2u) << "reverse, shift";
  drive(*p.client, p.id, *p.path);
}

}  // namespace
}  // namespace pullout::integration
