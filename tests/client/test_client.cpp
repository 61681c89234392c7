// pullout::Client against a fake service made of plain Fast DDS entities (loopback only, a domain
// of its own per test process): requests and progress arrive with the client's fields filled,
// replies of other vehicles are filtered out, late joiners get the latest path, callbacks run on
// the client's thread with no internal lock held, undecodable replies are dropped, waits time out.
//
// Negative checks never follow a sleep: each one is made after a later sample on the same writer
// (reliable DDS keeps a writer's order) has been seen, so the unwanted delivery would have come first.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
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

// Type support that writes an undecodable sample for request id kUndecodableRequestId (the fields
// up to the first boolean, then a byte of 2 where CDR allows only 0 and 1, and the end of the
// payload: fastcdr throws BadParamException, which the generated deserialize() does not catch),
// and the generated encoding for any other sample.
constexpr std::uint64_t kUndecodableRequestId = 666;

template <typename Generated, typename Msg>
class UndecodableAt666 : public Generated {
 public:
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const Msg& sample = *static_cast<const Msg*>(data);
    if (sample.request_id() != kUndecodableRequestId) return Generated::serialize(data, payload);
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload->data), payload->max_size);
    eprosima::fastcdr::Cdr ser(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    payload->encapsulation = ser.endianness() == eprosima::fastcdr::Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
    ser.serialize_encapsulation();
    ser << sample.vehicle_id() << sample.request_id() << sample.stamp().sec() << sample.stamp().nanosec();
    write_fields_before_first_boolean(ser, sample);
    ser << std::uint8_t{2};
    payload->length = static_cast<std::uint32_t>(ser.getSerializedDataLength());
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    const Msg& sample = *static_cast<const Msg*>(data);
    if (sample.request_id() == kUndecodableRequestId) return [] { return 1024u; };
    return Generated::getSerializedSizeProvider(data);
  }

 private:
  // PullOutPath: `found` comes first.
  static void write_fields_before_first_boolean(eprosima::fastcdr::Cdr& /*ser*/, const msg::PullOutPath& /*path*/) {}
  // PullOutStatus: state, current_path_idx, segment_count, planner_type, evaluation_table (empty),
  // stop_reason, error, planning_time_ms, then `safe`.
  static void write_fields_before_first_boolean(eprosima::fastcdr::Cdr& ser, const msg::PullOutStatus& status) {
    ser << static_cast<std::uint32_t>(status.state()) << status.current_path_idx() << status.segment_count()
        << static_cast<std::uint32_t>(status.planner_type()) << std::uint32_t{0} << status.stop_reason()
        << status.error() << status.planning_time_ms();
  }
};

// Path and status writers of a participant of their own (a participant registers one type per
// type name), with the undecodable type support above. History depth 8: an undecodable sample is
// not replaced in the writer's history by the good one written after it.
class UndecodingService {
 public:
  UndecodingService() {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    participant_ = factory->create_participant(test_domain(), client_detail::loopback_participant_qos());
    if (participant_ == nullptr) throw std::runtime_error("undecoding service: no participant");
    const auto topic = [this](dds::TopicDataType* type, const char* name) {
      dds::TypeSupport support(type);
      support.register_type(participant_);
      return participant_->create_topic(name, support.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    };
    dds::Topic* path = topic(
        std::make_unique<UndecodableAt666<msg::PullOutPathPubSubType, msg::PullOutPath>>().release(), "pullout/path");
    dds::Topic* status =
        topic(std::make_unique<UndecodableAt666<msg::PullOutStatusPubSubType, msg::PullOutStatus>>().release(),
              "pullout/status");
    auto* publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    dds::DataWriterQos wq;
    wq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    wq.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    wq.history().depth = 8;
    path_writer_ = publisher->create_datawriter(path, wq);
    status_writer_ = publisher->create_datawriter(status, wq);
    if (!path_writer_ || !status_writer_) throw std::runtime_error("undecoding service: endpoints");
  }
  ~UndecodingService() {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  UndecodingService(const UndecodingService&) = delete;
  UndecodingService& operator=(const UndecodingService&) = delete;

  bool matched() const {
    dds::PublicationMatchedStatus path;
    dds::PublicationMatchedStatus status;
    path_writer_->get_publication_matched_status(path);
    status_writer_->get_publication_matched_status(status);
    return path.current_count > 0 && status.current_count > 0;
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
  // State the callbacks capture is declared before the client: it must outlive the client's
  // thread (client.hpp, "Lifetime").
  std::mutex mutex;
  std::vector<std::uint64_t> path_ids;
  std::vector<ExecutionState> states;
  std::atomic<bool> on_test_thread{false};
  const auto test_thread = std::this_thread::get_id();
  Client client(options("car-1"));
  ASSERT_TRUE(client.wait_for_service(10s));
  EXPECT_EQ(client.current_request_id(), 0u);
  EXPECT_FALSE(client.current_segment().has_value());

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
  std::mutex mutex;
  std::vector<std::string> path_vehicles;
  std::vector<std::string> status_vehicles;
  client.on_path([&](const PullOutPath& p) {
    std::lock_guard<std::mutex> lock(mutex);
    path_vehicles.push_back(p.vehicle_id);
  });
  client.on_status([&](const PullOutStatus& s) {
    std::lock_guard<std::mutex> lock(mutex);
    status_vehicles.push_back(s.vehicle_id);
  });
  // car-22's samples go first on each writer: by the time car-2's arrive, theirs would have too.
  service.publish(make_path("car-22", 5));
  service.publish(make_path("car-2", 6));
  service.publish(make_status("car-22", 5, ExecutionState::kNoPath));
  service.publish(make_status("car-2", 6, ExecutionState::kExecuting));
  ASSERT_TRUE(client.wait_for_status(6, nullptr, 5s).has_value());
  ASSERT_TRUE(client.wait_for_path(6, 5s).has_value());
  ASSERT_TRUE(other.wait_for_path(5, 5s).has_value());
  ASSERT_TRUE(other.wait_for_status(5, nullptr, 5s).has_value());
  EXPECT_FALSE(client.wait_for_path(5, 0ms).has_value());
  EXPECT_FALSE(client.wait_for_status(5, nullptr, 0ms).has_value());
  EXPECT_EQ(client.latest_path()->vehicle_id, "car-2");
  EXPECT_EQ(client.latest_status()->vehicle_id, "car-2");
  EXPECT_EQ(other.latest_status()->vehicle_id, "car-22");
  // Callbacks run in arrival order on one thread: once they have seen car-2's samples, they have
  // seen everything that was delivered before.
  ASSERT_TRUE(eventually([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return !path_vehicles.empty() && !status_vehicles.empty();
  }));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(path_vehicles, std::vector<std::string>{"car-2"});
  EXPECT_EQ(status_vehicles, std::vector<std::string>{"car-2"});
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

  std::mutex mutex;
  std::vector<std::uint64_t> seen;
  client.on_path([&](const PullOutPath& p) {
    std::lock_guard<std::mutex> lock(mutex);
    seen.push_back(p.request_id);
  });
  ASSERT_TRUE(eventually([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return !seen.empty();
  }));
  // The next path: once it is delivered, a second replay of 41 would have come before it.
  service.publish(make_path("car-3", 42));
  ASSERT_TRUE(eventually([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return seen.back() == 42u;
  }));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{41, 42}));  // replayed once, then the new one
}

TEST(ClientTest, UnregisteredCallbackIsNeverCalledAgain) {
  FakeService service;
  std::atomic<int> calls{0};
  std::atomic<bool> unregistered{false};
  std::atomic<int> calls_after_unregister{0};
  std::atomic<bool> completed{false};
  Client client(options("car-4"));
  ASSERT_TRUE(client.wait_for_service(10s));
  client.on_status([&](const PullOutStatus&) {
    if (unregistered.load()) ++calls_after_unregister;
    std::this_thread::sleep_for(20ms);  // make a delivery in progress likely
    if (unregistered.load()) ++calls_after_unregister;
    ++calls;
  });
  for (std::uint32_t i = 0; i < 5; ++i) service.publish(make_status("car-4", 9, ExecutionState::kExecuting, i));
  ASSERT_TRUE(eventually([&] { return calls.load() >= 1; }));
  client.on_status(nullptr);
  unregistered = true;
  // A later status, delivered to a new callback: the old one would have run before it.
  client.on_status([&](const PullOutStatus& s) {
    if (s.state == ExecutionState::kCompleted) completed = true;
  });
  service.publish(make_status("car-4", 9, ExecutionState::kCompleted, 1));
  ASSERT_TRUE(eventually([&] { return completed.load(); }));
  EXPECT_EQ(calls_after_unregister.load(), 0);
}

// client.hpp: callbacks run with no internal lock held. A callback that waits for another thread
// which uses the client (here: registers the status callback) must not deadlock.
TEST(ClientTest, CallbackMayWaitForAnotherThreadUsingTheClient) {
  FakeService service;
  std::promise<bool> verdict;
  std::future<bool> verdict_ready = verdict.get_future();
  std::thread helper;
  std::atomic<int> status_calls{0};
  Client client(options("car-10"));
  ASSERT_TRUE(client.wait_for_service(10s));
  client.on_path([&](const PullOutPath&) {
    if (helper.joinable()) return;
    auto registered = std::make_shared<std::promise<void>>();
    std::future<void> done = registered->get_future();
    helper = std::thread([&client, &status_calls, registered] {
      client.on_status([&status_calls](const PullOutStatus&) { ++status_calls; });
      registered->set_value();
    });
    // Bounded, so that a deadlock fails the test instead of hanging it; the helper is joined by
    // the test thread once this callback has returned.
    verdict.set_value(done.wait_for(3s) == std::future_status::ready);
  });
  service.publish(make_path("car-10", 3));
  ASSERT_EQ(verdict_ready.wait_for(10s), std::future_status::ready) << "the path callback never ran";
  EXPECT_TRUE(verdict_ready.get()) << "on_status from another thread blocked while a path callback ran";
  helper.join();
  // The callback the helper registered works.
  service.publish(make_status("car-10", 3, ExecutionState::kExecuting));
  EXPECT_TRUE(eventually([&] { return status_calls.load() >= 1; }));
}

// A callback may call the client's member functions: send, report_progress, the queries, and
// on_path / on_status (which then take effect for the next delivery).
TEST(ClientTest, CallbackMayCallTheClient) {
  FakeService service;
  std::atomic<std::uint64_t> sent{0};
  std::atomic<int> replaced_calls{0};
  std::atomic<bool> returned{false};
  Client client(options("car-11"));
  ASSERT_TRUE(client.wait_for_service(10s));
  client.on_path([&](const PullOutPath& p) {
    if (p.request_id != 3) return;
    sent = client.send(PullOutRequest{});
    client.report_progress(ExecutionProgress{});
    (void)client.latest_path();
    (void)client.current_segment();
    client.on_path([&](const PullOutPath&) { ++replaced_calls; });
    returned = true;
  });
  service.publish(make_path("car-11", 3));
  ASSERT_TRUE(eventually([&] { return returned.load(); }));
  const auto request = service.wait_request("car-11");
  ASSERT_TRUE(request.has_value());
  EXPECT_EQ(request->request_id, sent.load());
  const auto progress = service.wait_progress("car-11");
  ASSERT_TRUE(progress.has_value());
  EXPECT_EQ(progress->request_id, sent.load());
  service.publish(make_path("car-11", 4));
  EXPECT_TRUE(eventually([&] { return replaced_calls.load() >= 1; }));
}

// Undecodable replies (an invalid boolean byte) are dropped; the client goes on and
// receives the next good sample of the same writer.
TEST(ClientTest, UndecodableRepliesAreDroppedAndTheNextArrive) {
  UndecodingService service;
  Client client(options("car-12"));
  ASSERT_TRUE(eventually([&] { return service.matched(); }, 10000ms));
  service.publish(make_path("car-12", kUndecodableRequestId));
  service.publish(make_path("car-12", 7));
  service.publish(make_status("car-12", kUndecodableRequestId, ExecutionState::kExecuting));
  service.publish(make_status("car-12", 7, ExecutionState::kExecuting));
  ASSERT_TRUE(client.wait_for_path(7, 10s).has_value());
  ASSERT_TRUE(client.wait_for_status(7, nullptr, 10s).has_value());
  EXPECT_FALSE(client.wait_for_path(kUndecodableRequestId, 0ms).has_value());
  EXPECT_FALSE(client.wait_for_status(kUndecodableRequestId, nullptr, 0ms).has_value());
}

TEST(ClientTest, WaitsTimeOutAndSkipOtherRequests) {
  FakeService service;
  Client client(options("car-5"));
  ASSERT_TRUE(client.wait_for_service(10s));
  // The contract of a timeout: not before it expires (steady clock; no upper bound asserted).
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(client.wait_for_path(123, 150ms).has_value());
  EXPECT_GE(std::chrono::steady_clock::now() - start, 150ms);
  service.publish(make_status("car-5", 1, ExecutionState::kExecuting));
  ASSERT_TRUE(client.wait_for_status(1, nullptr, 5s).has_value());
  // Received, and for request 1: a wait for another request does not take it.
  EXPECT_FALSE(client.wait_for_status(2, nullptr, 100ms).has_value());
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

// --- re-sending and a lost service ---

TEST(ClientRetryTest, AnUnansweredRequestIsResentUnchangedUntilAnswered) {
  FakeService service;
  ClientOptions o = options("car-20");
  o.resend_period = std::chrono::milliseconds(100);
  Client client(o);
  ASSERT_TRUE(client.wait_for_service(10s));
  const std::uint64_t id = client.send(PullOutRequest{});
  const auto first = service.wait_request("car-20");
  ASSERT_TRUE(first.has_value());
  // Nothing answered: the same sample comes again.
  const auto again = service.wait_request("car-20");
  ASSERT_TRUE(again.has_value()) << "the unanswered request was not re-sent";
  EXPECT_EQ(again->request_id, id);
  EXPECT_EQ(again->stamp_ns, first->stamp_ns);
  // planning does not answer it (the service may die before the search ends)...
  service.publish(make_status("car-20", id, ExecutionState::kPlanning));
  ASSERT_TRUE(client.wait_for_status(id, nullptr, 5s).has_value());
  ASSERT_TRUE(service.wait_request("car-20").has_value());
  ASSERT_TRUE(service.wait_request("car-20").has_value());
  // ...the path does.
  service.publish(make_path("car-20", id));
  ASSERT_TRUE(client.wait_for_path(id, 5s).has_value());
  EXPECT_EQ(client.current_request_id(), id);
}

TEST(ClientRetryTest, ARequestSentBeforeTheServiceExistedReachesItWhenItAppears) {
  ClientOptions o = options("car-21");
  Client client(o);
  const std::uint64_t id = client.send(PullOutRequest{});  // no reader yet: a volatile write is lost
  FakeService service;
  const auto got = service.wait_request("car-21", 10000ms);
  ASSERT_TRUE(got.has_value()) << "the request was not re-sent to the service that appeared";
  EXPECT_EQ(got->request_id, id);
  service.publish(make_path("car-21", id));
  EXPECT_TRUE(client.wait_for_path(id, 5s).has_value());
}

TEST(ClientRetryTest, APlanningStatusOfALostServiceIsNeverReported) {
  auto service = std::make_unique<FakeService>();
  // The request must still be re-sent when the next service appears, however slow the steps
  // before are (the sanitizer build): a window well beyond the waits below.
  ClientOptions o = options("car-22");
  o.resend_window = std::chrono::milliseconds(60000);
  Client client(o);
  ASSERT_TRUE(client.wait_for_service(10s));
  EXPECT_EQ(client.service_state(), ServiceState::kConnected);
  const std::uint64_t id = client.send(PullOutRequest{});
  service->publish(make_status("car-22", id, ExecutionState::kPlanning));
  ASSERT_TRUE(client.wait_for_status(id, nullptr, 5s).has_value());
  ASSERT_TRUE(client.latest_status().has_value());
  service.reset();  // deleted: its endpoints unmatch at once
  ASSERT_TRUE(eventually([&] { return !client.latest_status().has_value(); }, 5000ms))
      << "latest_status() still says " << static_cast<int>(client.latest_status()->state) << " from a lost service";
  EXPECT_EQ(client.service_state(), ServiceState::kLost);
  EXPECT_FALSE(client.wait_for_status(id, nullptr, 0ms).has_value());
  // The next service answers the re-sent request: its statuses are reported again.
  FakeService next;
  ASSERT_TRUE(next.wait_request("car-22", 10000ms).has_value());
  next.publish(make_status("car-22", id, ExecutionState::kPlanning));
  ASSERT_TRUE(client.wait_for_status(id, nullptr, 5s).has_value());
  EXPECT_EQ(client.latest_status()->state, ExecutionState::kPlanning);
  EXPECT_EQ(client.service_state(), ServiceState::kConnected);
}

TEST(ClientRetryTest, AWaitNothingCanAnswerReturnsWhenTheServiceIsLost) {
  auto service = std::make_unique<FakeService>();
  ClientOptions o = options("car-23");
  Client client(o);
  ASSERT_TRUE(client.wait_for_service(10s));
  const std::uint64_t id = client.send(PullOutRequest{});
  service->publish(make_path("car-23", id));
  service->publish(make_status("car-23", id, ExecutionState::kWaitingApproval));
  ASSERT_TRUE(client.wait_for_status(id, nullptr, 5s).has_value());
  // Answered: it is not re-sent, so once the service is gone nothing can bring `executing`.
  std::thread stopper([&] {
    std::this_thread::sleep_for(200ms);
    service.reset();
  });
  const auto start = std::chrono::steady_clock::now();
  const auto executing = client.wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kExecuting; }, 30s);
  const auto waited = std::chrono::steady_clock::now() - start;
  stopper.join();
  EXPECT_FALSE(executing.has_value());
  EXPECT_LT(waited, 10s) << "the wait ran to its timeout";
  EXPECT_EQ(client.service_state(), ServiceState::kLost);
  // The path and the last status are kept (only planning is stale).
  EXPECT_TRUE(client.latest_path().has_value());
  ASSERT_TRUE(client.latest_status().has_value());
  EXPECT_EQ(client.latest_status()->state, ExecutionState::kWaitingApproval);
}

TEST(ClientRetryTest, AWaitForAnUnansweredRequestEndsWithItsResendWindowWhenTheServiceIsLost) {
  auto service = std::make_unique<FakeService>();
  ClientOptions o = options("car-25");
  o.resend_window = std::chrono::milliseconds(1500);
  Client client(o);
  ASSERT_TRUE(client.wait_for_service(10s));
  const std::uint64_t id = client.send(PullOutRequest{});
  ASSERT_TRUE(service->wait_request("car-25").has_value());
  service.reset();  // lost with the request unanswered: re-sent (to no one) until the window ends
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(client.wait_for_path(id, 30s).has_value());
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s) << "the wait ran to its timeout";
  EXPECT_EQ(client.service_state(), ServiceState::kLost);
}

TEST(ClientOptionsTest, InvalidResendOptionsThrow) {
  ClientOptions o = options("car-24");
  o.resend_period = std::chrono::milliseconds(0);
  EXPECT_THROW(Client{o}, std::invalid_argument);
  o = options("car-24");
  o.resend_window = std::chrono::milliseconds(-1);
  EXPECT_THROW(Client{o}, std::invalid_argument);
}

// A vehicle with replicas of the service waits until each reads its requests (a request sent
// before a replica matched never reaches it): one service is not two.
TEST(ClientTest, WaitsForAsManyServicesAsAsked) {
  Client client(options("car-9"));
  FakeService first;
  ASSERT_TRUE(client.wait_for_services(1, 10s));
  EXPECT_EQ(client.matched_services(), 1u);
  EXPECT_FALSE(client.wait_for_services(2, 300ms));
  FakeService second;
  ASSERT_TRUE(client.wait_for_services(2, 10s));
  EXPECT_EQ(client.matched_services(), 2u);
}

TEST(ClientTest, NoServiceMeansNoMatch) {
  ClientOptions o = options("car-8");
  o.domain_id = 231;  // no test ever runs a (fake) service there
  Client client(o);
  EXPECT_FALSE(client.wait_for_service(200ms));
  EXPECT_EQ(client.service_state(), ServiceState::kNotFound);
}

}  // namespace
}  // namespace pullout
