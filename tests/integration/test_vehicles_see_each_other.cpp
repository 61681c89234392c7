// Vehicles that see each other, through the real service over DDS (tests/scenarios/
// fleet_opposite_shoulders.yaml): fleet-a approved and executing, fleet-b in the neighbouring spot
// whose path crosses fleet-a's is held, its status naming fleet-a, until fleet-a's progress has
// passed; then it departs. Control: without fleet-a executing, fleet-b departs at once. And mixed
// vehicles: a request naming an unknown profile, or bad dimensions, is rejected naming the field.
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "integration_support.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

bool executing(const PullOutStatus& s) { return s.state == ExecutionState::kExecuting; }

class VehiclesSeeEachOther : public ServiceTest {
 protected:
  struct Vehicle {
    std::unique_ptr<Client> client;
    std::uint64_t id{0};
    PullOutPath path;
    std::int64_t stamp_ns{1'000'000'000};
  };
  Vehicle send(const PullOutRequest& request) {
    Vehicle v;
    v.client = connect(request.vehicle_id);
    v.id = v.client->send(request);
    const auto path = v.client->wait_for_path(v.id, kReplyTimeout);
    EXPECT_TRUE(path && path->found) << request.vehicle_id << ": " << service_stderr();
    if (path) v.path = *path;
    return v;
  }
  // One approved sample 20 ms later on the vehicle's clock.
  static void report(Vehicle& v, const Pose2& pose, double velocity) {
    v.stamp_ns += 20'000'000;
    v.client->report_progress(progress_sample(v.id, v.stamp_ns, pose, velocity, true));
  }
  static Pose2 start_of(const PullOutPath& p) { return p.partial_paths.front().points.front().pose; }
};

TEST_F(VehiclesSeeEachOther, TheVehicleInTheNeighbouringSpotIsHeldUntilTheExecutingOnesProgressPasses) {
  start_service();
  const Scenario sc = load_test_scenario("fleet_opposite_shoulders");
  ASSERT_EQ(sc.fleet.size(), 1u);
  Vehicle a = send(sc.fleet.front());
  ASSERT_FALSE(a.path.partial_paths.empty());
  report(a, start_of(a.path), 0.0);
  ASSERT_TRUE(a.client->wait_for_status(a.id, executing, kReplyTimeout)) << "fleet-a departs";

  Vehicle b = send(sc.request);
  ASSERT_FALSE(b.path.partial_paths.empty());
  report(b, start_of(b.path), 0.0);
  const auto held = b.client->wait_for_status(
      b.id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingSafety; }, kReplyTimeout);
  ASSERT_TRUE(held) << service_stderr();
  EXPECT_EQ(held->waiting_for_vehicle_id, "fleet-a");
  EXPECT_NE(held->stop_reason.find("fleet-a"), std::string::npos) << held->stop_reason;
  EXPECT_FALSE(held->departed);

  // fleet-a drives its path and past its end; fleet-b keeps reporting, approved, from its spot.
  bool b_departed = false;
  std::size_t a_samples = 0;
  const auto drive_a = [&](const Pose2& pose, double v) {
    report(a, pose, v);
    ++a_samples;
    report(b, start_of(b.path), 0.0);
    std::this_thread::sleep_for(10ms);  // pacing: keep-last-1 progress may merge a burst
    const auto s = b.client->latest_status();
    if (s && s->request_id == b.id && executing(*s)) b_departed = true;
  };
  for (const auto& segment : a.path.partial_paths) {
    for (const auto& point : segment.points) {
      if (b_departed) break;
      drive_a(point.pose, point.longitudinal_velocity_mps == 0.0 ? 0.5 : point.longitudinal_velocity_mps);
    }
  }
  const Pose2 end = a.path.partial_paths.back().points.back().pose;
  for (int i = 0; i < 200 && !b_departed; ++i) drive_a({end.x + 0.2 * (i + 1), end.y, end.yaw}, 2.0);
  const auto departed = b.client->wait_for_status(b.id, executing, kReplyTimeout);
  ASSERT_TRUE(departed) << "fleet-b never departed; " << service_stderr();
  EXPECT_TRUE(departed->waiting_for_vehicle_id.empty());
  EXPECT_TRUE(departed->departed);
  EXPECT_GT(a_samples, 1u) << "fleet-b went while fleet-a had not moved";
}

TEST_F(VehiclesSeeEachOther, WithoutTheOtherVehicleExecutingTheVehicleDepartsAtOnce) {
  start_service();
  const Scenario sc = load_test_scenario("fleet_opposite_shoulders");
  ASSERT_EQ(sc.fleet.size(), 1u);
  Vehicle a = send(sc.fleet.front());  // planned, never approved: not executing
  Vehicle b = send(sc.request);
  ASSERT_FALSE(b.path.partial_paths.empty());
  report(b, start_of(b.path), 0.0);
  const auto s = b.client->wait_for_status(b.id, executing, kReplyTimeout);
  ASSERT_TRUE(s) << service_stderr();
  EXPECT_TRUE(s->waiting_for_vehicle_id.empty());
}

TEST_F(VehiclesSeeEachOther, ABadVehicleIsRejectedNamingTheField) {
  start_service();
  const Scenario sc = load_test_scenario("straight_shoulder");
  const auto client = connect("int-mixed-bad");
  PullOutRequest unknown = sc.request;
  unknown.vehicle_profile = "tram";
  const std::uint64_t id = client->send(unknown);
  const auto rejected = client->wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kRejected; }, kReplyTimeout);
  ASSERT_TRUE(rejected) << service_stderr();
  EXPECT_NE(rejected->error.find("vehicle_profile: unknown profile 'tram'"), std::string::npos) << rejected->error;

  PullOutRequest bad = sc.request;
  VehicleInfo v;
  v.wheel_tread_m = 50.0;
  bad.vehicle = v;
  const std::uint64_t id2 = client->send(bad);
  const auto rejected2 = client->wait_for_status(
      id2, [](const PullOutStatus& s) { return s.state == ExecutionState::kRejected; }, kReplyTimeout);
  ASSERT_TRUE(rejected2) << service_stderr();
  EXPECT_NE(rejected2->error.find("vehicle.wheel_tread"), std::string::npos) << rejected2->error;

  // A bus profile through the client's options: planned with the bus.
  const auto bus = connect("int-mixed-bus");
  PullOutRequest as_bus = sc.request;
  as_bus.vehicle_profile = "bus";
  const std::uint64_t id3 = bus->send(as_bus);
  const auto path = bus->wait_for_path(id3, kReplyTimeout);
  ASSERT_TRUE(path);
  EXPECT_TRUE(path->found);
}

}  // namespace
}  // namespace pullout::integration
