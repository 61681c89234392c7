// Safe departure over DDS with the real service: the approval handshake, waiting for a fast car
// from behind (then going once the re-sent request no longer has it), going with a far car or a
// car that could not pass anyway, and a car appearing after departure (a stop path is published
// under the same request id, then the original path again once safe and stopped).
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "integration_support.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

// Polls `pred` every 20 ms until it holds or `timeout` passes.
bool eventually(const std::function<bool()>& pred, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return pred();
}

class SafeDeparture : public ServiceTest {
 protected:
  // One odometry sample; the progress topic keeps the last sample per vehicle, so samples are
  // spaced by 50 ms (each `dt_ns` later on the vehicle's clock).
  void report(Client& client, std::uint64_t id, const Pose2& pose, double v, bool approved,
              std::int64_t dt_ns = 100'000'000) {
    stamp_ns_ += dt_ns;
    client.report_progress(progress_sample(id, stamp_ns_, pose, v, approved));
    std::this_thread::sleep_for(50ms);
  }

  // Reports approved samples at `pose` until the status is `state` (or ~3 s pass).
  std::optional<PullOutStatus> report_until(Client& client, std::uint64_t id, const Pose2& pose, double v,
                                            ExecutionState state) {
    for (int i = 0; i < 60; ++i) {
      report(client, id, pose, v, true);
      const auto st = client.latest_status();
      if (st && st->request_id == id && st->state == state) return st;
    }
    return std::nullopt;
  }

  std::int64_t stamp_ns_{1'000'000'000};
};

TEST_F(SafeDeparture, NotExecutingUntilApproved) {
  Sent sent = start_and_send("straight_shoulder", "int-approval");
  ASSERT_NE(sent.client, nullptr);
  Scenario& scenario = sent.scenario;
  auto& client = sent.client;
  const std::uint64_t id = sent.id;
  const auto& path = sent.path;
  ASSERT_TRUE(path && path->found);
  const auto waiting = client->wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout);
  ASSERT_TRUE(waiting);
  EXPECT_EQ(waiting->stop_reason, "waiting approval");
  EXPECT_EQ(waiting->turn_signal, path->turn_signal);
  EXPECT_FALSE(waiting->departed);

  for (int i = 0; i < 10; ++i) report(*client, id, scenario.request.ego_pose, 0.0, false);
  auto latest = client->latest_status();
  ASSERT_TRUE(latest);
  EXPECT_EQ(latest->state, ExecutionState::kWaitingApproval);
  EXPECT_EQ(latest->turn_signal_start_ns, 0);

  const auto executing = report_until(*client, id, scenario.request.ego_pose, 0.0, ExecutionState::kExecuting);
  ASSERT_TRUE(executing) << "not executing after approval";
  EXPECT_TRUE(executing->departed);
  EXPECT_TRUE(executing->safe);
  EXPECT_GT(executing->turn_signal_start_ns, 0);
  EXPECT_EQ(executing->turn_signal, TurnSignal::kRight);  // from the shoulder on the left
}

TEST_F(SafeDeparture, FastCarFromBehindHoldsUntilItIsGone) {
  Sent sent = start_and_send("traffic_fast_from_behind", "int-fast-car");
  ASSERT_NE(sent.client, nullptr);
  Scenario& scenario = sent.scenario;
  auto& client = sent.client;
  const std::uint64_t id = sent.id;
  const auto& path = sent.path;
  ASSERT_TRUE(path && path->found);

  const auto held = report_until(*client, id, scenario.request.ego_pose, 0.0, ExecutionState::kWaitingSafety);
  ASSERT_TRUE(held);
  EXPECT_FALSE(held->safe);
  EXPECT_EQ(held->unsafe_object_id, 21);
  EXPECT_EQ(held->stop_reason.rfind("dynamic object risk", 0), 0u) << held->stop_reason;
  for (int i = 0; i < 10; ++i) report(*client, id, scenario.request.ego_pose, 0.0, true);
  EXPECT_EQ(client->latest_status()->state, ExecutionState::kWaitingSafety);

  // The vehicle re-sends its request with fresh objects: the car has passed. Within
  // backward_path_update_duration this only updates the objects: the same path, new id.
  scenario.request.objects.clear();
  const std::uint64_t id2 = client->send(scenario.request);
  const auto path2 = client->wait_for_path(id2, kReplyTimeout);
  ASSERT_TRUE(path2 && path2->found);
  EXPECT_EQ(path2->partial_paths[0].points.size(), path->partial_paths[0].points.size());
  const auto go = report_until(*client, id2, scenario.request.ego_pose, 0.0, ExecutionState::kExecuting);
  ASSERT_TRUE(go) << "not released once the car had gone";
  EXPECT_TRUE(go->safe);
}

TEST_F(SafeDeparture, FarCarAndCarThatCouldNotPassDoNotHold) {
  start_service();
  double offset_m = 0.0;  // the second vehicle 1 km away: not held for the first one's path
  for (const char* name : {"traffic_far_behind", "traffic_cannot_pass"}) {
    Scenario scenario = load_test_scenario(name);
    translate(scenario.request, offset_m, 0.0);
    offset_m += 1000.0;
    auto client = connect(std::string("int-") + name);
    ASSERT_NE(client, nullptr);
    const std::uint64_t id = client->send(scenario.request);
    const auto path = client->wait_for_path(id, kReplyTimeout);
    ASSERT_TRUE(path && path->found) << name;
    const auto go = report_until(*client, id, scenario.request.ego_pose, 0.0, ExecutionState::kExecuting);
    ASSERT_TRUE(go) << name << ": " << (client->latest_status() ? client->latest_status()->stop_reason : "");
  }
}

TEST_F(SafeDeparture, CarAppearingAfterDepartureStopsThenResumes) {
  start_service();
  Scenario scenario = load_test_scenario("traffic_far_behind");
  scenario.request.objects.clear();
  auto client = connect("int-appearing");
  ASSERT_NE(client, nullptr);
  const std::uint64_t id = client->send(scenario.request);
  const auto path = client->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path && path->found);
  ASSERT_TRUE(report_until(*client, id, scenario.request.ego_pose, 0.0, ExecutionState::kExecuting));

  // Drive a few metres at 2 m/s.
  const auto& points = path->partial_paths[0].points;
  std::size_t at = 0;
  while (at + 1 < points.size() &&
         std::hypot(points[at].pose.x - points[0].pose.x, points[at].pose.y - points[0].pose.y) < 6.0) {
    ++at;
    report(*client, id, points[at].pose, 2.0, true, 500'000'000);
  }
  ASSERT_EQ(client->latest_status()->state, ExecutionState::kExecuting);
  // A point beyond the stop distance where the original path moves: tells the two paths apart.
  std::size_t far = at;
  while (far + 1 < points.size() &&
         (std::hypot(points[far].pose.x - points[at].pose.x, points[far].pose.y - points[at].pose.y) < 4.0 ||
          points[far].longitudinal_velocity_mps <= 0.0)) {
    ++far;
  }
  ASSERT_GT(points[far].longitudinal_velocity_mps, 0.0);

  // A fast car appears 30 m behind: the re-sent request only updates the objects (latched path).
  Object car;
  car.id = 31;
  car.object_class = ObjectClass::kCar;
  car.pose = {points[at].pose.x - 30.0, 0.0, 0.0};
  car.velocity_mps = 10.0;
  scenario.request.objects = {car};
  scenario.request.ego_pose = points[at].pose;
  scenario.request.ego_velocity_mps = 2.0;
  const std::uint64_t id2 = client->send(scenario.request);
  ASSERT_TRUE(client->wait_for_path(id2, kReplyTimeout));
  const auto stopping = report_until(*client, id2, points[at].pose, 2.0, ExecutionState::kWaitingSafety);
  ASSERT_TRUE(stopping);
  EXPECT_EQ(stopping->unsafe_object_id, 31);
  EXPECT_TRUE(stopping->departed);

  // The stop path: same request id and points, velocities reach 0 within the jerk-limited stop
  // distance from 2 m/s (2.96 m with 1 m/s^2, 1 m/s^3).
  ASSERT_TRUE(eventually(
      [&] {
        const auto p = client->latest_path();
        return p && p->request_id == id2 && p->partial_paths[0].points[far].longitudinal_velocity_mps == 0.0;
      },
      3000ms));
  const PullOutPath stop = *client->latest_path();
  ASSERT_EQ(stop.partial_paths[0].points.size(), points.size());
  for (std::size_t i = at; i < points.size(); ++i) {
    const double d = std::hypot(points[i].pose.x - points[at].pose.x, points[i].pose.y - points[at].pose.y);
    const double v = stop.partial_paths[0].points[i].longitudinal_velocity_mps;
    EXPECT_LE(v, 2.0 + 1e-9);
    if (d > 2.96 + 0.5) {
      EXPECT_DOUBLE_EQ(v, 0.0) << "point " << i << " at " << d << " m";
    }
  }

  // The car has passed; the vehicle has stopped: resume the original path, same request id.
  scenario.request.objects.clear();
  const std::uint64_t id3 = client->send(scenario.request);
  ASSERT_TRUE(client->wait_for_path(id3, kReplyTimeout));
  // Still moving: stays stopped-waiting even though safe.
  report(*client, id3, points[at].pose, 1.0, true);
  EXPECT_NE(client->latest_status()->state, ExecutionState::kExecuting);
  const auto resumed = report_until(*client, id3, points[at].pose, 0.0, ExecutionState::kExecuting);
  ASSERT_TRUE(resumed);
  EXPECT_EQ(resumed->current_path_idx, 0u);
  ASSERT_TRUE(eventually(
      [&] {
        const auto p = client->latest_path();
        return p && p->request_id == id3 &&
               p->partial_paths[0].points[far].longitudinal_velocity_mps == points[far].longitudinal_velocity_mps;
      },
      3000ms));
}

TEST_F(SafeDeparture, ReSentRequestKeepsTheSegmentIndexOfALatchedMultiSegmentPath) {
  Sent sent = start_and_send("parallel_spot_reverse", "int-latched");
  ASSERT_NE(sent.client, nullptr);
  Scenario& scenario = sent.scenario;
  auto& client = sent.client;
  const std::uint64_t id = sent.id;
  const auto& path = sent.path;
  ASSERT_TRUE(path && path->found);
  ASSERT_EQ(path->partial_paths.size(), 3u) << "reverse, arc 1, arc 2";
  ASSERT_TRUE(report_until(*client, id, scenario.request.ego_pose, 0.0, ExecutionState::kExecuting));

  // Drive the reverse leg to its end and stand there until the service moves to segment 1.
  const auto stand_until = [&](std::uint64_t rid, const Pose2& pose, std::uint32_t idx) {
    for (int i = 0; i < 60; ++i) {
      report(*client, rid, pose, 0.0, true, 500'000'000);
      const auto st = client->latest_status();
      if (st && st->request_id == rid && st->current_path_idx == idx) return true;
    }
    return false;
  };
  const Pose2 end0 = path->partial_paths[0].points.back().pose;
  report(*client, id, path->partial_paths[0].points[1].pose, -1.0, true);
  ASSERT_TRUE(stand_until(id, end0, 1u));

  // The vehicle re-sends its request from there: latched, the index stays 1 under the new id.
  scenario.request.ego_pose = end0;
  const std::uint64_t id2 = client->send(scenario.request);
  const auto path2 = client->wait_for_path(id2, kReplyTimeout);
  ASSERT_TRUE(path2 && path2->found);
  ASSERT_EQ(path2->partial_paths.size(), 3u);
  EXPECT_EQ(path2->partial_paths[1].points.size(), path->partial_paths[1].points.size());
  const auto st = client->wait_for_status(
      id2, [](const PullOutStatus& s) { return s.current_path_idx == 1u; }, kReplyTimeout);
  ASSERT_TRUE(st);
  EXPECT_EQ(st->state, ExecutionState::kExecuting);
  EXPECT_EQ(client->current_segment(), std::optional<std::uint32_t>(1u));

  // And it keeps counting with the new id: the end of arc 1 leads to segment 2.
  report(*client, id2, path->partial_paths[1].points[1].pose, 1.0, true);
  ASSERT_TRUE(stand_until(id2, path->partial_paths[1].points.back().pose, 2u));
}

TEST_F(SafeDeparture, TurnSignalIsOnForThePrepareTimeBeforeDeparture) {
  // The shipped config with prepare_time_before_start: 2 s (and the profiles file given).
  std::ifstream in(default_config_path());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("prepare_time_before_start: 0.0", "prepare_time_before_start: 2.0");
  replace("profiles_file: \"\"", "profiles_file: " + loopback_profiles_path());
  start_service(temp_.write_file("pullout.yaml", text));

  const Scenario scenario = load_test_scenario("straight_shoulder");
  auto client = connect("int-prepare");
  ASSERT_NE(client, nullptr);
  const std::uint64_t id = client->send(scenario.request);
  ASSERT_TRUE(client->wait_for_path(id, kReplyTimeout));
  // Approved at t0: the signal comes on, departure waits 2 s on the progress clock.
  report(*client, id, scenario.request.ego_pose, 0.0, true);
  const std::int64_t t0 = stamp_ns_;
  ASSERT_TRUE(eventually(
      [&] {
        const auto st = client->latest_status();
        return st && st->state == ExecutionState::kWaitingSafety;
      },
      3000ms));
  EXPECT_EQ(client->latest_status()->stop_reason, "turn signal prepare time");
  EXPECT_EQ(client->latest_status()->turn_signal_start_ns, t0);
  report(*client, id, scenario.request.ego_pose, 0.0, true, 1'500'000'000);  // t0 + 1.5 s
  EXPECT_EQ(client->latest_status()->state, ExecutionState::kWaitingSafety);
  const auto go = report_until(*client, id, scenario.request.ego_pose, 0.0, ExecutionState::kExecuting);
  ASSERT_TRUE(go);
  EXPECT_GE(stamp_ns_ - t0, 2'000'000'000);
}

}  // namespace
}  // namespace pullout::integration
