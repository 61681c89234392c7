// Many pullout::Clients on one ClientParticipant, against the real pullout_service over loopback
// DDS: each vehicle is answered for its own request only (the path starts where that vehicle
// stands, and carries its id and request id), destroying one client leaves the others served,
// and the participant's contract (one client per vehicle id, no security, shared lifetime).
//
// Each vehicle stands at its own x on the shoulder, so a path handed to the wrong vehicle (or
// planned from another vehicle's request) starts at the wrong place. No negative check follows a
// sleep: foreign samples are counted by callbacks, read after every vehicle's own reply arrived
// on the same readers (reliable readers keep a writer's order).
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration_support.hpp"
#include "pullout/client/client.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

constexpr double kBaseX = 8.0;   // [m] straight_shoulder's start is x = 10
constexpr double kStepX = 0.75;  // [m] between consecutive vehicles

class SharedParticipantTest : public ServiceTest {
 protected:
  void SetUp() override {
    start_service();
    ASSERT_FALSE(HasFatalFailure());
    ClientParticipantOptions options;
    options.domain_id = domain();
    participant_ = std::make_unique<ClientParticipant>(options);
    base_ = load_test_scenario("straight_shoulder").request;
  }

  // A vehicle on the participant, matched with the service; counts replies of other vehicles or
  // requests that reach its callbacks.
  struct Vehicle {
    std::unique_ptr<Client> client;
    double x{0.0};
    std::shared_ptr<std::atomic<int>> foreign = std::make_shared<std::atomic<int>>(0);
  };

  Vehicle add_vehicle(int index) {
    Vehicle v;
    ClientOptions options;
    options.vehicle_id = "shared-" + std::to_string(index);
    v.client = std::make_unique<Client>(*participant_, options);
    v.x = kBaseX + kStepX * index;
    const std::string id = options.vehicle_id;
    auto foreign = v.foreign;
    v.client->on_path([id, foreign](const PullOutPath& p) {
      if (p.vehicle_id != id) ++*foreign;
    });
    v.client->on_status([id, foreign](const PullOutStatus& s) {
      if (s.vehicle_id != id) ++*foreign;
    });
    return v;
  }

  // Sends this vehicle's request and checks its answer: its id, its request, its start.
  std::uint64_t send(Vehicle& v) {
    PullOutRequest request = base_;
    request.ego_pose.x = v.x;
    return v.client->send(request);
  }

  void expect_own_answer(Vehicle& v, std::uint64_t id) {
    const auto path = v.client->wait_for_path(id, kReplyTimeout);
    ASSERT_TRUE(path.has_value()) << v.client->vehicle_id() << ": no path for request " << id;
    EXPECT_EQ(path->vehicle_id, v.client->vehicle_id());
    EXPECT_EQ(path->request_id, id);
    ASSERT_TRUE(path->found) << v.client->vehicle_id();
    expect_found_path_invariants(*path);
    ASSERT_FALSE(path->partial_paths.empty());
    ASSERT_FALSE(path->partial_paths.front().points.empty());
    // The path starts where this vehicle stands (no backward shift is needed on this free road).
    EXPECT_NEAR(path->partial_paths.front().points.front().pose.x, v.x, 1e-6) << v.client->vehicle_id();
    const auto status = v.client->wait_for_status(
        id, [](const PullOutStatus& s) { return s.state != ExecutionState::kPlanning; }, kReplyTimeout);
    ASSERT_TRUE(status.has_value()) << v.client->vehicle_id();
    EXPECT_EQ(status->vehicle_id, v.client->vehicle_id());
    EXPECT_EQ(status->state, ExecutionState::kWaitingApproval);
  }

  std::unique_ptr<ClientParticipant> participant_;
  PullOutRequest base_;
};

TEST_F(SharedParticipantTest, TwentyVehiclesOnOneParticipantEachGetOnlyTheirOwnReplies) {
  constexpr int kVehicles = 20;
  std::vector<Vehicle> vehicles;
  for (int i = 0; i < kVehicles; ++i) vehicles.push_back(add_vehicle(i));
  EXPECT_EQ(participant_->client_count(), static_cast<std::size_t>(kVehicles));
  for (auto& v : vehicles) ASSERT_TRUE(v.client->wait_for_service(kMatchTimeout)) << v.client->vehicle_id();
  EXPECT_EQ(vehicles.front().client->domain_id(), domain());

  // All requests first, then the answers: the service handles them concurrently.
  std::vector<std::uint64_t> ids;
  for (auto& v : vehicles) ids.push_back(send(v));
  for (int i = 0; i < kVehicles; ++i) {
    expect_own_answer(vehicles[i], ids[i]);
    // The latest path is this vehicle's, and the callback saw nothing foreign.
    const auto latest = vehicles[i].client->latest_path();
    ASSERT_TRUE(latest.has_value());
    EXPECT_EQ(latest->request_id, ids[i]);
  }
  for (auto& v : vehicles) EXPECT_EQ(v.foreign->load(), 0) << v.client->vehicle_id();
}

TEST_F(SharedParticipantTest, DestroyingOneClientDoesNotDisturbTheOthers) {
  constexpr int kVehicles = 5;
  std::vector<Vehicle> vehicles;
  for (int i = 0; i < kVehicles; ++i) vehicles.push_back(add_vehicle(i));
  for (auto& v : vehicles) ASSERT_TRUE(v.client->wait_for_service(kMatchTimeout));
  for (auto& v : vehicles) expect_own_answer(v, send(v));

  // Vehicle 2 leaves: its endpoints go, the participant and the others stay.
  vehicles[2].client.reset();
  EXPECT_EQ(participant_->client_count(), static_cast<std::size_t>(kVehicles - 1));
  for (int i = 0; i < kVehicles; ++i) {
    if (i == 2) continue;
    EXPECT_EQ(vehicles[i].client->service_state(), ServiceState::kConnected) << i;
    expect_own_answer(vehicles[i], send(vehicles[i]));
  }

  // The same vehicle may come back on the participant and is served again.
  Vehicle again = add_vehicle(2);
  ASSERT_TRUE(again.client->wait_for_service(kMatchTimeout));
  expect_own_answer(again, send(again));
  for (auto& v : vehicles) {
    if (v.client) {
      EXPECT_EQ(v.foreign->load(), 0) << v.client->vehicle_id();
    }
  }
  EXPECT_EQ(again.foreign->load(), 0);
}

TEST_F(SharedParticipantTest, AClientKeepsWorkingWhenItsParticipantObjectGoesFirst) {
  Vehicle v = add_vehicle(0);
  ASSERT_TRUE(v.client->wait_for_service(kMatchTimeout));
  participant_.reset();  // a contract violation that must not leave the client dangling
  expect_own_answer(v, send(v));
}

TEST_F(SharedParticipantTest, OneClientPerVehicleIdAndNoSecurityOnASharedParticipant) {
  Vehicle v = add_vehicle(0);
  ClientOptions same;
  same.vehicle_id = v.client->vehicle_id();
  EXPECT_THROW(Client(*participant_, same), std::invalid_argument);
  ClientOptions secure;
  secure.vehicle_id = "shared-secure";
  secure.security_dir = temp_.path();
  EXPECT_THROW(Client(*participant_, secure), std::invalid_argument);
  ClientOptions empty;
  EXPECT_THROW(Client(*participant_, empty), std::invalid_argument);
  // The failed constructions registered nothing.
  EXPECT_EQ(participant_->client_count(), 1u);
  ASSERT_TRUE(v.client->wait_for_service(kMatchTimeout));
  expect_own_answer(v, send(v));
}

TEST(ClientParticipantOptionsTest, BadDomainThrows) {
  ClientParticipantOptions options;
  options.domain_id = 233;
  EXPECT_THROW(ClientParticipant{options}, std::invalid_argument);
  options.domain_id = -1;
  EXPECT_THROW(ClientParticipant{options}, std::invalid_argument);
}

}  // namespace
}  // namespace pullout::integration
