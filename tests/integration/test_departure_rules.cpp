// The session's rules over DDS with the real service: a re-sent request is validated in full (it
// used to only replace the objects), and progress stamps cannot buy a standstill that did not
// happen (they used to be trusted).
#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "integration_support.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

class DepartureRules : public ServiceTest {};

TEST_F(DepartureRules, AResentRequestWithABadObjectIsRejectedNamingTheField) {
  Sent sent = start_and_send("straight_shoulder", "int-resend-bad");
  ASSERT_TRUE(sent.path && sent.path->found);
  ASSERT_TRUE(sent.client->wait_for_status(
      sent.id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout));
  // The same goal again at once (within backward_path_update_duration): it used to update only
  // the objects, taking a car of negative length.
  PullOutRequest again = sent.scenario.request;
  Object car;
  car.id = 3;
  car.pose = {50.0, -8.0, 0.0};
  car.length_m = -4.5;
  again.objects = {car};
  const std::uint64_t id = sent.client->send(again);
  const auto rejected = sent.client->wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kRejected; }, kReplyTimeout);
  ASSERT_TRUE(rejected) << "latest: "
                        << (sent.client->latest_status() ? static_cast<int>(sent.client->latest_status()->state) : -1);
  EXPECT_NE(rejected->error.find("objects[0].length_m"), std::string::npos) << rejected->error;
  const auto path = sent.client->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path);
  EXPECT_FALSE(path->found) << "a rejected request must not leave the vehicle a path to drive";
}

TEST_F(DepartureRules, StampsCannotBuyAStandstillAtTheReverseEnd) {
  Sent sent = start_and_send("car_close_ahead", "int-stamps");
  ASSERT_TRUE(sent.path && sent.path->found);
  ASSERT_GE(sent.path->partial_paths.size(), 2u);
  Client& client = *sent.client;
  std::int64_t stamp = 1'000'000'000;
  const auto report = [&](const Pose2& pose, double v, std::int64_t dt_ns) {
    stamp += dt_ns;
    client.report_progress(progress_sample(sent.id, stamp, pose, v, true));
  };
  const Pose2 start = sent.path->partial_paths[0].points.front().pose;
  std::optional<PullOutStatus> executing;
  for (int i = 0; i < 100 && !executing; ++i) {
    report(start, 0.0, 50'000'000);
    executing = client.wait_for_status(
        sent.id, [](const PullOutStatus& s) { return s.state == ExecutionState::kExecuting; }, 30ms);
  }
  ASSERT_TRUE(executing);

  // At the end of the reverse leg, standing still: every sample claims 0.5 s on the vehicle's
  // clock while 20 ms pass. th_stopped_time is 1 s: the stamps alone would make it after two.
  const Pose2 end0 = sent.path->partial_paths[0].points.back().pose;
  const auto stopped_at = SteadyClock::now();
  std::optional<PullOutStatus> advanced;
  for (int i = 0; i < 200 && !advanced; ++i) {
    report(end0, 0.0, 500'000'000);
    advanced = client.wait_for_status(
        sent.id, [](const PullOutStatus& s) { return s.current_path_idx == 1; }, 20ms);
  }
  const double waited_s = std::chrono::duration<double>(SteadyClock::now() - stopped_at).count();
  ASSERT_TRUE(advanced) << "never advanced past the reverse leg\n" << service_stderr();
  // Advanced only once a second had really passed (less the reply's own latency).
  EXPECT_GE(waited_s, 0.95) << "the segment advanced on the stamps alone";
}

TEST_F(DepartureRules, AWrongFirstStampIsRecoveredFrom) {
  Sent sent = start_and_send("car_close_ahead", "int-future");
  ASSERT_TRUE(sent.path && sent.path->found);
  Client& client = *sent.client;
  std::int64_t stamp = 1'000'000'000;
  const Pose2 start = sent.path->partial_paths[0].points.front().pose;
  // The first sample, not approved, stamped 1e6 s ahead: it becomes the reference ...
  client.report_progress(progress_sample(sent.id, stamp + 1'000'000'000'000'000, start, 0.0, false));
  // ... and honest, approved samples take over once kReanchorSamples of them agree.
  std::optional<PullOutStatus> executing;
  for (int i = 0; i < 100 && !executing; ++i) {
    stamp += 50'000'000;
    client.report_progress(progress_sample(sent.id, stamp, start, 0.0, true));
    executing = client.wait_for_status(
        sent.id, [](const PullOutStatus& s) { return s.state == ExecutionState::kExecuting; }, 30ms);
  }
  EXPECT_TRUE(executing) << service_stderr();
}

}  // namespace
}  // namespace pullout::integration
