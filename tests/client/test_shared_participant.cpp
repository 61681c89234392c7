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
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <thread>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "integration_support.hpp"
#include "pullout/client/client.hpp"
#include "pullout/idl/topics.hpp"
#include "pullout/idl/vehicle_filter.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

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

// The point of a ClientParticipant: the service's path and status writers see one filtered
// reader per participant, whatever the number of its vehicles (with a reader per vehicle, a
// fleet's reliability traffic grew as N^2: bench/RESULTS.md, "Load"). A stand-in writer on
// pullout/path, with the vehicle filter factory registered as the service does, counts the
// readers it matches. With endpoints per Client (the option kept for comparison) it counts one
// per vehicle.
TEST_F(SharedParticipantTest, TheServiceWritersMatchOneReaderPerParticipantNotPerVehicle) {
  namespace dds = eprosima::fastdds::dds;
  constexpr int kVehicles = 6;
  std::vector<Vehicle> vehicles;
  for (int i = 0; i < kVehicles; ++i) vehicles.push_back(add_vehicle(i));
  ClientParticipantOptions per_client_options;
  per_client_options.domain_id = domain();
  per_client_options.shared_endpoints = false;
  ClientParticipant per_client(per_client_options);
  std::vector<std::unique_ptr<Client>> others;
  for (int i = 0; i < kVehicles; ++i) {
    ClientOptions options;
    options.vehicle_id = "own-endpoints-" + std::to_string(i);
    others.push_back(std::make_unique<Client>(per_client, options));
  }
  for (auto& v : vehicles) ASSERT_TRUE(v.client->wait_for_service(kMatchTimeout));
  for (auto& c : others) ASSERT_TRUE(c->wait_for_service(kMatchTimeout));

  idl::VehicleIdFilterFactory filters;
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipantQos qos = factory->get_default_participant_qos();
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.emplace_back("127.0.0.1");
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.push_back(udp);
  dds::DomainParticipant* probe = factory->create_participant(domain(), qos);
  ASSERT_NE(probe, nullptr);
  ASSERT_EQ(probe->register_content_filter_factory(idl::kVehicleFilterClass, &filters),
            eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK);
  dds::TypeSupport type(new msg::PullOutPathPubSubType());
  type.register_type(probe);
  dds::Topic* topic = probe->create_topic(idl::kPathTopic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  dds::Publisher* publisher = probe->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  dds::DataWriterQos writer_qos;
  writer_qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  writer_qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  writer_qos.writer_resource_limits().reader_filters_allocation.maximum = 64;
  dds::DataWriter* writer = publisher->create_datawriter(topic, writer_qos);
  ASSERT_NE(writer, nullptr);
  // One reader for the shared participant's 6 vehicles, 6 for the per-Client ones.
  const auto deadline = std::chrono::steady_clock::now() + kMatchTimeout;
  dds::PublicationMatchedStatus matched;
  do {
    std::this_thread::sleep_for(50ms);
    writer->get_publication_matched_status(matched);
  } while (matched.current_count < 1 + kVehicles && std::chrono::steady_clock::now() < deadline);
  EXPECT_EQ(matched.current_count, 1 + kVehicles);
  // No more than that once discovery has settled (a reader per vehicle would have come with them).
  std::this_thread::sleep_for(500ms);
  writer->get_publication_matched_status(matched);
  EXPECT_EQ(matched.current_count, 1 + kVehicles);
  probe->delete_contained_entities();
  factory->delete_participant(probe);

  for (auto& v : vehicles) expect_own_answer(v, send(v));
  for (auto& v : vehicles) EXPECT_EQ(v.foreign->load(), 0) << v.client->vehicle_id();
}

// Vehicles join and leave the participant while others keep requesting: the set filter changes
// under traffic. Every request of the vehicles that stay is answered with their own path, a
// vehicle that joins is served, a vehicle that left and its id taken by another participant is
// served there, and no callback ever sees another vehicle's reply.
TEST_F(SharedParticipantTest, VehiclesJoiningAndLeavingWhileOthersRequestEachGetOnlyTheirOwn) {
  constexpr int kSteady = 4;
  std::vector<Vehicle> steady;
  for (int i = 0; i < kSteady; ++i) steady.push_back(add_vehicle(i));
  for (auto& v : steady) ASSERT_TRUE(v.client->wait_for_service(kMatchTimeout));

  std::atomic<bool> stop{false};
  std::atomic<int> answered{0};
  std::atomic<int> failures{0};
  // Stopped and joined on every way out of the test (an ASSERT returns early).
  struct Joiner {
    std::atomic<bool>& stop;
    std::thread thread;
    ~Joiner() {
      stop.store(true);
      if (thread.joinable()) thread.join();
    }
  } traffic{stop, std::thread([&] {
              while (!stop.load()) {
                for (auto& v : steady) {
                  PullOutRequest request = base_;
                  request.ego_pose.x = v.x;
                  const auto id = v.client->send(request);
                  const auto path = v.client->wait_for_path(id, kReplyTimeout);
                  if (!path || path->vehicle_id != v.client->vehicle_id() || path->request_id != id ||
                      std::abs(path->partial_paths.front().points.front().pose.x - v.x) > 1e-6) {
                    ++failures;
                  } else {
                    ++answered;
                  }
                }
              }
            })};

  // Joiners 10..17, each served; every other one leaves again at once after its answer.
  std::vector<Vehicle> joined;
  for (int i = 10; i < 18; ++i) {
    Vehicle v = add_vehicle(i);
    ASSERT_TRUE(v.client->wait_for_service(kMatchTimeout)) << i;
    expect_own_answer(v, send(v));
    EXPECT_EQ(v.foreign->load(), 0) << i;
    if (i % 2 == 0) {
      v.client.reset();
    } else {
      joined.push_back(std::move(v));
    }
  }
  // A vehicle that left this participant (shared-10) now on a participant of its own.
  ClientParticipantOptions other_options;
  other_options.domain_id = domain();
  ClientParticipant other(other_options);
  ClientOptions moved;
  moved.vehicle_id = "shared-10";
  Client moved_client(other, moved);
  ASSERT_TRUE(moved_client.wait_for_service(kMatchTimeout));
  PullOutRequest request = base_;
  request.ego_pose.x = kBaseX + kStepX * 10;
  const auto moved_id = moved_client.send(request);
  const auto moved_path = moved_client.wait_for_path(moved_id, kReplyTimeout);
  ASSERT_TRUE(moved_path.has_value());
  EXPECT_EQ(moved_path->vehicle_id, "shared-10");

  // The joined ones still served after the others left.
  for (auto& v : joined) expect_own_answer(v, send(v));
  stop.store(true);
  traffic.thread.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_GE(answered.load(), kSteady);
  for (auto& v : steady) EXPECT_EQ(v.foreign->load(), 0) << v.client->vehicle_id();
  for (auto& v : joined) EXPECT_EQ(v.foreign->load(), 0) << v.client->vehicle_id();
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
