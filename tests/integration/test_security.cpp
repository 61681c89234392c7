// DDS Security: the real pullout_service with credentials (dds.security_dir), real clients and
// raw Fast DDS participants on loopback, a test PKI made by scripts/make-test-pki for this run.
//
//   - an authorised vehicle is planned as without security;
//   - a participant without credentials, or with credentials of a CA nobody trusts, matches
//     nothing: it is not served and reads no one's path;
//   - an authenticated vehicle reads only its own paths, and cannot approve or replace another
//     vehicle's path (its samples for another vehicle id are refused by the service).
//
// Negative checks come with a positive control that happens after the unwanted event would have:
// DDS reliable keeps one writer's order, and the service takes the samples of one reader in
// arrival order, so a forged sample acknowledged by the service is handled before a later genuine
// one; the genuine one's answer bounds the wait.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "integration_support.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/idl/security.hpp"
#include "pullout/idl/topics.hpp"
#include "service_process.hpp"

namespace pullout::integration {
namespace {

namespace dds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;
using namespace std::chrono_literals;

// The credentials of this run (scripts/make-test-pki), made once for the whole test program.
const std::string& pki_dir() {
  static const TempDir dir;
  static const bool made = [] {
    const std::string command =
        "bash '" + source_path("scripts/make-test-pki") + "' '" + dir.path() + "/pki' car-1 car-2 >/dev/null";
    return std::system(command.c_str()) == 0;
  }();
  static const std::string path = made ? dir.path() + "/pki" : std::string();
  return path;
}
std::string vehicle_credentials(const std::string& id) { return pki_dir() + "/vehicles/" + id; }
std::string intruder_credentials() { return pki_dir() + "/intruder"; }

// A raw participant on the service's domain, with or without credentials, whose publisher and
// subscriber are in `partition` (none when empty). Entities its permissions do not grant are not
// created (null), which the tests check.
class RawParticipant {
 public:
  RawParticipant(int domain, const std::string& security_dir, const std::string& partition) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    EXPECT_EQ(factory->load_XML_profiles_file(loopback_profiles_path()), ReturnCode_t::RETCODE_OK);
    dds::DomainParticipantQos qos;
    EXPECT_EQ(factory->get_participant_qos_from_profile("pullout_participant", qos), ReturnCode_t::RETCODE_OK);
    if (!security_dir.empty()) idl::add_security_properties(security_dir, qos);
    participant_ = factory->create_participant(domain, qos);
    if (participant_ == nullptr) return;
    const auto topic = [this](const char* name, dds::TopicDataType* type) {
      dds::TypeSupport support(type);
      support.register_type(participant_);
      return participant_->create_topic(name, support.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    };
    request_topic_ = topic(idl::kRequestTopic, idl::make_guarded_type<msg::PullOutRequestPubSubType>());
    progress_topic_ = topic(idl::kProgressTopic, idl::make_guarded_type<msg::ExecutionProgressPubSubType>());
    path_topic_ = topic(idl::kPathTopic, idl::make_guarded_type<msg::PullOutPathPubSubType>());
    dds::PublisherQos publisher_qos = dds::PUBLISHER_QOS_DEFAULT;
    dds::SubscriberQos subscriber_qos = dds::SUBSCRIBER_QOS_DEFAULT;
    if (!partition.empty()) {
      publisher_qos.partition().push_back(partition.c_str());
      subscriber_qos.partition().push_back(partition.c_str());
    }
    publisher_ = participant_->create_publisher(publisher_qos);
    subscriber_ = participant_->create_subscriber(subscriber_qos);
    request_writer_ = publisher_->create_datawriter_with_profile(request_topic_, idl::kRequestWriterProfile);
    progress_writer_ = publisher_->create_datawriter_with_profile(progress_topic_, idl::kProgressWriterProfile);
    dds::DataReaderQos reader_qos;
    subscriber_->get_datareader_qos_from_profile(idl::kPathReaderProfile, reader_qos);
    reader_qos.history().depth = 64;  // keep every path of every vehicle this reader gets
    reader_qos.resource_limits().max_samples_per_instance = 64;
    reader_qos.resource_limits().max_instances = 64;
    reader_qos.resource_limits().max_samples = 64 * 64;
    path_reader_ = subscriber_->create_datareader(path_topic_, reader_qos);
  }
  ~RawParticipant() {
    if (participant_ == nullptr) return;
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  RawParticipant(const RawParticipant&) = delete;
  RawParticipant& operator=(const RawParticipant&) = delete;

  bool has_participant() const { return participant_ != nullptr; }
  bool has_writers() const { return request_writer_ != nullptr && progress_writer_ != nullptr; }
  bool has_path_reader() const { return path_reader_ != nullptr; }

  // Whether both writers matched a reader (the service's), within `timeout`.
  bool wait_writers_matched(std::chrono::milliseconds timeout) const {
    const auto until = std::chrono::steady_clock::now() + timeout;
    do {
      dds::PublicationMatchedStatus requests;
      dds::PublicationMatchedStatus progress;
      request_writer_->get_publication_matched_status(requests);
      progress_writer_->get_publication_matched_status(progress);
      if (requests.current_count > 0 && progress.current_count > 0) return true;
      std::this_thread::sleep_for(20ms);
    } while (std::chrono::steady_clock::now() < until);
    return false;
  }

  // Writes and waits until every matched reader acknowledged the sample.
  bool write_acknowledged(const PullOutRequest& request) {
    msg::PullOutRequest sample = idl::to_msg(request);
    return request_writer_->write(&sample) &&
           request_writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(10, 0)) == ReturnCode_t::RETCODE_OK;
  }
  bool write_acknowledged(const ExecutionProgress& progress) {
    msg::ExecutionProgress sample = idl::to_msg(progress);
    return progress_writer_->write(&sample) && progress_writer_->wait_for_acknowledgments(
                                                   eprosima::fastrtps::Duration_t(10, 0)) == ReturnCode_t::RETCODE_OK;
  }

  // The vehicle ids of the paths received so far (taken: each id once per sample).
  std::vector<std::string> take_path_vehicles() {
    std::vector<std::string> ids;
    msg::PullOutPath sample;
    dds::SampleInfo info;
    while (path_reader_->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) ids.push_back(sample.vehicle_id());
    }
    return ids;
  }

 private:
  dds::DomainParticipant* participant_{nullptr};
  dds::Topic* request_topic_{nullptr};
  dds::Topic* progress_topic_{nullptr};
  dds::Topic* path_topic_{nullptr};
  dds::Publisher* publisher_{nullptr};
  dds::Subscriber* subscriber_{nullptr};
  dds::DataWriter* request_writer_{nullptr};
  dds::DataWriter* progress_writer_{nullptr};
  dds::DataReader* path_reader_{nullptr};
};

// What a client received, in order.
struct Received {
  std::mutex mutex;
  std::vector<std::uint64_t> path_ids;
  std::vector<std::pair<std::uint64_t, ExecutionState>> statuses;

  void attach(Client& client) {
    client.on_path([this](const PullOutPath& p) {
      std::lock_guard<std::mutex> lock(mutex);
      path_ids.push_back(p.request_id);
    });
    client.on_status([this](const PullOutStatus& s) {
      std::lock_guard<std::mutex> lock(mutex);
      statuses.emplace_back(s.request_id, s.state);
    });
  }
  bool saw_path(std::uint64_t id) {
    std::lock_guard<std::mutex> lock(mutex);
    return std::find(path_ids.begin(), path_ids.end(), id) != path_ids.end();
  }
  bool saw_status(std::uint64_t id) {
    std::lock_guard<std::mutex> lock(mutex);
    return std::any_of(statuses.begin(), statuses.end(), [id](const auto& s) { return s.first == id; });
  }
  std::vector<ExecutionState> states_of(std::uint64_t id) {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<ExecutionState> out;
    for (const auto& s : statuses) {
      if (s.first == id) out.push_back(s.second);
    }
    return out;
  }
};

class SecurityTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(pki_dir().empty()) << "scripts/make-test-pki failed";
    const std::string config = temp_.write_file("secure.yaml", "dds:\n  profiles_file: " + loopback_profiles_path() +
                                                                   "\n  security_dir: " + pki_dir() + "/service\n");
    ServiceOptions options;
    options.executable = PULLOUT_SERVICE_EXE;
    options.config_path = config;
    options.probe_security_dir = vehicle_credentials("car-2");
    options.probe_vehicle_id = "car-2";
    try {
      service_.emplace(options);
    } catch (const std::exception& e) {
      FAIL() << e.what();
    }
  }
  void TearDown() override {
    if (!service_) return;
    const StopReport report = service_->stop();
    EXPECT_TRUE(report.clean()) << report.describe();
  }

  std::unique_ptr<Client> secure_client(const std::string& vehicle) {
    ClientOptions options;
    options.vehicle_id = vehicle;
    options.domain_id = service_->domain();
    options.security_dir = vehicle_credentials(vehicle);
    auto client = std::make_unique<Client>(options);
    EXPECT_TRUE(client->wait_for_service(kMatchTimeout)) << vehicle << " did not match the secure service";
    return client;
  }

  // Sends the straight-shoulder scenario's request and waits for its (found) path.
  std::uint64_t plan(Client& client) {
    const std::uint64_t id = client.send(load_test_scenario("straight_shoulder").request);
    const auto path = client.wait_for_path(id, kReplyTimeout);
    EXPECT_TRUE(path.has_value() && path->found) << "no path for request " << id;
    return id;
  }

  TempDir temp_;
  std::optional<ServiceProcess> service_;
};

TEST_F(SecurityTest, AuthorisedVehicleIsPlanned) {
  auto car1 = secure_client("car-1");
  const std::uint64_t id = car1->send(load_test_scenario("straight_shoulder").request);
  const auto path = car1->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path.has_value());
  expect_found_path_invariants(*path);
  const auto status = car1->wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout);
  EXPECT_TRUE(status.has_value());
}

// Without credentials, or with credentials from an untrusted CA: nothing matches, nothing is
// served, nothing is read. The positive control: a vehicle with credentials, started after them,
// matches and is planned meanwhile.
TEST_F(SecurityTest, ParticipantWithoutTrustedCredentialsGetsNothing) {
  RawParticipant plain(service_->domain(), "", "car-1");
  RawParticipant intruder(service_->domain(), intruder_credentials(), "car-1");
  ASSERT_TRUE(plain.has_participant() && plain.has_writers() && plain.has_path_reader());
  ASSERT_TRUE(intruder.has_participant() && intruder.has_writers() && intruder.has_path_reader())
      << "the intruder's own (self-signed) permissions grant it car-1 locally";

  auto car1 = secure_client("car-1");
  Received received;
  received.attach(*car1);
  const std::uint64_t id = plan(*car1);
  EXPECT_FALSE(plain.wait_writers_matched(0ms));
  EXPECT_FALSE(intruder.wait_writers_matched(0ms));
  EXPECT_TRUE(plain.take_path_vehicles().empty()) << "a participant without credentials read a path";
  EXPECT_TRUE(intruder.take_path_vehicles().empty()) << "an untrusted participant read a path";
  // A plain client cannot even find the service (its endpoints are invisible to it).
  ClientOptions options;
  options.vehicle_id = "car-1";
  options.domain_id = service_->domain();
  Client unauthenticated(options);
  EXPECT_FALSE(unauthenticated.wait_for_service(0ms));
  EXPECT_TRUE(received.saw_path(id));
}

// car-2's credentials grant it only partition car-2: it cannot even create a reader in car-1's,
// and the reader in its own partition gets car-2's paths and never car-1's.
TEST_F(SecurityTest, AuthenticatedVehicleReadsOnlyItsOwnPaths) {
  RawParticipant spy_elsewhere(service_->domain(), vehicle_credentials("car-2"), "car-1");
  ASSERT_TRUE(spy_elsewhere.has_participant());
  EXPECT_FALSE(spy_elsewhere.has_path_reader()) << "car-2's permissions must not grant partition car-1";
  EXPECT_FALSE(spy_elsewhere.has_writers());

  RawParticipant spy(service_->domain(), vehicle_credentials("car-2"), "car-2");
  ASSERT_TRUE(spy.has_participant() && spy.has_path_reader());
  auto car1 = secure_client("car-1");
  auto car2 = secure_client("car-2");
  plan(*car1);
  plan(*car2);  // after car-1's path was published
  std::vector<std::string> seen;
  const auto until = std::chrono::steady_clock::now() + kReplyTimeout;
  while (std::find(seen.begin(), seen.end(), "car-2") == seen.end() && std::chrono::steady_clock::now() < until) {
    for (auto& id : spy.take_path_vehicles()) seen.push_back(id);
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_NE(std::find(seen.begin(), seen.end(), "car-2"), seen.end()) << "car-2's reader never got its own path";
  EXPECT_EQ(std::count(seen.begin(), seen.end(), "car-1"), 0) << "car-2 read car-1's path";
}

// car-2, authenticated, writes (in its own partition, as its permissions allow) an approval and a
// new request in car-1's name: the service refuses both.
TEST_F(SecurityTest, AuthenticatedVehicleCannotApproveOrReplaceAnothersPath) {
  auto car1 = secure_client("car-1");
  Received received;
  received.attach(*car1);
  const Scenario scenario = load_test_scenario("straight_shoulder");
  const std::uint64_t planned = plan(*car1);
  ASSERT_TRUE(car1->wait_for_status(
      planned, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout));

  RawParticipant forger(service_->domain(), vehicle_credentials("car-2"), "car-2");
  ASSERT_TRUE(forger.has_writers());
  ASSERT_TRUE(forger.wait_writers_matched(kMatchTimeout)) << "car-2's writers must match the service's readers";
  const auto now_ns = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
        .count();
  };
  ExecutionProgress approval = progress_sample(planned, now_ns(), scenario.request.ego_pose, 0.0, true);
  approval.vehicle_id = "car-1";
  ASSERT_TRUE(forger.write_acknowledged(approval));
  PullOutRequest replacement = scenario.request;
  replacement.vehicle_id = "car-1";
  replacement.request_id = planned + 1000;
  ASSERT_TRUE(forger.write_acknowledged(replacement));

  // car-1 itself, after the forged samples (same readers, so handled after them): a progress
  // sample that does not approve, then a new request.
  ExecutionProgress own = progress_sample(planned, now_ns(), scenario.request.ego_pose, 0.0, false);
  car1->report_progress(own);
  const std::uint64_t next = car1->send(scenario.request);
  ASSERT_TRUE(car1->wait_for_path(next, kReplyTimeout).has_value());
  EXPECT_FALSE(received.saw_path(replacement.request_id)) << "car-2 replaced car-1's path";
  EXPECT_FALSE(received.saw_status(replacement.request_id));
  // Had the forged approval been taken, car-1 would have left kWaitingApproval (and come back to
  // it with its own sample that withdraws the approval).
  for (const ExecutionState state : received.states_of(planned)) {
    EXPECT_TRUE(state == ExecutionState::kPlanning || state == ExecutionState::kWaitingApproval)
        << "car-1's path changed state on car-2's approval: " << static_cast<int>(state);
  }
}

}  // namespace
}  // namespace pullout::integration
