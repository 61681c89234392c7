// pullout::Client against a fake service made of plain Fast DDS entities (loopback only, a domain
// of its own per test process): requests and progress arrive with the client's fields filled,
// replies of other vehicles are filtered out, late joiners get the latest path, callbacks run on
// the client's thread, waits time out.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "dds_qos.hpp"
#include "pullout/client/client.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

namespace pullout {
namespace {

namespace dds = eprosima::fastdds::dds;
using namespace std::chrono_literals;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;

// A domain of this test process, away from domain 0 where services may run.
int test_domain() { return 150 + static_cast<int>(::getpid() % 80); }

// Polls `condition` until true or the timeout expires.
template <typename Condition>
bool eventually(Condition condition, std::chrono::milliseconds timeout = 5000ms) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(5ms);
  }
  return condition();
}

// The service side of the topics, with the QoS of DESIGN.md.
class FakeService {
 public:
  FakeService() {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    participant_ = factory->create_participant(test_domain(), client_detail::loopback_participant_qos());
    if (participant_ == nullptr) throw std::runtime_error("fake service: no participant");
    const auto topic = [this](dds::TopicDataType* type, const char* name) {
      dds::TypeSupport support(type);
      support.register_type(participant_);
      return participant_->create_topic(name, support.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    };
    dds::Topic* request = topic(std::make_unique<msg::PullOutRequestPubSubType>().release(), "pullout/request");
    dds::Topic* progress = topic(std::make_unique<msg::ExecutionProgressPubSubType>().release(), "pullout/progress");
    dds::Topic* path = topic(std::make_unique<msg::PullOutPathPubSubType>().release(), "pullout/path");
    dds::Topic* status = topic(std::make_unique<msg::PullOutStatusPubSubType>().release(), "pullout/status");
    auto* subscriber = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    auto* publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    dds::DataReaderQos rq;
    rq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    rq.history().depth = 16;
    request_reader_ = subscriber->create_datareader(request, rq);
    progress_reader_ = subscriber->create_datareader(progress, rq);
    dds::DataWriterQos wq;
    wq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    wq.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    wq.history().depth = 1;
    path_writer_ = publisher->create_datawriter(path, wq);
    status_writer_ = publisher->create_datawriter(status, wq);
    if (!request_reader_ || !progress_reader_ || !path_writer_ || !status_writer_) {
      throw std::runtime_error("fake service: endpoints");
    }
  }
  ~FakeService() {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  FakeService(const FakeService&) = delete;
  FakeService& operator=(const FakeService&) = delete;

  // The next request of `vehicle` (another test process may share the domain).
  std::optional<PullOutRequest> wait_request(const std::string& vehicle, std::chrono::milliseconds timeout = 5000ms) {
    std::optional<PullOutRequest> out;
    eventually(
        [&] {
          msg::PullOutRequest sample;
          dds::SampleInfo info;
          while (request_reader_->take_next_sample(&sample, &info) == ReturnCode::RETCODE_OK) {
            if (!info.valid_data) continue;
            if (sample.vehicle_id() != vehicle) continue;
            std::vector<RequestIssue> issues;
            out = idl::from_msg(sample, issues);
            return true;
          }
          return false;
        },
        timeout);
    return out;
  }
  std::optional<ExecutionProgress> wait_progress(const std::string& vehicle,
                                                 std::chrono::milliseconds timeout = 5000ms) {
    std::optional<ExecutionProgress> out;
    eventually(
        [&] {
          msg::ExecutionProgress sample;
          dds::SampleInfo info;
          while (progress_reader_->take_next_sample(&sample, &info) == ReturnCode::RETCODE_OK) {
            if (!info.valid_data || sample.vehicle_id() != vehicle) continue;
            std::vector<RequestIssue> issues;
            out = idl::from_msg(sample, issues);
            return true;
          }
          return false;
        },
        timeout);
    return out;
  }
  void publish(const PullOutPath& path) {
    msg::PullOutPath sample = idl::to_msg(path);
    ASSERT_TRUE(path_writer_->write(&sample));
  }
  void publish(const PullOutStatus& status) {
    msg::PullOutStatus sample = idl::to_msg(status);
    ASSERT_TRUE(status_writer_->write(&sample));
  }

 private:
  dds::DomainParticipant* participant_{nullptr};
  dds::DataReader* request_reader_{nullptr};
  dds::DataReader* progress_reader_{nullptr};
  dds::DataWriter* path_writer_{nullptr};
  dds::DataWriter* status_writer_{nullptr};
};

ClientOptions options(const std::string& vehicle) {
  ClientOptions o;
  o.vehicle_id = vehicle;
  o.domain_id = test_domain();
  return o;
}

PullOutPath make_path(const std::string& vehicle, std::uint64_t request_id, int points_per_segment = 10) {
  PullOutPath path;
  path.vehicle_id = vehicle;
  path.request_id = request_id;
  path.found = true;
  path.planner_type = PlannerType::kShift;
  for (int s = 0; s < 2; ++s) {
    PathWithLaneId segment;
    for (int i = 0; i < points_per_segment; ++i) segment.points.push_back({{0.1 * i, 1.0 * s, 0.0}, 1.0, {1, 2}});
    path.partial_paths.push_back(segment);
    path.pairs_terminal_velocity_and_accel.push_back({s == 0 ? 0.0 : 2.0, 0.0});
  }
  path.end_pose = {20.0, 0.0, 0.0};
  return path;
}

PullOutStatus make_status(const std::string& vehicle, std::uint64_t request_id, ExecutionState state,
                          std::uint32_t idx = 0) {
  PullOutStatus status;
  status.vehicle_id = vehicle;
  status.request_id = request_id;
  status.state = state;
  status.current_path_idx = idx;
  status.segment_count = 2;
  status.planner_type = PlannerType::kShift;
  return status;
}

TEST(ClientOptionsTest, InvalidOptionsThrow) {
  EXPECT_THROW(Client(options("")), std::invalid_argument);
  EXPECT_THROW(Client(options(std::string(256, 'x'))), std::invalid_argument);
  EXPECT_THROW(Client(options(std::string("a\0b", 3))), std::invalid_argument);
  ClientOptions bad_domain = options("v");
  bad_domain.domain_id = 233;
  EXPECT_THROW(Client{bad_domain}, std::invalid_argument);
  ClientOptions missing_file = options("v");
  missing_file.profiles_file = "/nonexistent/profiles.xml";
  EXPECT_THROW(Client{missing_file}, ClientError);
}

TEST(ClientOptionsTest, ProfilesFileNeedsTheParticipantProfile) {
  const auto file =
      std::filesystem::temp_directory_path() / ("pullout_client_test_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(file) << R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>
  <transport_descriptors><transport_descriptor>
    <transport_id>client_test_udp</transport_id><type>UDPv4</type>
    <interfaceWhiteList><address>127.0.0.1</address></interfaceWhiteList>
  </transport_descriptor></transport_descriptors>
  <participant profile_name="client_test_participant"><rtps>
    <userTransports><transport_id>client_test_udp</transport_id></userTransports>
    <useBuiltinTransports>false</useBuiltinTransports>
  </rtps></participant>
</profiles></dds>)";
  ClientOptions o = options("xml-vehicle");
  o.profiles_file = file.string();
  o.participant_profile = "no_such_profile";
  EXPECT_THROW(Client{o}, ClientError);
  o.participant_profile = "client_test_participant";
  // Loading the same file again (second client in the process) must work too.
  EXPECT_NO_THROW(Client{o});
  EXPECT_NO_THROW(Client{o});
  std::filesystem::remove(file);
}

TEST(ClientTest, RequestReplyRoundTrip) {
  FakeService service;
  Client client(options("car-1"));
  ASSERT_TRUE(client.wait_for_service(10s));
  EXPECT_EQ(client.current_request_id(), 0u);
  EXPECT_FALSE(client.current_segment().has_value());

  std::mutex mutex;
  std::vector<std::uint64_t> path_ids;
  std::vector<ExecutionState> states;
  std::atomic<bool> on_test_thread{false};
  const auto test_thread = std::this_thread::get_id();
  client.on_path([&](const PullOutPath& p) {
    std::lock_guard<std::mutex> lock(mutex);
    if (std::this_thread::get_id() == test_thread) on_test_thread = true;
    path_ids.push_back(p.request_id);
  });
  client.on_status([&](const PullOutStatus& s) {
    std::lock_guard<std::mutex> lock(mutex);
    states.push_back(s.state);
  });

  PullOutRequest request;
  request.vehicle_id = "ignored";
  request.ego_pose = {1.0, 2.0, 0.5};
  const std::uint64_t id = client.send(request);
  EXPECT_GT(id, 0u);
  EXPECT_EQ(client.current_request_id(), id);
  const auto received = service.wait_request("car-1");
  ASSERT_TRUE(received.has_value());
  EXPECT_EQ(received->vehicle_id, "car-1");
  EXPECT_EQ(received->request_id, id);
  EXPECT_GT(received->stamp_ns, 0);
  EXPECT_NEAR(received->ego_pose.yaw, 0.5, 1e-9);

  service.publish(make_status("car-1", id, ExecutionState::kPlanning));
  service.publish(make_path("car-1", id));
  service.publish(make_status("car-1", id, ExecutionState::kExecuting, 1));

  const auto path = client.wait_for_path(id, 5s);
  ASSERT_TRUE(path.has_value());
  EXPECT_EQ(path->partial_paths.size(), 2u);
  const auto status = client.wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kExecuting; }, 5s);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(client.current_segment(), std::optional<std::uint32_t>(1));
  EXPECT_EQ(client.latest_status()->state, ExecutionState::kExecuting);
  EXPECT_TRUE(eventually([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return path_ids.size() == 1 && !states.empty() && states.back() == ExecutionState::kExecuting;
  }));
  EXPECT_FALSE(on_test_thread.load());

  // Progress carries the vehicle and the current request.
  ExecutionProgress progress;
  progress.pose = {3.0, 4.0, 0.0};
  progress.velocity_mps = 1.5;
  client.report_progress(progress);
  const auto got = service.wait_progress("car-1");
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->vehicle_id, "car-1");
  EXPECT_EQ(got->request_id, id);
  EXPECT_GT(got->stamp_ns, 0);
  EXPECT_DOUBLE_EQ(got->velocity_mps, 1.5);

  // A newer request: its id is larger and becomes current; the old segment no longer applies.
  const std::uint64_t id2 = client.send(request);
  EXPECT_GT(id2, id);
  EXPECT_FALSE(client.current_segment().has_value());
}

TEST(ClientTest, OtherVehiclesAreFilteredOut) {
  FakeService service;
  Client client(options("car-2"));
  Client other(options("car-22"));  // shares a prefix
  ASSERT_TRUE(client.wait_for_service(10s));
  ASSERT_TRUE(other.wait_for_service(10s));
  service.publish(make_path("car-22", 5));
  service.publish(make_path("car-2", 6));
  service.publish(make_status("car-22", 5, ExecutionState::kNoPath));
  ASSERT_TRUE(client.wait_for_path(6, 5s).has_value());
  ASSERT_TRUE(other.wait_for_path(5, 5s).has_value());
  EXPECT_FALSE(client.wait_for_path(5, 200ms).has_value());
  EXPECT_EQ(client.latest_path()->vehicle_id, "car-2");
  EXPECT_FALSE(client.latest_status().has_value());
  EXPECT_EQ(other.latest_status()->vehicle_id, "car-22");
}

TEST(ClientTest, LateJoinerGetsLatestPathAndReplayedCallback) {
  FakeService service;
  service.publish(make_path("car-3", 41));
  service.publish(make_status("car-3", 41, ExecutionState::kExecuting, 1));
  Client client(options("car-3"));
  ASSERT_TRUE(eventually([&] { return client.latest_path().has_value() && client.latest_status().has_value(); }));
  EXPECT_EQ(client.latest_path()->request_id, 41u);
  // A restarted client adopts the request it was executing.
  EXPECT_EQ(client.current_request_id(), 41u);
  EXPECT_EQ(client.current_segment(), std::optional<std::uint32_t>(1));

  std::atomic<int> calls{0};
  client.on_path([&](const PullOutPath& p) {
    EXPECT_EQ(p.request_id, 41u);
    ++calls;
  });
  EXPECT_TRUE(eventually([&] { return calls.load() == 1; }));
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(calls.load(), 1);  // replayed once, not again
}

TEST(ClientTest, UnregisteredCallbackIsNeverCalledAgain) {
  FakeService service;
  Client client(options("car-4"));
  ASSERT_TRUE(client.wait_for_service(10s));
  std::atomic<int> calls{0};
  client.on_status([&](const PullOutStatus&) {
    std::this_thread::sleep_for(20ms);  // make a delivery in progress likely
    ++calls;
  });
  for (std::uint32_t i = 0; i < 5; ++i) service.publish(make_status("car-4", 9, ExecutionState::kExecuting, i));
  ASSERT_TRUE(eventually([&] { return calls.load() >= 1; }));
  client.on_status(nullptr);
  const int after = calls.load();
  service.publish(make_status("car-4", 9, ExecutionState::kCompleted, 1));
  ASSERT_TRUE(client.wait_for_status(
      9, [](const PullOutStatus& s) { return s.state == ExecutionState::kCompleted; }, 5s));
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(calls.load(), after);
}

TEST(ClientTest, WaitsTimeOutAndSkipOtherRequests) {
  FakeService service;
  Client client(options("car-5"));
  ASSERT_TRUE(client.wait_for_service(10s));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(client.wait_for_path(123, 150ms).has_value());
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_GE(waited, 150ms);
  EXPECT_LT(waited, 2s);
  service.publish(make_status("car-5", 1, ExecutionState::kExecuting));
  EXPECT_FALSE(client.wait_for_status(2, nullptr, 200ms).has_value());
  EXPECT_TRUE(client.wait_for_status(1, nullptr, 5s).has_value());
  EXPECT_FALSE(client.wait_for_status(
      1, [](const PullOutStatus& s) { return s.state == ExecutionState::kCompleted; }, 100ms));
  // No request yet and no path adopted: progress has nothing to refer to.
  EXPECT_THROW(client.report_progress(ExecutionProgress{}), std::logic_error);
}

TEST(ClientTest, UnboundedWaitReturnsWhenTheReplyArrives) {
  FakeService service;
  Client client(options("car-9"));
  ASSERT_TRUE(client.wait_for_service(10s));
  std::thread publisher([&] {
    std::this_thread::sleep_for(100ms);
    service.publish(make_path("car-9", 5));
  });
  const auto path = client.wait_for_path(5, Client::Duration::max());
  publisher.join();
  ASSERT_TRUE(path.has_value());
  EXPECT_EQ(path->request_id, 5u);
}

TEST(ClientTest, LargePathArrives) {
  FakeService service;
  Client client(options("car-6"));
  ASSERT_TRUE(client.wait_for_service(10s));
  service.publish(make_path("car-6", 77, 2500));  // 5,000 points, a few hundred KB
  const auto path = client.wait_for_path(77, 10s);
  ASSERT_TRUE(path.has_value());
  EXPECT_EQ(path->partial_paths[1].points.size(), 2500u);
}

TEST(ClientTest, RequestIdsIncreaseAcrossClientRestarts) {
  std::uint64_t first = 0;
  {
    Client a(options("car-7"));
    first = a.send(PullOutRequest{});
  }
  Client b(options("car-7"));
  EXPECT_GT(b.send(PullOutRequest{}), first);
}

TEST(ClientTest, NoServiceMeansNoMatch) {
  ClientOptions o = options("car-8");
  o.domain_id = 231;  // no test ever runs a (fake) service there
  Client client(o);
  EXPECT_FALSE(client.wait_for_service(200ms));
}

}  // namespace
}  // namespace pullout
