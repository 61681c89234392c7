// Bad input against the real pullout_service: malformed requests are rejected with the field
// named while other vehicles are served in the same run, and a bad config stops the service at
// start-up with every problem named.
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "integration_support.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;
namespace dds = eprosima::fastdds::dds;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;

class BadInput : public ServiceTest {};

bool is_state(const PullOutStatus& s, ExecutionState state) { return s.state == state; }

// A plain Fast DDS request writer with the QoS of config/dds/loopback.xml (participant profile
// pullout_participant, writer profile pullout_request_writer): what a vehicle stack that does
// not use pullout::Client would run. Sends messages the client library would never produce.
class RawRequestWriter {
 public:
  explicit RawRequestWriter(int domain) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    if (factory->load_XML_profiles_file(loopback_profiles_path()) != ReturnCode::RETCODE_OK) {
      throw std::runtime_error("cannot load " + loopback_profiles_path());
    }
    participant_ = factory->create_participant_with_profile(domain, "pullout_participant");
    if (participant_ == nullptr) throw std::runtime_error("raw writer: no participant");
    dds::TypeSupport type(std::make_unique<msg::PullOutRequestPubSubType>().release());
    type.register_type(participant_);
    dds::Topic* topic = participant_->create_topic("pullout/request", type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    dds::Publisher* publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    if (topic == nullptr || publisher == nullptr) throw std::runtime_error("raw writer: no topic/publisher");
    writer_ = publisher->create_datawriter_with_profile(topic, "pullout_request_writer");
    if (writer_ == nullptr) throw std::runtime_error("raw writer: no writer from profile pullout_request_writer");
  }
  ~RawRequestWriter() {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  RawRequestWriter(const RawRequestWriter&) = delete;
  RawRequestWriter& operator=(const RawRequestWriter&) = delete;

  bool wait_matched(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      dds::PublicationMatchedStatus status;
      writer_->get_publication_matched_status(status);
      if (status.current_count > 0) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }

  // Writes and waits until the service acknowledged it (the writer is volatile: it must stay
  // alive until then).
  bool write(msg::PullOutRequest& sample, int ack_timeout_s = 10) {
    if (!writer_->write(&sample)) return false;
    return writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(ack_timeout_s, 0)) ==
           ReturnCode::RETCODE_OK;
  }

 private:
  dds::DomainParticipant* participant_{nullptr};
  dds::DataWriter* writer_{nullptr};
};

std::int64_t system_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Waits for the REJECTED status of `id` and checks that the reply names `field` (and `words`,
// when given); the path of a rejected request says found = false with the same problems.
void expect_rejected(const Client& client, std::uint64_t id, const std::string& field, const std::string& words = "") {
  const auto status = client.wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kRejected); }, kReplyTimeout);
  ASSERT_TRUE(status) << "no REJECTED status for request " << id;
  EXPECT_NE(status->error.find(field), std::string::npos) << "error does not name " << field << ":\n" << status->error;
  if (!words.empty()) {
    EXPECT_NE(status->error.find(words), std::string::npos) << status->error;
  }
  const auto path = client.wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path) << "no path reply for the rejected request " << id;
  EXPECT_FALSE(path->found);
  ASSERT_FALSE(path->reasons.empty());
  bool named = false;
  for (const auto& r : path->reasons) named = named || r.find(field) != std::string::npos;
  EXPECT_TRUE(named) << "no reason names " << field;
}

void expect_served(const Client& client, std::uint64_t id) {
  const auto path = client.wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path) << client.vehicle_id() << ": no path for request " << id;
  expect_found_path_invariants(*path);
  const auto status = client.wait_for_status(
      id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kWaitingApproval); }, kReplyTimeout);
  EXPECT_TRUE(status) << client.vehicle_id() << ": no WAITING_APPROVAL status for request " << id;
}

TEST_F(BadInput, MalformedRequestsAreRejectedNamingTheFieldWhileOthersAreServed) {
  start_service();
  const Scenario scenario = load_test_scenario("straight_shoulder");
  auto vehicle_a = connect("int-bad-a");
  auto vehicle_b = connect("int-good-b");
  ASSERT_NE(vehicle_a, nullptr);
  ASSERT_NE(vehicle_b, nullptr);

  // A: NaN in the ego pose (caught when the message is converted).
  PullOutRequest nan_request = scenario.request;
  nan_request.ego_pose.x = std::numeric_limits<double>::quiet_NaN();
  const std::uint64_t nan_id = vehicle_a->send(nan_request);
  // B, in the same run, right behind it.
  const std::uint64_t b_first = vehicle_b->send(scenario.request);
  expect_rejected(*vehicle_a, nan_id, "ego_pose");
  expect_served(*vehicle_b, b_first);

  // A: a start pose on no lane (caught by the planner's validation).
  PullOutRequest off_lane = scenario.request;
  off_lane.ego_pose.y = 60.0;
  const std::uint64_t off_lane_id = vehicle_a->send(off_lane);
  expect_rejected(*vehicle_a, off_lane_id, "ego_pose", "no lane");

  // A, over plain DDS: an orientation quaternion of norm 0.5 (the client always writes unit ones).
  RawRequestWriter raw(domain());
  ASSERT_TRUE(raw.wait_matched(std::chrono::duration_cast<std::chrono::milliseconds>(kMatchTimeout)));
  PullOutRequest quaternion_request = scenario.request;
  quaternion_request.vehicle_id = "int-bad-a";
  quaternion_request.request_id = static_cast<std::uint64_t>(system_now_ns());
  quaternion_request.stamp_ns = system_now_ns();
  msg::PullOutRequest sample = idl::to_msg(quaternion_request);
  sample.ego_pose().orientation().x(0.0);
  sample.ego_pose().orientation().y(0.0);
  sample.ego_pose().orientation().z(0.3);
  sample.ego_pose().orientation().w(0.4);
  ASSERT_TRUE(raw.write(sample)) << "the raw request was not written or not acknowledged";
  expect_rejected(*vehicle_a, quaternion_request.request_id, "ego_pose.orientation", "unit quaternion");

  // After all that, both vehicles are served as usual.
  expect_served(*vehicle_b, vehicle_b->send(scenario.request));
  expect_served(*vehicle_a, vehicle_a->send(scenario.request));
}

// [bytes] Resident memory of a process (VmRSS of /proc/<pid>/status); 0 if unreadable.
std::size_t resident_bytes(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stoul(line.substr(6)) * 1024;
  }
  return 0;
}

TEST_F(BadInput, ARequestOverTheReadersPayloadSizeIsDroppedBeforeItIsReceivedWhole) {
  // The request reader's PREALLOCATED memory policy (config/dds/*.xml) fixes its payload size at
  // the type's maximum serialized size (59,963,736 bytes): Fast DDS refuses a larger sample at its
  // first fragment and acknowledges it as irrelevant, so the service never holds it. Before
  // (PREALLOCATED_WITH_REALLOC) the reader grew a payload to the sample's size and took it whole.
  start_service();
  const Scenario scenario = load_test_scenario("straight_shoulder");
  RawRequestWriter raw(domain());
  ASSERT_TRUE(raw.wait_matched(std::chrono::duration_cast<std::chrono::milliseconds>(kMatchTimeout)));
  const std::size_t rss_before = resident_bytes(service().pid());
  ASSERT_GT(rss_before, 0U);

  // About 100 MB of objects: 1,100 objects with 16 predicted paths of 100 poses each.
  PullOutRequest big = scenario.request;
  big.vehicle_id = "int-huge";
  big.request_id = 7;
  big.stamp_ns = system_now_ns();
  msg::PullOutRequest sample = idl::to_msg(big);
  msg::DetectedObject object;
  object.id(1);
  object.predicted_paths().resize(16);
  for (auto& path : object.predicted_paths()) path.path().resize(100);
  sample.objects().assign(1100, object);
  const std::size_t bytes = msg::PullOutRequestPubSubType().getSerializedSizeProvider(&sample)();
  ASSERT_GT(bytes, std::size_t{90} * 1000 * 1000);
  // Acknowledged (as irrelevant) without being received: the writer does not wait for 100 MB.
  ASSERT_TRUE(raw.write(sample, 60)) << "the oversized request was not acknowledged";

  // The same writer's next request (of a normal size) is served: the big one holds nothing back.
  auto huge = connect("int-huge");
  ASSERT_NE(huge, nullptr);
  PullOutRequest normal = big;
  normal.request_id = 8;
  normal.stamp_ns = system_now_ns();
  msg::PullOutRequest normal_sample = idl::to_msg(normal);
  ASSERT_TRUE(raw.write(normal_sample));
  expect_served(*huge, normal.request_id);
  // Another vehicle is served, and the service did not take the 100 MB in.
  auto other = connect("int-after-huge");
  ASSERT_NE(other, nullptr);
  expect_served(*other, other->send(scenario.request));
  const std::size_t rss_after = resident_bytes(service().pid());
  EXPECT_LT(rss_after, rss_before + std::size_t{30} * 1024 * 1024)
      << "service RSS grew from " << rss_before << " to " << rss_after << " bytes for a " << bytes << "-byte request";
}

TEST(ServiceStartup, RefusesABadConfigNamingEveryProblem) {
  TempDir dir;
  const std::string config = dir.write_file("bad.yaml",
                                            "start_planner:\n"
                                            "  th_arrived_distance: 1.0\n"
                                            "  no_such_parameter: 3\n"
                                            "  forward_path_length: -5.0\n"
                                            "dds:\n"
                                            "  profiles_file: " +
                                                loopback_profiles_path() + "\n");
  DomainLease lease;
  ChildProcess service({PULLOUT_SERVICE_EXE, "--config", config, "--domain", std::to_string(lease.domain())},
                       dir.path() + "/stdout", dir.path() + "/stderr");
  const auto exit = service.wait_exit(10s);
  ASSERT_TRUE(exit) << "the service did not exit with a bad config";
  const std::string err = read_file_tail(dir.path() + "/stderr", 10000);
  EXPECT_TRUE(exit->exited) << exit->describe();
  EXPECT_NE(exit->exit_code, 0);
  EXPECT_EQ(exit->exit_code, 1) << "documented exit code of a bad config";
  EXPECT_NE(err.find("no_such_parameter"), std::string::npos) << err;
  EXPECT_NE(err.find("forward_path_length"), std::string::npos) << err;
}

}  // namespace
}  // namespace pullout::integration
