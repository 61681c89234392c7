// The real pullout_service and real pullout::Clients over loopback DDS: a request is answered
// with a path and a status, the status follows a simulated vehicle to completion, late joiners
// get the latest path, nothing found gives a stop path with reasons, large paths and many
// vehicles are served. Every test runs its own service on a domain of its own (ServiceTest).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "integration_support.hpp"
#include "pullout/model/names.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

class PullOutFlow : public ServiceTest {};

bool is_state(const PullOutStatus& s, ExecutionState state) { return s.state == state; }

// Longitudinal position of `p` in the frame of `pose` [m] (positive ahead of it).
double ahead_of(const Pose2& pose, const Pose2& p) {
  return (p.x - pose.x) * std::cos(pose.yaw) + (p.y - pose.y) * std::sin(pose.yaw);
}

std::int64_t system_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

TEST_F(PullOutFlow, StraightShoulderIsPlannedAndExecutedToCompletion) {
  start_service();
  const Scenario scenario = load_test_scenario("straight_shoulder");
  auto client = connect("int-straight");
  ASSERT_NE(client, nullptr);

  const std::uint64_t id = client->send(scenario.request);
  const auto path = client->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path) << "no path within " << kReplyTimeout.count() << " s";
  EXPECT_EQ(path->vehicle_id, "int-straight");
  EXPECT_EQ(path->request_id, id);
  expect_found_path_invariants(*path);
  ASSERT_EQ(path->partial_paths.size(), 1u);
  EXPECT_EQ(path->planner_type, PlannerType::kShift);

  const auto executing = client->wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout);
  ASSERT_TRUE(executing) << "latest status: "
                         << (client->latest_status() ? static_cast<int>(client->latest_status()->state) : -1);
  EXPECT_EQ(executing->current_path_idx, 0u);
  EXPECT_EQ(executing->segment_count, 1u);
  EXPECT_EQ(executing->planner_type, PlannerType::kShift);
  EXPECT_FALSE(executing->evaluation_table.empty());
  EXPECT_EQ(client->current_segment(), std::optional<std::uint32_t>(0u));

  // Drive along the path: one odometry sample per path point.
  const auto& points = path->partial_paths[0].points;
  std::int64_t stamp_ns = system_now_ns();
  bool past_end = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    // 20 ms per point on the vehicle's clock: a burst must not run ahead of the service's clock by
    // more than the session's stamp tolerance (kMaxStampLead).
    if (i > 0) stamp_ns += 20'000'000;
    client->report_progress(progress_sample(id, stamp_ns, points[i].pose, points[i].longitudinal_velocity_mps, true));
    past_end = past_end || ahead_of(path->end_pose, points[i].pose) >= 0.0;
    const auto latest = client->latest_status();
    ASSERT_TRUE(latest);
    if (latest->request_id == id && latest->state == ExecutionState::kCompleted) {
      ASSERT_TRUE(past_end) << "COMPLETED before the vehicle reported a pose past end_pose (point " << i << ")";
    }
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_TRUE(past_end) << "the path never passes its own end_pose";

  // The vehicle stands at the last point and keeps reporting, as odometry does. (Progress is
  // volatile, and Client::wait_for_service does not wait for the progress writer to match: the
  // first samples may precede the match.)
  std::optional<PullOutStatus> completed;
  const auto give_up = SteadyClock::now() + kReplyTimeout;
  while (!completed && SteadyClock::now() < give_up) {
    completed = client->wait_for_status(
        id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kCompleted); }, 100ms);
    if (completed) break;
    stamp_ns += 100'000'000;
    ExecutionProgress standing;
    standing.request_id = id;
    standing.stamp_ns = stamp_ns;
    standing.pose = points.back().pose;
    standing.velocity_mps = 0.0;
    standing.approved = true;
    client->report_progress(standing);
  }
  ASSERT_TRUE(completed) << "no COMPLETED status after driving past end_pose";
  EXPECT_EQ(completed->current_path_idx, 0u);
  EXPECT_EQ(completed->segment_count, 1u);
  EXPECT_EQ(client->current_segment(), std::optional<std::uint32_t>(0u));
  EXPECT_EQ(client->latest_status()->state, ExecutionState::kCompleted);
}

TEST_F(PullOutFlow, ClientStartedAfterTheReplyGetsTheLatestPath) {
  start_service();
  const Scenario scenario = load_test_scenario("straight_shoulder");
  std::uint64_t id = 0;
  std::size_t segments = 0;
  {
    auto first = connect("int-late-joiner");
    ASSERT_NE(first, nullptr);
    id = first->send(scenario.request);
    const auto path = first->wait_for_path(id, kReplyTimeout);
    ASSERT_TRUE(path);
    ASSERT_TRUE(path->found);
    segments = path->partial_paths.size();
    ASSERT_TRUE(first->wait_for_status(
        id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout));
  }  // the first client is gone: only the service's transient-local history has the reply now

  // The second client takes its QoS from the shipped profiles file (the first used the built-in
  // defaults): both must give transient-local readers.
  auto second = connect("int-late-joiner", loopback_profiles_path());
  ASSERT_NE(second, nullptr);
  const auto path = second->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path) << "the late joiner did not receive the latest path";
  const auto latest = second->latest_path();
  ASSERT_TRUE(latest);
  EXPECT_EQ(latest->request_id, id);
  EXPECT_EQ(latest->partial_paths.size(), segments);
  expect_found_path_invariants(*latest);
  // A restarted client adopts the request the service last answered.
  EXPECT_EQ(second->current_request_id(), id);
  const auto status = second->wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout);
  ASSERT_TRUE(status);
  EXPECT_EQ(second->current_segment(), std::optional<std::uint32_t>(0u));
}

// Sends the boxed_in scenario and checks the reply: a stop path (found = false, every velocity 0,
// reasons) and NO_PATH with a stop reason and an evaluation table in which nothing succeeded.
// `status` receives the NO_PATH status; `table` the table as text for failure messages.
void expect_boxed_in_reply(Client& client, const Scenario& scenario, PullOutStatus& status, std::string& table) {
  const std::uint64_t id = client.send(scenario.request);
  const auto path = client.wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path);
  EXPECT_FALSE(path->found);
  EXPECT_FALSE(path->reasons.empty());
  ASSERT_FALSE(path->partial_paths.empty()) << "a stop path has at least one partial path";
  EXPECT_EQ(path->pairs_terminal_velocity_and_accel.size(), path->partial_paths.size());
  for (const auto& segment : path->partial_paths) {
    EXPECT_GE(segment.points.size(), 2u);
    for (const PathPoint& p : segment.points) EXPECT_EQ(p.longitudinal_velocity_mps, 0.0);
  }
  for (const auto& pair : path->pairs_terminal_velocity_and_accel) EXPECT_EQ(pair.velocity_mps, 0.0);

  const auto no_path = client.wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kNoPath); }, kReplyTimeout);
  ASSERT_TRUE(no_path) << "no NO_PATH status";
  EXPECT_FALSE(no_path->stop_reason.empty());
  EXPECT_EQ(client.current_segment(), std::nullopt);
  ASSERT_FALSE(no_path->evaluation_table.empty());
  std::ostringstream text;
  for (const PlannerAttempt& row : no_path->evaluation_table) {
    text << "\n  planner " << static_cast<int>(row.planner) << ", margin " << row.margin_m << " m, backward "
         << row.backward_distance_m << " m: " << describe(row);
    EXPECT_NE(row.outcome, AttemptOutcome::kSuccess);
  }
  status = *no_path;
  table = text.str();
}

TEST_F(PullOutFlow, BoxedInGivesAStopPathAndNoPathWithReasons) {
  // The shipped config searches backward start poses (enable_back) and skips a start candidate
  // closer than collision_check_margin_from_front_object to an object ahead, as Autoware does,
  // the current pose included: here no candidate survives, and the table says why for each.
  start_service();
  const Scenario scenario = load_test_scenario("boxed_in");
  auto client = connect("int-boxed-in");
  ASSERT_NE(client, nullptr);
  PullOutStatus status;
  std::string table;
  expect_boxed_in_reply(*client, scenario, status, table);
  if (HasFatalFailure()) return;
  bool current_pose_explained = false;
  for (const PlannerAttempt& row : status.evaluation_table) {
    current_pose_explained = current_pose_explained || row.backward_distance_m == 0.0;
  }
  EXPECT_TRUE(current_pose_explained) << "no row for the current pose:" << table;
}

TEST_F(PullOutFlow, BoxedInWithoutBackwardSearchTriesEveryMargin) {
  // Only the current pose as start candidate: every margin of the ladder is tried, each attempt
  // recorded with its outcome. Single moves only: shunting (forward first, without the backward
  // search) gets out of this spot.
  const std::string config = temp_.write_file("no_back.yaml",
                                              "start_planner:\n"
                                              "  enable_back: false\n"
                                              "  geometric_pull_out_max_shunts: 0\n"
                                              "dds:\n"
                                              "  profiles_file: " +
                                                  loopback_profiles_path() + "\n");
  start_service(config);
  const Scenario scenario = load_scenario(scenario_path("boxed_in"), load_config(config));
  auto client = connect("int-boxed-in-no-back");
  ASSERT_NE(client, nullptr);
  PullOutStatus status;
  std::string table;
  expect_boxed_in_reply(*client, scenario, status, table);
  if (HasFatalFailure()) return;
  std::set<double> margins;
  for (const PlannerAttempt& row : status.evaluation_table) margins.insert(row.margin_m);
  const auto& ladder = scenario.parameters.collision_check_margins;
  EXPECT_EQ(margins, std::set<double>(ladder.begin(), ladder.end())) << "evaluation table:" << table;
  EXPECT_EQ(margins.size(), 4u) << "evaluation table:" << table;
}

TEST_F(PullOutFlow, FiveThousandPointPathArrives) {
  // A 6 km straight road; the reference path runs from the start to the goal 5.8 km ahead, one
  // point per metre: the reply has about 5,800 points (~0.5 MB).
  const std::string config = temp_.write_file("long_road.yaml",
                                              "start_planner:\n"
                                              "  forward_path_length: 6000.0\n"
                                              "  center_line_path_interval: 1.0\n"
                                              "dds:\n"
                                              "  profiles_file: " +
                                                  loopback_profiles_path() + "\n");
  const std::string scenario_file =
      temp_.write_file("long_road_scenario.yaml",
                       "description: \"6 km straight road, goal 5.8 km ahead: a path of more than 5,000 points\"\n"
                       "lanes:\n"
                       "  - {id: 1, subtype: road, speed_limit: 13.89,\n"
                       "     left_bound: [[0, 1.75], [6000, 1.75]], right_bound: [[0, -1.75], [6000, -1.75]]}\n"
                       "  - {id: 2, subtype: road_shoulder, speed_limit: 13.89,\n"
                       "     left_bound: [[0, 4.75], [6000, 4.75]], right_bound: [[0, 1.75], [6000, 1.75]]}\n"
                       "start: {x: 10.0, y: 3.25, yaw_deg: 0.0}\n"
                       "goal: {x: 5810.0, y: 0.0, yaw_deg: 0.0}\n"
                       "planner: {forward_path_length: 6000.0, center_line_path_interval: 1.0}\n"
                       "deadline_ms: 5000\n");
  start_service(config);
  const Scenario scenario = load_scenario(scenario_file, load_config(config));
  auto client = connect("int-long-road");
  ASSERT_NE(client, nullptr);

  constexpr auto kBound = 5s;  // functional bound, not a timing test (a quiet run takes ~0.1 s)
  const auto sent = SteadyClock::now();
  const std::uint64_t id = client->send(scenario.request);
  const auto path = client->wait_for_path(id, kReplyTimeout);
  const auto elapsed = SteadyClock::now() - sent;
  ASSERT_TRUE(path) << "no path within " << kReplyTimeout.count() << " s";
  expect_found_path_invariants(*path);
  std::size_t points = 0;
  for (const auto& segment : path->partial_paths) points += segment.points.size();
  EXPECT_GE(points, 5000u);
  RecordProperty("points", static_cast<int>(points));
  RecordProperty("send_to_path_ms",
                 static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(elapsed).count()));
  EXPECT_LT(elapsed, kBound) << "took " << std::chrono::duration_cast<std::chrono::milliseconds>(elapsed).count()
                             << " ms";
  const auto status = client->wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->segment_count, path->partial_paths.size());
}

TEST_F(PullOutFlow, TwentyVehiclesAtOnceAreAllServed) {
  constexpr int kVehicles = 20;
  constexpr auto kBound = 30s;  // for all of them, from the first send
  start_service();
  const Scenario scenario = load_test_scenario("straight_shoulder");

  std::vector<std::unique_ptr<Client>> clients;
  clients.reserve(kVehicles);
  for (int i = 0; i < kVehicles; ++i) {
    ClientOptions options;
    options.vehicle_id = "int-fleet-" + std::to_string(i);
    options.domain_id = domain();
    clients.push_back(std::make_unique<Client>(options));
  }
  const auto match_deadline = SteadyClock::now() + kMatchTimeout;
  for (auto& c : clients) {
    const auto left = std::chrono::duration_cast<Client::Duration>(match_deadline - SteadyClock::now());
    ASSERT_TRUE(c->wait_for_service(std::max(left, Client::Duration::zero())))
        << c->vehicle_id() << " did not match the service";
  }

  // Every vehicle sends from its own thread at (nearly) the same moment.
  std::atomic<bool> go{false};
  std::vector<std::optional<PullOutPath>> paths(kVehicles);
  std::vector<std::uint64_t> ids(kVehicles, 0);
  std::vector<std::string> errors(kVehicles);
  std::vector<std::thread> threads;
  threads.reserve(kVehicles);
  const auto start = SteadyClock::now();
  for (int i = 0; i < kVehicles; ++i) {
    threads.emplace_back([&, i] {
      while (!go.load()) std::this_thread::yield();
      try {
        ids[i] = clients[i]->send(scenario.request);
        const auto left = std::chrono::duration_cast<Client::Duration>(start + kBound - SteadyClock::now());
        paths[i] = clients[i]->wait_for_path(ids[i], std::max(left, Client::Duration::zero()));
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    });
  }
  go.store(true);
  for (auto& t : threads) t.join();
  const auto elapsed = SteadyClock::now() - start;

  int served = 0;
  for (int i = 0; i < kVehicles; ++i) {
    SCOPED_TRACE(clients[i]->vehicle_id());
    EXPECT_TRUE(errors[i].empty()) << errors[i];
    if (!paths[i]) {
      ADD_FAILURE() << "no path";
      continue;
    }
    EXPECT_EQ(paths[i]->vehicle_id, clients[i]->vehicle_id());
    EXPECT_EQ(paths[i]->request_id, ids[i]);
    expect_found_path_invariants(*paths[i]);
    if (paths[i]->found) ++served;
  }
  EXPECT_EQ(served, kVehicles);
  EXPECT_LT(elapsed, kBound);
  // And each vehicle's status is its own.
  for (int i = 0; i < kVehicles; ++i) {
    const auto status = clients[i]->wait_for_status(
        ids[i], [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout);
    EXPECT_TRUE(status) << clients[i]->vehicle_id();
  }
}

}  // namespace
}  // namespace pullout::integration
