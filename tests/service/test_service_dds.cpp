// Integration test of pullout_service over real DDS on loopback.
//
// Starts the real pullout_service process (config/pullout.yaml, config/dds/loopback.xml) on a
// domain of its own, talks to it with plain Fast DDS entities built from the same XML profiles,
// and checks the messages that come back: paths, statuses, execution progress, rejections, many
// vehicles at once, and a clean exit on SIGTERM.
//
// Negative checks never follow a sleep: the unwanted sample would come before a later one that the
// test waits for (DDS reliable keeps each writer's order; the service handles the samples of a
// reader in arrival order on one thread and publishes from there, or from the one job a vehicle
// runs at a time). The test client's readers keep 64 samples per vehicle so nothing is overwritten
// before the test looks.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

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
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pullout/config/scenario.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/model/names.hpp"
#include "service_process.hpp"  // DomainLease, ServiceProcess

namespace pullout {
namespace {

namespace dds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;
using Clock = std::chrono::steady_clock;

const std::string kSourceDir = PULLOUT_SOURCE_DIR;
const std::string kServiceBinary = PULLOUT_SERVICE_BIN;
const std::string kProfiles = kSourceDir + "/config/dds/loopback.xml";
constexpr auto kReplyTimeout = std::chrono::seconds(10);

// ---- the service process -----------------------------------------------------------------------

class ServiceChild {
 public:
  void start(int domain) {
    const std::string config = kSourceDir + "/config/pullout.yaml";
    const std::string domain_text = std::to_string(domain);
    std::vector<std::string> args{kServiceBinary, "--config", config, "--domain", domain_text, "--log-level", "warn"};
    std::vector<char*> argv;
    argv.reserve(args.size() + 1);
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ASSERT_EQ(posix_spawn(&pid_, kServiceBinary.c_str(), nullptr, nullptr, argv.data(), environ), 0);
  }

  // SIGTERM, then the exit status (or -1 if it had to be killed or was killed by a signal).
  // Idempotent: once the child is reaped (here or by running()) its exit status is returned.
  int stop(std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) {
    if (pid_ <= 0) return exit_code_;
    ::kill(pid_, SIGTERM);
    const auto until = Clock::now() + timeout;
    int status = 0;
    while (Clock::now() < until) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) return reaped(status);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
    pid_ = 0;
    return exit_code_;
  }

  pid_t pid() const { return pid_; }

  // User + system CPU time of the process so far [s].
  double cpu_seconds() const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/stat");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // Fields after the command name (which may contain spaces) start after the last ')'.
    std::istringstream fields(text.substr(text.rfind(')') + 2));
    std::string field;
    double ticks = 0.0;
    for (int i = 3; i <= 15 && fields >> field; ++i) {
      if (i == 14 || i == 15) ticks += std::stod(field);  // utime, stime
    }
    return ticks / static_cast<double>(::sysconf(_SC_CLK_TCK));
  }

  bool running() {
    if (pid_ <= 0) return false;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == 0) return true;
    reaped(status);  // exited: never signal this pid again
    return false;
  }

  ~ServiceChild() { stop(std::chrono::milliseconds(2000)); }

 private:
  int reaped(int status) {
    pid_ = 0;
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return exit_code_;
  }

  pid_t pid_{0};
  int exit_code_{-1};
};

// ---- a minimal client --------------------------------------------------------------------------

template <typename Msg, typename Model>
class Inbox {
 public:
  using Convert = std::function<Model(const Msg&)>;
  Inbox(dds::DataReader* reader, Convert convert) : reader_(reader), convert_(std::move(convert)) {}

  // Waits until some received sample satisfies `pred`; returns it.
  std::optional<Model> wait_for(const std::function<bool(const Model&)>& pred,
                                std::chrono::milliseconds timeout = kReplyTimeout) {
    const auto until = Clock::now() + timeout;
    while (true) {
      drain();
      for (const auto& s : samples_) {
        if (pred(s)) return s;
      }
      if (Clock::now() >= until) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  const std::vector<Model>& samples() {
    drain();
    return samples_;
  }

 private:
  void drain() {
    Msg m;
    dds::SampleInfo info;
    while (reader_->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) samples_.push_back(convert_(m));
    }
  }

  dds::DataReader* reader_;
  Convert convert_;
  std::vector<Model> samples_;
};

// Writes the PullOutRequest samples of request id 0 with a `lanes` sequence that claims 2^31 - 1
// elements and then ends (a reader that trusted the length would try to allocate hundreds of GB),
// and any other request with the generated encoding.
class GarbageRequestType : public msg::PullOutRequestPubSubType {
 public:
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const auto* request = static_cast<msg::PullOutRequest*>(data);
    if (request->request_id() != 0) return msg::PullOutRequestPubSubType::serialize(data, payload);
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload->data), payload->max_size);
    eprosima::fastcdr::Cdr ser(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    payload->encapsulation = ser.endianness() == eprosima::fastcdr::Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
    ser.serialize_encapsulation();
    ser << request->vehicle_id() << request->request_id() << request->stamp().sec() << request->stamp().nanosec();
    for (int i = 0; i < 7 + 1 + 7; ++i) ser << (i == 6 || i == 14 ? 1.0 : 0.0);  // ego pose, velocity, goal pose
    ser << static_cast<std::uint32_t>(0x7FFFFFFF);                               // lanes: "2^31 - 1 elements"
    payload->length = static_cast<std::uint32_t>(ser.getSerializedDataLength());
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    if (static_cast<msg::PullOutRequest*>(data)->request_id() != 0) {
      return msg::PullOutRequestPubSubType::getSerializedSizeProvider(data);
    }
    return [] { return 1024u; };
  }
};

// Writes the ExecutionProgress samples of request id 0 with an `approved` byte of 2 (CDR allows
// only 0 and 1: fastcdr throws BadParamException, which the generated deserialize() does not
// catch), and any other sample with the generated encoding.
class GarbageProgressType : public msg::ExecutionProgressPubSubType {
 public:
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const auto* progress = static_cast<msg::ExecutionProgress*>(data);
    if (progress->request_id() != 0) return msg::ExecutionProgressPubSubType::serialize(data, payload);
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload->data), payload->max_size);
    eprosima::fastcdr::Cdr ser(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    payload->encapsulation = ser.endianness() == eprosima::fastcdr::Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
    ser.serialize_encapsulation();
    ser << progress->vehicle_id() << progress->request_id() << progress->stamp().sec() << progress->stamp().nanosec();
    for (int i = 0; i < 7 + 1; ++i) ser << (i == 6 ? 1.0 : 0.0);  // pose, velocity
    ser << std::uint8_t{2};                                       // approved: neither false nor true
    payload->length = static_cast<std::uint32_t>(ser.getSerializedDataLength());
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    if (static_cast<msg::ExecutionProgress*>(data)->request_id() != 0) {
      return msg::ExecutionProgressPubSubType::getSerializedSizeProvider(data);
    }
    return [] { return 1024u; };
  }
};

std::int64_t system_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

class TestClient {
 public:
  explicit TestClient(int domain) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    if (factory->load_XML_profiles_file(kProfiles) != ReturnCode_t::RETCODE_OK) throw std::runtime_error("xml");
    participant_ = factory->create_participant_with_profile(domain, "pullout_participant");
    if (participant_ == nullptr) throw std::runtime_error("participant");
    auto* request_topic = topic("pullout/request", idl::make_guarded_type<msg::PullOutRequestPubSubType>());
    // A second participant for the garbage writer: one participant registers one type per name.
    garbage_participant_ = factory->create_participant_with_profile(domain, "pullout_participant");
    if (garbage_participant_ == nullptr) throw std::runtime_error("participant");
    dds::TypeSupport garbage_type(std::make_unique<GarbageRequestType>().release());
    garbage_type.register_type(garbage_participant_);
    auto* garbage_topic =
        garbage_participant_->create_topic("pullout/request", garbage_type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    garbage_writer_ = garbage_participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT)
                          ->create_datawriter_with_profile(garbage_topic, "pullout_request_writer");
    if (garbage_writer_ == nullptr) throw std::runtime_error("garbage writer");
    dds::TypeSupport garbage_progress_type(std::make_unique<GarbageProgressType>().release());
    garbage_progress_type.register_type(garbage_participant_);
    auto* garbage_progress_topic = garbage_participant_->create_topic(
        "pullout/progress", garbage_progress_type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    garbage_progress_writer_ = garbage_participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT)
                                   ->create_datawriter_with_profile(garbage_progress_topic, "pullout_progress_writer");
    if (garbage_progress_writer_ == nullptr) throw std::runtime_error("garbage progress writer");
    auto* progress_topic = topic("pullout/progress", idl::make_guarded_type<msg::ExecutionProgressPubSubType>());
    auto* path_topic = topic("pullout/path", idl::make_guarded_type<msg::PullOutPathPubSubType>());
    auto* status_topic = topic("pullout/status", idl::make_guarded_type<msg::PullOutStatusPubSubType>());
    auto* pub = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    auto* sub = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    request_writer_ = pub->create_datawriter_with_profile(request_topic, "pullout_request_writer");
    progress_writer_ = pub->create_datawriter_with_profile(progress_topic, "pullout_progress_writer");
    path_reader_ = sub->create_datareader(path_topic, deep_reader_qos(sub, "pullout_path_reader"));
    status_reader_ = sub->create_datareader(status_topic, deep_reader_qos(sub, "pullout_status_reader"));
    if (!request_writer_ || !progress_writer_ || !path_reader_ || !status_reader_) {
      throw std::runtime_error("entities");
    }
    paths = std::make_unique<Inbox<msg::PullOutPath, PullOutPath>>(
        path_reader_, [](const msg::PullOutPath& m) { return idl::from_msg(m); });
    statuses = std::make_unique<Inbox<msg::PullOutStatus, PullOutStatus>>(
        status_reader_, [](const msg::PullOutStatus& m) { return idl::from_msg(m); });
  }

  ~TestClient() {
    garbage_participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(garbage_participant_);
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  // Waits until the service's readers and writers are matched, both ways. Discovery is not
  // symmetric: the service may read this client's requests before its status writer knows this
  // client's reader, and a status written then reaches the reader only as the writer's history
  // (the latest sample per vehicle), so a `planning` followed by the answer would arrive as the
  // answer alone.
  bool wait_matched(std::chrono::milliseconds timeout = std::chrono::milliseconds(15000)) {
    const auto until = Clock::now() + timeout;
    while (Clock::now() < until) {
      dds::PublicationMatchedStatus req;
      dds::PublicationMatchedStatus prog;
      dds::SubscriptionMatchedStatus path;
      dds::SubscriptionMatchedStatus status;
      request_writer_->get_publication_matched_status(req);
      progress_writer_->get_publication_matched_status(prog);
      path_reader_->get_subscription_matched_status(path);
      status_reader_->get_subscription_matched_status(status);
      if (req.current_count >= 1 && prog.current_count >= 1 && path.current_count >= 1 && status.current_count >= 1) {
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  bool send(const PullOutRequest& r) {
    msg::PullOutRequest m = idl::to_msg(r);
    return request_writer_->write(&m);
  }
  bool send(msg::PullOutRequest m) { return request_writer_->write(&m); }
  bool send_garbage(const std::string& vehicle) {
    msg::PullOutRequest m;
    m.vehicle_id(vehicle);
    return send_through_garbage_writer(m);
  }
  // A good request (request_id != 0) on the garbage writer: it arrives after the garbage sent before.
  bool send_through_garbage_writer(msg::PullOutRequest m) {
    const auto until = Clock::now() + std::chrono::seconds(10);
    dds::PublicationMatchedStatus matched;
    while (garbage_writer_->get_publication_matched_status(matched), matched.current_count < 1) {
      if (Clock::now() > until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return garbage_writer_->write(&m);
  }
  bool send(const ExecutionProgress& p) {
    msg::ExecutionProgress m = idl::to_msg(p);
    return progress_writer_->write(&m);
  }
  // Progress with request id 0 is undecodable (GarbageProgressType), any other is good.
  bool send_through_garbage_progress_writer(const ExecutionProgress& p) {
    const auto until = Clock::now() + std::chrono::seconds(10);
    dds::PublicationMatchedStatus matched;
    while (garbage_progress_writer_->get_publication_matched_status(matched), matched.current_count < 1) {
      if (Clock::now() > until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    msg::ExecutionProgress m = idl::to_msg(p);
    return garbage_progress_writer_->write(&m);
  }

  std::optional<PullOutStatus> final_status(const std::string& vehicle, std::uint64_t request_id) {
    return statuses->wait_for([&](const PullOutStatus& s) {
      return s.vehicle_id == vehicle && s.request_id == request_id && s.state != ExecutionState::kPlanning;
    });
  }
  std::optional<PullOutPath> path_of(const std::string& vehicle, std::uint64_t request_id) {
    return paths->wait_for([&](const PullOutPath& p) { return p.vehicle_id == vehicle && p.request_id == request_id; });
  }

  std::unique_ptr<Inbox<msg::PullOutPath, PullOutPath>> paths;
  std::unique_ptr<Inbox<msg::PullOutStatus, PullOutStatus>> statuses;

 private:
  // The profile's reader QoS with 64 samples kept per vehicle instead of 1 (for up to 256 vehicles).
  static dds::DataReaderQos deep_reader_qos(dds::Subscriber* sub, const char* profile) {
    dds::DataReaderQos qos;
    if (sub->get_datareader_qos_from_profile(profile, qos) != ReturnCode_t::RETCODE_OK) {
      throw std::runtime_error(std::string("no profile ") + profile);
    }
    // Fast DDS requires max_samples >= max_instances * max_samples_per_instance.
    qos.history().depth = 64;
    qos.resource_limits().max_samples_per_instance = 64;
    qos.resource_limits().max_instances = 256;
    qos.resource_limits().max_samples = 64 * 256;
    return qos;
  }

  dds::Topic* topic(const char* name, dds::TopicDataType* type_ptr) {
    dds::TypeSupport type(type_ptr);
    type.register_type(participant_);
    return participant_->create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  }

  dds::DomainParticipant* participant_{nullptr};
  dds::DomainParticipant* garbage_participant_{nullptr};
  dds::DataWriter* garbage_writer_{nullptr};
  dds::DataWriter* garbage_progress_writer_{nullptr};
  dds::DataWriter* request_writer_{nullptr};
  dds::DataWriter* progress_writer_{nullptr};
  dds::DataReader* path_reader_{nullptr};
  dds::DataReader* status_reader_{nullptr};
};

PullOutRequest scenario_request(const std::string& name, const std::string& vehicle, std::uint64_t request_id) {
  PullOutRequest r = load_scenario(kSourceDir + "/tests/scenarios/" + name + ".yaml").request;
  r.vehicle_id = vehicle;
  r.request_id = request_id;
  return r;
}

// ---- the tests -------------------------------------------------------------------------------

class ServiceDds : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    service_ = std::make_unique<ServiceChild>();
    // A domain of this test process's own (shared lease with tests/integration), so that tests run
    // in parallel never talk to each other's service.
    domain_ = std::make_unique<integration::DomainLease>();
    service_->start(domain_->domain());
    client_ = std::make_unique<TestClient>(domain_->domain());
    matched_ = client_->wait_matched();
  }
  static void TearDownTestSuite() {
    client_.reset();
    // A service that did not exit cleanly (a crash, a sanitizer report) fails the test it ran in.
    const int exit_code = service_->stop();
    if (exit_code != 0) ADD_FAILURE() << "pullout_service exit status " << exit_code << " (-1: killed by a signal)";
    service_.reset();
    domain_.reset();
  }
  void SetUp() override {
    ASSERT_TRUE(matched_) << "the service did not show up on domain " << domain_->domain();
    ASSERT_TRUE(service_->running());
  }

  // A vehicle that departed from the suite's shared start pose executes its path, which makes its
  // swept path an obstacle for every later vehicle there (the fleet check). It drives its one
  // segment to the end, so that the suite's tests see the same empty shoulder in any order.
  static void drive_out_of_the_way(const std::string& vehicle, std::uint64_t request_id) {
    const auto path = client_->path_of(vehicle, request_id);
    ASSERT_TRUE(path.has_value());
    ASSERT_EQ(path->partial_paths.size(), 1u) << vehicle << " drives one segment";
    ExecutionProgress gone;
    gone.vehicle_id = vehicle;
    gone.request_id = request_id;
    gone.stamp_ns = system_now_ns();
    gone.pose = Pose2{path->end_pose.x + 0.5 * std::cos(path->end_pose.yaw),
                      path->end_pose.y + 0.5 * std::sin(path->end_pose.yaw), path->end_pose.yaw};
    gone.velocity_mps = 1.0;
    gone.approved = true;
    ASSERT_TRUE(client_->send(gone));
    const auto done = client_->statuses->wait_for([&](const PullOutStatus& s) {
      return s.vehicle_id == vehicle && s.request_id == request_id && s.state == ExecutionState::kCompleted;
    });
    ASSERT_TRUE(done.has_value()) << vehicle << " did not complete";
  }

  static std::unique_ptr<integration::DomainLease> domain_;
  static std::unique_ptr<ServiceChild> service_;
  static std::unique_ptr<TestClient> client_;
  static bool matched_;
};

std::unique_ptr<integration::DomainLease> ServiceDds::domain_;
std::unique_ptr<ServiceChild> ServiceDds::service_;
std::unique_ptr<TestClient> ServiceDds::client_;
bool ServiceDds::matched_ = false;

TEST_F(ServiceDds, FoundPathAndStatus) {
  ASSERT_TRUE(client_->send(scenario_request("straight_shoulder", "found-1", 11)));
  const auto status = client_->final_status("found-1", 11);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->state, ExecutionState::kWaitingApproval) << status->stop_reason << status->error;
  EXPECT_EQ(status->current_path_idx, 0u);
  EXPECT_EQ(status->planner_type, PlannerType::kShift);
  EXPECT_FALSE(status->evaluation_table.empty());
  EXPECT_GT(status->planning_time_ms, 0.0);

  const auto path = client_->path_of("found-1", 11);
  ASSERT_TRUE(path.has_value());
  EXPECT_TRUE(path->found);
  EXPECT_EQ(path->planner_type, PlannerType::kShift);
  ASSERT_GE(path->partial_paths.size(), 1u);
  EXPECT_EQ(path->partial_paths.size(), path->pairs_terminal_velocity_and_accel.size());
  EXPECT_EQ(status->segment_count, path->partial_paths.size());
  for (const auto& segment : path->partial_paths) EXPECT_GE(segment.points.size(), 2u);
}

TEST_F(ServiceDds, ProgressAdvancesToCompletion) {
  // A probe vehicle waiting for approval: its progress, written after a sample of drive-1 on the
  // same writer, is handled after that sample, and the status it causes comes after any status
  // that sample caused.
  const PullOutRequest probe = scenario_request("straight_shoulder", "drive-probe", 22);
  ASSERT_TRUE(client_->send(probe));
  const auto probe_waiting = client_->final_status("drive-probe", 22);
  ASSERT_TRUE(probe_waiting.has_value());
  ASSERT_EQ(probe_waiting->state, ExecutionState::kWaitingApproval);

  ASSERT_TRUE(client_->send(scenario_request("straight_shoulder", "drive-1", 21)));
  const auto path = client_->path_of("drive-1", 21);
  ASSERT_TRUE(path.has_value());
  ASSERT_TRUE(path->found);
  const auto executing = client_->final_status("drive-1", 21);
  ASSERT_TRUE(executing.has_value());
  ASSERT_EQ(executing->state, ExecutionState::kWaitingApproval);

  std::int64_t stamp = 1'000'000'000;
  const auto send_progress = [&](std::uint64_t request_id, const Pose2& pose, double v) {
    ExecutionProgress p;
    p.vehicle_id = "drive-1";
    p.request_id = request_id;
    p.stamp_ns = stamp;
    p.pose = pose;
    p.velocity_mps = v;
    p.approved = true;
    EXPECT_TRUE(client_->send(p));
    // Keep-last-1: give the service time to take each sample before the next replaces it.
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  };

  // Every segment but the last: stand at its end for longer than th_stopped_time (vehicle clock).
  const std::size_t n = path->partial_paths.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Pose2 end = path->partial_paths[i].points.back().pose;
    send_progress(21, end, 0.0);
    stamp += 1'500'000'000;
    send_progress(21, end, 0.0);
    const auto next = client_->statuses->wait_for([&](const PullOutStatus& s) {
      return s.vehicle_id == "drive-1" && s.request_id == 21 && s.current_path_idx == i + 1;
    });
    ASSERT_TRUE(next.has_value()) << "segment " << i << " did not finish";
  }

  // Past the end pose, but for a stale request id: ignored.
  const Pose2 past{path->end_pose.x + 0.5 * std::cos(path->end_pose.yaw),
                   path->end_pose.y + 0.5 * std::sin(path->end_pose.yaw), path->end_pose.yaw};
  stamp += 100'000'000;
  send_progress(20, past, 1.0);
  ExecutionProgress approve;
  approve.vehicle_id = "drive-probe";
  approve.request_id = 22;
  approve.stamp_ns = system_now_ns();
  approve.pose = probe.ego_pose;
  approve.approved = true;
  ASSERT_TRUE(client_->send(approve));
  const auto probe_moved = client_->statuses->wait_for([](const PullOutStatus& s) {
    return s.vehicle_id == "drive-probe" && s.request_id == 22 && s.state != ExecutionState::kWaitingApproval &&
           s.state != ExecutionState::kPlanning;
  });
  ASSERT_TRUE(probe_moved.has_value()) << "the probe's approval was not handled";
  for (const auto& s : client_->statuses->samples()) {
    if (s.vehicle_id == "drive-1") {
      EXPECT_NE(s.state, ExecutionState::kCompleted) << "completed by progress for a stale request";
    }
  }

  stamp += 100'000'000;
  send_progress(21, past, 1.0);
  const auto done = client_->statuses->wait_for([](const PullOutStatus& s) {
    return s.vehicle_id == "drive-1" && s.request_id == 21 && s.state == ExecutionState::kCompleted;
  });
  ASSERT_TRUE(done.has_value());
  EXPECT_EQ(done->current_path_idx, n - 1);

  drive_out_of_the_way("drive-probe", 22);
}

TEST_F(ServiceDds, NoPathGivesAStopPathWithReasons) {
  ASSERT_TRUE(client_->send(scenario_request("boxed_in", "boxed-1", 31)));
  const auto status = client_->final_status("boxed-1", 31);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->state, ExecutionState::kNoPath);
  EXPECT_FALSE(status->stop_reason.empty());
  EXPECT_FALSE(status->evaluation_table.empty());
  const auto path = client_->path_of("boxed-1", 31);
  ASSERT_TRUE(path.has_value());
  EXPECT_FALSE(path->found);
  EXPECT_FALSE(path->reasons.empty());
  for (const auto& segment : path->partial_paths) {
    for (const auto& p : segment.points) EXPECT_EQ(p.longitudinal_velocity_mps, 0.0);
  }
}

// The request's statuses in the order they arrived.
std::vector<ExecutionState> states_of(const std::vector<PullOutStatus>& statuses, const std::string& vehicle,
                                      std::uint64_t request_id) {
  std::vector<ExecutionState> states;
  for (const auto& s : statuses) {
    if (s.vehicle_id == vehicle && s.request_id == request_id) states.push_back(s.state);
  }
  return states;
}

TEST_F(ServiceDds, ASearchLongerThanTheQuickBudgetIsAnnouncedAsPlanningFirst) {
  // Every lane-based attempt fails (132 of them) and the freespace planner tries too: the search
  // takes far longer than service.quick_answer_ms (2 ms), so `planning` is written when the quick
  // attempt runs out, before the answer and never after it.
  ASSERT_TRUE(client_->send(scenario_request("full_search", "long-1", 81)));
  const auto status = client_->final_status("long-1", 81);
  ASSERT_TRUE(status.has_value());
  const std::vector<ExecutionState> states = states_of(client_->statuses->samples(), "long-1", 81);
  ASSERT_GE(states.size(), 2u) << "answered " << to_string(status->state) << " in " << status->planning_time_ms
                               << " ms with no `planning` status";
  EXPECT_EQ(states.front(), ExecutionState::kPlanning);
  EXPECT_NE(states.back(), ExecutionState::kPlanning);
  EXPECT_EQ(std::count(states.begin(), states.end(), ExecutionState::kPlanning), 1);
}

TEST_F(ServiceDds, NoPlanningStatusFollowsTheAnswer) {
  // A quick search is answered without `planning` (or, on a slow machine, with it first): either
  // way the answer is the request's last status.
  ASSERT_TRUE(client_->send(scenario_request("straight_shoulder", "quick-1", 82)));
  const auto status = client_->final_status("quick-1", 82);
  ASSERT_TRUE(status.has_value());
  // The vehicle's next request answered: its statuses come from the same writer, in order, after
  // anything still written for request 82 (no sleep standing in for "nothing more came").
  ASSERT_TRUE(client_->send(scenario_request("straight_shoulder", "quick-1", 83)));
  ASSERT_TRUE(client_->final_status("quick-1", 83).has_value());
  const std::vector<ExecutionState> states = states_of(client_->statuses->samples(), "quick-1", 82);
  ASSERT_FALSE(states.empty());
  EXPECT_EQ(states.back(), ExecutionState::kWaitingApproval);
  EXPECT_LE(std::count(states.begin(), states.end(), ExecutionState::kPlanning), 1);
}

TEST_F(ServiceDds, MalformedRequestIsRejectedNamingTheField) {
  msg::PullOutRequest m = idl::to_msg(scenario_request("straight_shoulder", "bad-1", 41));
  m.ego_pose().position().x(std::numeric_limits<double>::quiet_NaN());
  m.goal_pose().orientation().w(3.0);
  ASSERT_TRUE(client_->send(m));
  const auto status = client_->final_status("bad-1", 41);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->state, ExecutionState::kRejected);
  EXPECT_NE(status->error.find("ego_pose.position: "), std::string::npos) << status->error;
  EXPECT_NE(status->error.find("goal_pose.orientation: "), std::string::npos) << status->error;
  const auto path = client_->path_of("bad-1", 41);
  ASSERT_TRUE(path.has_value());
  EXPECT_FALSE(path->found);
  EXPECT_TRUE(path->partial_paths.empty());

  // The same vehicle recovers with a good request, and the service is still up.
  ASSERT_TRUE(client_->send(scenario_request("straight_shoulder", "bad-1", 42)));
  const auto good = client_->final_status("bad-1", 42);
  ASSERT_TRUE(good.has_value());
  EXPECT_EQ(good->state, ExecutionState::kWaitingApproval);
}

TEST_F(ServiceDds, UndecodableSampleIsDroppedAndTheServiceGoesOn) {
  ASSERT_TRUE(client_->send_garbage("garbage-1"));
  // On the same writer, so it arrives after the garbage (another vehicle: the writer keeps the
  // last sample per vehicle, and must not replace the garbage before it is sent).
  ASSERT_TRUE(
      client_->send_through_garbage_writer(idl::to_msg(scenario_request("straight_shoulder", "garbage-2", 45))));
  const auto status = client_->final_status("garbage-2", 45);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->state, ExecutionState::kWaitingApproval);
  EXPECT_TRUE(service_->running());
}

TEST_F(ServiceDds, UndecodableProgressIsDroppedAndTheServiceGoesOn) {
  const PullOutRequest probe = scenario_request("straight_shoulder", "garbage-3", 46);
  ASSERT_TRUE(client_->send(probe));
  const auto waiting = client_->final_status("garbage-3", 46);
  ASSERT_TRUE(waiting.has_value());
  ASSERT_EQ(waiting->state, ExecutionState::kWaitingApproval);

  ExecutionProgress garbage;
  garbage.vehicle_id = "garbage-4";  // request id 0: undecodable
  ASSERT_TRUE(client_->send_through_garbage_progress_writer(garbage));
  // The approval of garbage-3, on the same writer (another vehicle, so the writer does not replace
  // the garbage): handled after the garbage, if the service survived it.
  ExecutionProgress approve;
  approve.vehicle_id = "garbage-3";
  approve.request_id = 46;
  approve.stamp_ns = system_now_ns();
  approve.pose = probe.ego_pose;
  approve.approved = true;
  ASSERT_TRUE(client_->send_through_garbage_progress_writer(approve));
  const auto moved = client_->statuses->wait_for([](const PullOutStatus& s) {
    return s.vehicle_id == "garbage-3" && s.request_id == 46 && s.state != ExecutionState::kWaitingApproval &&
           s.state != ExecutionState::kPlanning;
  });
  ASSERT_TRUE(moved.has_value()) << "the approval after the undecodable progress was not handled";
  EXPECT_TRUE(service_->running());
  drive_out_of_the_way("garbage-3", 46);
}

TEST_F(ServiceDds, CoreValidationRejectsAnInconsistentRequest) {
  PullOutRequest r = scenario_request("straight_shoulder", "nolanes-1", 51);
  r.lanes.clear();
  ASSERT_TRUE(client_->send(r));
  const auto status = client_->final_status("nolanes-1", 51);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->state, ExecutionState::kRejected);
  EXPECT_FALSE(status->error.empty());
}

TEST_F(ServiceDds, ManyVehiclesAtOnce) {
  // More vehicles than Fast DDS's default max_instances (10): the profiles must raise it.
  constexpr int kVehicles = 24;
  for (int i = 0; i < kVehicles; ++i) {
    ASSERT_TRUE(client_->send(
        scenario_request(i % 4 == 3 ? "boxed_in" : "straight_shoulder", "fleet-" + std::to_string(i), 100 + i)));
  }
  for (int i = 0; i < kVehicles; ++i) {
    const std::string id = "fleet-" + std::to_string(i);
    const auto status = client_->final_status(id, 100 + i);
    ASSERT_TRUE(status.has_value()) << id;
    EXPECT_EQ(status->state, i % 4 == 3 ? ExecutionState::kNoPath : ExecutionState::kWaitingApproval) << id;
    const auto path = client_->path_of(id, 100 + i);
    ASSERT_TRUE(path.has_value()) << id;
    EXPECT_EQ(path->found, i % 4 != 3) << id;
  }
}

TEST_F(ServiceDds, NewerRequestReplacesTheOlderOne) {
  // Three requests back to back: the last one is answered; an older one may be answered first
  // (if its search finished before the next arrived) but never after it.
  for (std::uint64_t id = 61; id <= 63; ++id) {
    ASSERT_TRUE(client_->send(scenario_request("straight_shoulder", "replace-1", id)));
  }
  const auto last = client_->final_status("replace-1", 63);
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(last->state, ExecutionState::kWaitingApproval);
  // A vehicle runs one job at a time (planning_queue.hpp): 63's job started after 61's and 62's
  // had returned, so any status they published came before 63's final one.
  std::uint64_t latest_seen = 0;
  for (const auto& s : client_->statuses->samples()) {
    if (s.vehicle_id != "replace-1") continue;
    EXPECT_GE(s.request_id, latest_seen) << "an older request was answered after a newer one";
    latest_seen = std::max(latest_seen, s.request_id);
  }
}

// Resamples a polyline to `n` points evenly spaced between its first and last point.
std::vector<Point2> resampled(const std::vector<Point2>& line, std::size_t n) {
  std::vector<Point2> out;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(n - 1);
    out.push_back(
        {line.front().x + t * (line.back().x - line.front().x), line.front().y + t * (line.back().y - line.front().y)});
  }
  return out;
}

TEST_F(ServiceDds, LargeRequestArrivesAndIsPlanned) {
  // 4 bounds of 5,000 points: a request of about 500 KB, fragmented over UDP.
  PullOutRequest r = scenario_request("straight_shoulder", "large-1", 71);
  for (auto& lane : r.lanes) {
    lane.left_bound = resampled(lane.left_bound, 5000);
    lane.right_bound = resampled(lane.right_bound, 5000);
  }
  // What is tested is the transport, not the planner's speed on dense lanes: a generous budget.
  r.deadline_ms = 5000.0;
  const auto t0 = Clock::now();
  ASSERT_TRUE(client_->send(r));
  const auto status = client_->final_status("large-1", 71);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->state, ExecutionState::kWaitingApproval) << status->error << status->stop_reason;
  // Reported, not asserted (a shared CI machine makes transport times noisy).
  const double round_trip_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  // Informative only: the transport time of a request this large is measured by bench/e2e_latency.
  std::printf("large request: round trip %.1f ms, planning %.1f ms\n", round_trip_ms, status->planning_time_ms);
}

TEST_F(ServiceDds, RequestOverTheLimitsIsRejected) {
  // service.limits.max_points_per_line is 10,000 in the shipped config.
  PullOutRequest r = scenario_request("straight_shoulder", "huge-1", 81);
  r.lanes[0].left_bound = resampled(r.lanes[0].left_bound, 10001);
  ASSERT_TRUE(client_->send(r));
  const auto status = client_->final_status("huge-1", 81);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->state, ExecutionState::kRejected);
  EXPECT_NE(status->error.find("lanes[0].left_bound"), std::string::npos) << status->error;
}

TEST_F(ServiceDds, IdleServiceDoesNotSpin) {
  // After traffic on both readers, the dispatcher must sleep in its WaitSet, not poll.
  ASSERT_TRUE(client_->send(scenario_request("straight_shoulder", "idle-1", 91)));
  ASSERT_TRUE(client_->final_status("idle-1", 91).has_value());
  ExecutionProgress p;
  p.vehicle_id = "idle-1";
  p.request_id = 91;
  p.pose = scenario_request("straight_shoulder", "idle-1", 91).ego_pose;
  ASSERT_TRUE(client_->send(p));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const double before = service_->cpu_seconds();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  EXPECT_LT(service_->cpu_seconds() - before, 0.2);
}

// A service of its own (tests/integration's harness, on a leased domain): independent of the order
// of the tests.
TEST(ServiceDdsProcess, StopsCleanlyOnSigterm) {
  integration::ServiceOptions options;
  options.executable = kServiceBinary;
  options.config_path = kSourceDir + "/config/pullout.yaml";
  integration::ServiceProcess service(options);  // returns once a probe client matched it
  {
    // Working (a request answered) before the signal.
    TestClient client(service.domain());
    ASSERT_TRUE(client.wait_matched()) << "the service did not show up on domain " << service.domain();
    ASSERT_TRUE(client.send(scenario_request("straight_shoulder", "sigterm-1", 1)));
    ASSERT_TRUE(client.final_status("sigterm-1", 1).has_value()) << service.stderr_tail();
  }
  ASSERT_TRUE(service.running());
  const integration::StopReport report = service.stop();
  EXPECT_TRUE(report.clean()) << report.describe() << "\n" << service.stderr_tail();
}

}  // namespace
}  // namespace pullout
