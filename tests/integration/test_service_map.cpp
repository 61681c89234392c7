// The real pullout_service configured with a Lanelet2 map (the project's own
// tests/maps/straight_shoulder.osm, so the test needs nothing outside the repository): a request
// naming route lanelets is answered with a path, a bad route is rejected naming the field, and a
// malformed map file stops the service at start-up with one line.
#include <chrono>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "integration_support.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

class MapService : public ServiceTest {
 protected:
  // A config beside the temporary directory's map reference: the shipped parameters, the
  // loopback profile and map.path (absolute, so the file may live anywhere).
  std::string map_config() {
    return temp_.write_file("map.yaml", "dds:\n  profiles_file: " + loopback_profiles_path() + "\nmap:\n  path: " +
                                            source_path("tests/maps/straight_shoulder.osm") + "\n");
  }
};

bool is_state(const PullOutStatus& s, ExecutionState state) { return s.state == state; }

TEST_F(MapService, RouteRequestIsAnsweredAndABadRouteIsRejectedNamingTheField) {
  start_service(map_config());
  const Scenario scenario = load_test_scenario("map_shoulder");
  ASSERT_TRUE(scenario.request.lanes.empty()) << "the request carries route ids only";
  auto client = connect("int-map");
  ASSERT_NE(client, nullptr);

  const std::uint64_t id = client->send(scenario.request);
  const auto path = client->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path) << "no path for the route request\n" << service_stderr();
  expect_found_path_invariants(*path);
  EXPECT_EQ(path->planner_type, PlannerType::kShift);
  // Lane ids along the path are the map's lanelet ids.
  bool on_route = false;
  for (const auto& point : path->partial_paths.back().points) {
    for (std::int64_t lane : point.lane_ids) on_route = on_route || lane == 102;
  }
  EXPECT_TRUE(on_route) << "the path never reaches route lanelet 102";
  // Found: the service waits for the vehicle's approval to depart.
  const auto waiting = client->wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout);
  EXPECT_TRUE(waiting);

  // Another vehicle (the first one's path is latched until it departs): lanelets 101 and 103 are
  // not consecutive, rejected with the field named.
  auto other = connect("int-map-bad");
  ASSERT_NE(other, nullptr);
  PullOutRequest bad = scenario.request;
  bad.route_lanelet_ids = {101, 103};
  const std::uint64_t bad_id = other->send(bad);
  const auto rejected = other->wait_for_status(
      bad_id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kRejected); }, kReplyTimeout);
  ASSERT_TRUE(rejected) << "no REJECTED status for the bad route";
  EXPECT_NE(rejected->error.find("route_lanelet_ids[1]"), std::string::npos) << rejected->error;
  EXPECT_NE(rejected->error.find("not connected"), std::string::npos) << rejected->error;

  // An unknown lanelet id.
  bad.route_lanelet_ids = {101, 777};
  const std::uint64_t unknown_id = other->send(bad);
  const auto unknown = other->wait_for_status(
      unknown_id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kRejected); }, kReplyTimeout);
  ASSERT_TRUE(unknown);
  EXPECT_NE(unknown->error.find("route_lanelet_ids[1]: unknown lanelet id 777"), std::string::npos) << unknown->error;

  // The service keeps serving the good route, to that vehicle too.
  const std::uint64_t again = other->send(scenario.request);
  const auto path_again = other->wait_for_path(again, kReplyTimeout);
  ASSERT_TRUE(path_again);
  EXPECT_TRUE(path_again->found);
}

// An Autoware route (segments with lane-change neighbours) crosses the wire and plans on the
// service's map; a segment that does not connect is rejected naming it.
TEST_F(MapService, RouteSegmentsRequestIsAnswered) {
  start_service(temp_.write_file("two_lane.yaml", "dds:\n  profiles_file: " + loopback_profiles_path() +
                                                      "\nmap:\n  path: " + source_path("tests/maps/two_lane_road.osm") +
                                                      "\n"));
  const Scenario scenario = load_test_scenario("map_lane_change_route");
  ASSERT_EQ(scenario.request.route_segments.size(), 3u);
  auto client = connect("int-map-segments");
  ASSERT_NE(client, nullptr);
  const std::uint64_t id = client->send(scenario.request);
  const auto path = client->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path) << "no path for the route segments\n" << service_stderr();
  expect_found_path_invariants(*path);
  EXPECT_TRUE(path->found);

  auto other = connect("int-map-segments-bad");
  ASSERT_NE(other, nullptr);
  PullOutRequest bad = scenario.request;
  bad.route_segments.erase(bad.route_segments.begin() + 1);  // 111/121 then 113/123: a gap
  const std::uint64_t bad_id = other->send(bad);
  const auto rejected = other->wait_for_status(
      bad_id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kRejected); }, kReplyTimeout);
  ASSERT_TRUE(rejected) << "no REJECTED status for the disconnected route";
  EXPECT_NE(rejected->error.find("route_segments[1]"), std::string::npos) << rejected->error;
  EXPECT_NE(rejected->error.find("not connected"), std::string::npos) << rejected->error;
}

// A route request is checked for traffic on the lanes picked on the map (the service used to build
// its safety check from the request's inline lanes, which a route request does not have).
TEST_F(MapService, ARouteRequestHoldsForAFastCarFromBehind) {
  start_service(map_config());
  const Scenario scenario = load_test_scenario("map_traffic_fast_from_behind");
  ASSERT_TRUE(scenario.request.lanes.empty());
  auto client = connect("int-map-traffic");
  ASSERT_NE(client, nullptr);
  const std::uint64_t id = client->send(scenario.request);
  const auto path = client->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path && path->found) << service_stderr();
  // The first status already carries the verdict at the start.
  const auto waiting = client->wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout);
  ASSERT_TRUE(waiting);
  EXPECT_FALSE(waiting->safe);
  EXPECT_EQ(waiting->unsafe_object_id, 21);
  // Approved: held for the car, never executing.
  const Pose2 start = path->partial_paths.front().points.front().pose;
  std::int64_t stamp = 1'000'000'000;
  std::optional<PullOutStatus> held;
  for (int i = 0; i < 50 && !held; ++i) {
    stamp += 50'000'000;
    client->report_progress(progress_sample(id, stamp, start, 0.0, true));
    held = client->wait_for_status(
        id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingSafety); }, 50ms);
  }
  ASSERT_TRUE(held) << "approved, but not held for the car behind";
  EXPECT_EQ(held->unsafe_object_id, 21);
  EXPECT_FALSE(held->departed);
}

TEST(ServiceStartup, RefusesAMalformedMapWithOneLine) {
  TempDir dir;
  const std::string map = dir.write_file("broken.osm", "<osm>\n<node id=\"1\">\n</osm>\n");
  const std::string config =
      dir.write_file("map.yaml", "dds:\n  profiles_file: " + loopback_profiles_path() + "\nmap:\n  path: broken.osm\n");
  DomainLease lease;
  ChildProcess service({PULLOUT_SERVICE_EXE, "--config", config, "--domain", std::to_string(lease.domain())},
                       dir.path() + "/stdout", dir.path() + "/stderr");
  const auto exit = service.wait_exit(10s);
  ASSERT_TRUE(exit) << "the service did not exit with a malformed map";
  EXPECT_TRUE(exit->exited) << exit->describe();
  EXPECT_EQ(exit->exit_code, 1) << "documented exit code of a bad config or map";
  const std::string err = read_file_tail(dir.path() + "/stderr", 10000);
  EXPECT_NE(err.find("pullout_service: invalid map (map.path): " + map + ": line 3: not valid XML"), std::string::npos)
      << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << "one line:\n" << err;
}

}  // namespace
}  // namespace pullout::integration
