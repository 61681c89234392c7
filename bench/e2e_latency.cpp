// End-to-end latency of the pullout service over loopback DDS, beside the floors it is made of.
//
//   bench_e2e [--requests 200] [--warmup 20] [--pings 200] [--plans 200]
//
// In one run, on a DDS domain leased for the run (loopback only, config/dds/loopback.xml):
//   1. planning   StartPlanner::plan on straight_shoulder in this process (no DDS).
//   2. e2e        the real pullout_service process and one pullout::Client: `requests`
//                 sequential straight_shoulder requests; latency = send() -> wait_for_path()
//                 returning. The service's own planning time (status.planning_time_ms) is
//                 collected too.
//   2b. secure    the same with DDS Security (a test PKI made for the run by
//                 scripts/make-test-pki; config/dds/security/governance.xml).
//   3. ping-pong  a second process (this binary with --echo) echoes samples over two topics
//                 (bench/ping, bench/pong) with the QoS of pullout/path (reliable, transient
//                 local, keep last 1). Two series: the real reply (a PullOutPath of the same
//                 serialized size) both ways, and a request-sized ping answered by the
//                 reply-sized sample (the shape of request -> path).
// request -> path is one round trip, so the e2e figure compares with a ping-pong ROUND TRIP
// plus the planning time: overhead = e2e p50 - (planning p50 + round trip p50). The overhead is
// what the service and the client add: conversions, the dispatcher and worker hand-offs, the
// PLANNING status written before the search, the client's thread waking the waiter.
//
// Prints a markdown table. Every wait is bounded; both child processes are stopped by PID
// (SIGTERM, SIGKILL after a timeout) also on failure. Not a unit test: results go to
// bench/RESULTS.md by hand, with the machine's load (uptime) at the time.
#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "load_average.hpp"
#include "percentiles.hpp"
#include "pullout/client/client.hpp"
#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"
#include "pullout/pipeline/start_planner.hpp"
#include "service_process.hpp"

namespace {

namespace dds = eprosima::fastdds::dds;
namespace integration = pullout::integration;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
using SteadyClock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr const char* kPingTopic = "bench/ping";
constexpr const char* kPongTopic = "bench/pong";
constexpr const char* kWriterProfile = "pullout_path_writer";
constexpr const char* kReaderProfile = "pullout_path_reader";
// Markers in PullOutPath::reasons that steer the echo process.
constexpr const char* kStoreTemplate = "bench:store-template";  // keep this sample (and echo it)
constexpr const char* kReplyTemplate = "bench:reply-template";  // answer with the kept sample
constexpr auto kMatchTimeout = 15s;
constexpr auto kReplyTimeout = 5s;

std::string source_path(const std::string& relative) { return std::string(PULLOUT_SOURCE_DIR) + "/" + relative; }

double ms_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double, std::milli>(SteadyClock::now() - t0).count();
}

// ------------------------------------------------------------------------------------------------
// Statistics

using pullout::bench::summarize;
using pullout::bench::Summary;

void print_row(const std::string& what, const Summary& s) {
  std::printf("| %s | %zu | %.3f | %.3f | %.3f | %.3f |\n", what.c_str(), s.n, s.p50, s.p90, s.p99, s.max);
}

using pullout::bench::load_text;

// ------------------------------------------------------------------------------------------------
// The two ping-pong endpoints: one participant from the loopback profile, a writer on one topic
// and a reader on the other, both with the QoS of pullout/path.

class PingPongEndpoint {
 public:
  PingPongEndpoint(int domain, const std::string& profiles, const char* write_topic, const char* read_topic) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    if (factory->load_XML_profiles_file(profiles) != ReturnCode::RETCODE_OK) {
      throw std::runtime_error("cannot load DDS profiles " + profiles);
    }
    participant_ = factory->create_participant_with_profile(domain, "pullout_participant");
    if (participant_ == nullptr) throw std::runtime_error("cannot create the ping-pong participant");
    dds::TypeSupport type(std::make_unique<pullout::msg::PullOutPathPubSubType>().release());
    type.register_type(participant_);
    dds::Topic* out = participant_->create_topic(write_topic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    dds::Topic* in = participant_->create_topic(read_topic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    dds::Publisher* publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    dds::Subscriber* subscriber = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (out == nullptr || in == nullptr || publisher == nullptr || subscriber == nullptr) {
      cleanup();
      throw std::runtime_error("cannot create the ping-pong topics");
    }
    writer_ = publisher->create_datawriter_with_profile(out, kWriterProfile);
    reader_ = subscriber->create_datareader_with_profile(in, kReaderProfile);
    if (writer_ == nullptr || reader_ == nullptr) {
      cleanup();
      throw std::runtime_error("cannot create the ping-pong endpoints");
    }
    reader_->get_statuscondition().set_enabled_statuses(dds::StatusMask::data_available());
    waitset_.attach_condition(reader_->get_statuscondition());
  }
  ~PingPongEndpoint() { cleanup(); }
  PingPongEndpoint(const PingPongEndpoint&) = delete;
  PingPongEndpoint& operator=(const PingPongEndpoint&) = delete;

  bool wait_matched(std::chrono::milliseconds timeout) const {
    const auto deadline = SteadyClock::now() + timeout;
    while (SteadyClock::now() < deadline) {
      dds::PublicationMatchedStatus pub;
      dds::SubscriptionMatchedStatus sub;
      writer_->get_publication_matched_status(pub);
      reader_->get_subscription_matched_status(sub);
      if (pub.current_count > 0 && sub.current_count > 0) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }

  bool write(pullout::msg::PullOutPath& sample) { return writer_->write(&sample); }

  // Waits up to `timeout` for data, then takes every sample into `out`. False on timeout.
  bool wait_take(std::chrono::nanoseconds timeout, std::vector<pullout::msg::PullOutPath>& out) {
    out.clear();
    dds::ConditionSeq active;
    const auto ns = timeout.count();
    waitset_.wait(active, eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                                                         static_cast<std::uint32_t>(ns % 1000000000)));
    pullout::msg::PullOutPath sample;
    dds::SampleInfo info;
    while (reader_->take_next_sample(&sample, &info) == ReturnCode::RETCODE_OK) {
      if (info.valid_data) out.push_back(sample);
    }
    return !out.empty();
  }

 private:
  void cleanup() {
    if (participant_ == nullptr) return;
    if (reader_ != nullptr) waitset_.detach_condition(reader_->get_statuscondition());
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    participant_ = nullptr;
  }

  dds::DomainParticipant* participant_{nullptr};
  dds::DataWriter* writer_{nullptr};
  dds::DataReader* reader_{nullptr};
  dds::WaitSet waitset_;
};

bool has_marker(const pullout::msg::PullOutPath& s, const char* marker) {
  return std::find(s.reasons().begin(), s.reasons().end(), marker) != s.reasons().end();
}

// --echo: answers every ping until SIGTERM/SIGINT. Exit 0 after a clean DDS shutdown.
int run_echo(int domain, const std::string& profiles) {
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGTERM);
  sigaddset(&stop, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop, nullptr);  // before DDS threads exist: they inherit it
  try {
    PingPongEndpoint endpoint(domain, profiles, kPongTopic, kPingTopic);
    std::optional<pullout::msg::PullOutPath> kept;
    std::vector<pullout::msg::PullOutPath> samples;
    const timespec no_wait{0, 0};
    while (sigtimedwait(&stop, nullptr, &no_wait) < 0) {
      if (!endpoint.wait_take(100ms, samples)) continue;
      for (auto& s : samples) {
        if (has_marker(s, kReplyTemplate) && kept) {
          kept->request_id(s.request_id());
          endpoint.write(*kept);
          continue;
        }
        if (has_marker(s, kStoreTemplate)) {
          kept = s;
          kept->reasons().clear();
        }
        endpoint.write(s);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_e2e --echo: %s\n", e.what());
    return 2;
  }
  return 0;
}

// ------------------------------------------------------------------------------------------------
// Measurements

struct E2eResult {
  std::vector<double> latency_ms;
  std::vector<double> service_planning_ms;
  pullout::PullOutPath reply;  // the last path, template for the ping-pong
  std::size_t lost{0};
};

// `security_dir`: the vehicle's DDS Security credentials (empty: none).
E2eResult measure_e2e(const pullout::Scenario& scenario, int domain, int warmup, int requests,
                      const std::string& security_dir = "") {
  pullout::ClientOptions options;
  options.vehicle_id = "bench-e2e";
  options.domain_id = domain;  // built-in loopback-only defaults
  options.security_dir = security_dir;
  pullout::Client client(options);
  if (!client.wait_for_service(kMatchTimeout)) throw std::runtime_error("the client did not match the service");
  E2eResult r;
  const auto executing = [](const pullout::PullOutStatus& s) {
    return s.state == pullout::ExecutionState::kWaitingApproval || s.state == pullout::ExecutionState::kNoPath ||
           s.state == pullout::ExecutionState::kRejected;
  };
  for (int i = 0; i < warmup + requests; ++i) {
    // Alternate the goal by 0.5 m: a re-sent request for the same goal within
    // backward_path_update_duration would only update the objects, not plan.
    pullout::PullOutRequest request = scenario.request;
    request.goal_pose.x += (i % 2) * 0.5;
    const auto t0 = SteadyClock::now();
    const std::uint64_t id = client.send(request);
    const auto path = client.wait_for_path(id, kReplyTimeout);
    const double latency = ms_since(t0);
    // The final status follows the path; wait for it so that requests never overlap.
    const auto status = client.wait_for_status(id, executing, kReplyTimeout);
    if (!path || !path->found || !status) {
      ++r.lost;
      continue;
    }
    r.reply = *path;
    if (i < warmup) continue;
    r.latency_ms.push_back(latency);
    r.service_planning_ms.push_back(status->planning_time_ms);
  }
  return r;
}

std::vector<double> measure_planning(const pullout::Scenario& scenario, const pullout::Config& config, int warmup,
                                     int plans) {
  const pullout::StartPlanner planner(scenario.vehicle, scenario.parameters, config.service.limits);
  std::vector<double> out;
  for (int i = 0; i < warmup + plans; ++i) {
    const auto t0 = SteadyClock::now();
    const pullout::PlanningResult result = planner.plan(scenario.request, pullout::StopCondition());
    const double ms = ms_since(t0);
    if (result.outcome != pullout::PlanningResult::Outcome::kFound) throw std::runtime_error("planning found no path");
    if (i >= warmup) out.push_back(ms);
  }
  return out;
}

struct PingPongResult {
  std::vector<double> symmetric_ms;   // reply-sized both ways
  std::vector<double> asymmetric_ms;  // request-sized ping, reply-sized pong
  std::size_t lost{0};
};

// Round trip of one ping: write `ping` with request_id `seq`, wait for the pong carrying `seq`.
std::optional<double> round_trip(PingPongEndpoint& endpoint, pullout::msg::PullOutPath& ping, std::uint64_t seq) {
  ping.request_id(seq);
  std::vector<pullout::msg::PullOutPath> pongs;
  const auto t0 = SteadyClock::now();
  if (!endpoint.write(ping)) return std::nullopt;
  const auto deadline = t0 + kReplyTimeout;
  while (SteadyClock::now() < deadline) {
    endpoint.wait_take(deadline - SteadyClock::now(), pongs);
    for (const auto& p : pongs) {
      if (p.request_id() == seq) return ms_since(t0);
    }
  }
  return std::nullopt;
}

PingPongResult measure_ping_pong(PingPongEndpoint& endpoint, const pullout::msg::PullOutPath& reply,
                                 std::size_t request_bytes, int warmup, int pings) {
  PingPongResult r;
  std::uint64_t seq = 1;
  pullout::msg::PullOutPath full = reply;
  full.reasons().clear();
  full.reasons().push_back(kStoreTemplate);  // 21 bytes more than the reply; negligible, and stated
  for (int i = 0; i < warmup + pings; ++i) {
    const auto rtt = round_trip(endpoint, full, seq++);
    if (!rtt) {
      ++r.lost;
    } else if (i >= warmup) {
      r.symmetric_ms.push_back(*rtt);
    }
  }
  // A ping as large as the request: an empty path padded with a string to the request's size.
  pullout::msg::PullOutPath small;
  small.vehicle_id(reply.vehicle_id());
  small.reasons().push_back(kReplyTemplate);
  const std::size_t base = pullout::msg::PullOutPath::getCdrSerializedSize(small);
  if (request_bytes > base + 8) small.reasons().push_back(std::string(request_bytes - base - 8, 'x'));
  for (int i = 0; i < warmup + pings; ++i) {
    const auto rtt = round_trip(endpoint, small, seq++);
    if (!rtt) {
      ++r.lost;
    } else if (i >= warmup) {
      r.asymmetric_ms.push_back(*rtt);
    }
  }
  return r;
}

int run_bench(int requests, int warmup, int pings, int plans) {
  const std::string service_exe = PULLOUT_SERVICE_EXE;
  const std::string config_path = source_path("config/pullout.yaml");
  const std::string profiles = source_path("config/dds/loopback.xml");
  const pullout::Config config = pullout::load_config(config_path);
  const pullout::Scenario scenario =
      pullout::load_scenario(source_path("tests/scenarios/straight_shoulder.yaml"), config);
  const std::string load_before = load_text();

  // 1. In-process planning (nothing else of ours running).
  const std::vector<double> planning = measure_planning(scenario, config, 20, plans);

  integration::DomainLease lease;
  // 2. End to end through the real service.
  E2eResult e2e;
  integration::StopReport service_report;
  {
    integration::ServiceOptions options;
    options.executable = service_exe;
    options.config_path = config_path;
    options.domain = lease.domain();
    integration::ServiceProcess service(options);
    e2e = measure_e2e(scenario, lease.domain(), warmup, requests);
    service_report = service.stop();
  }
  if (e2e.latency_ms.empty()) throw std::runtime_error("no request was answered");

  // 2b. The same with DDS Security (test PKI of scripts/make-test-pki, config/dds/security/:
  // authentication, access control, payloads and submessages encrypted).
  E2eResult secure;
  integration::StopReport secure_report;
  {
    integration::TempDir dir;
    const std::string pki = dir.path() + "/pki";
    const std::string command =
        "bash '" + source_path("scripts/make-test-pki") + "' '" + pki + "' bench-e2e >/dev/null";
    if (std::system(command.c_str()) != 0) throw std::runtime_error("scripts/make-test-pki failed");
    integration::ServiceOptions options;
    options.executable = service_exe;
    options.config_path =
        dir.write_file("secure.yaml", "dds:\n  profiles_file: " + source_path("config/dds/loopback.xml") +
                                          "\n  security_dir: " + pki + "/service\n");
    options.domain = lease.domain();
    options.probe_security_dir = pki + "/vehicles/bench-e2e";
    options.probe_vehicle_id = "bench-e2e";
    integration::ServiceProcess service(options);
    secure = measure_e2e(scenario, lease.domain(), warmup, requests, pki + "/vehicles/bench-e2e");
    secure_report = service.stop();
  }

  // 3. The DDS floor, with the service stopped.
  const pullout::msg::PullOutPath reply_msg = pullout::idl::to_msg(e2e.reply);
  pullout::PullOutRequest sent = scenario.request;
  sent.vehicle_id = "bench-e2e";
  const pullout::msg::PullOutRequest request_msg = pullout::idl::to_msg(sent);
  const std::size_t reply_bytes = pullout::msg::PullOutPath::getCdrSerializedSize(reply_msg);
  const std::size_t request_bytes = pullout::msg::PullOutRequest::getCdrSerializedSize(request_msg);
  std::size_t reply_points = 0;
  for (const auto& s : e2e.reply.partial_paths) reply_points += s.points.size();

  PingPongResult ping;
  integration::ExitResult echo_exit;
  {
    integration::TempDir dir;
    char self[4096];
    const ssize_t len = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
    if (len <= 0) throw std::runtime_error("cannot find this executable");
    self[len] = '\0';
    integration::ChildProcess echo({self, "--echo", "--domain", std::to_string(lease.domain()), "--profiles", profiles},
                                   dir.path() + "/echo.stdout", dir.path() + "/echo.stderr");
    PingPongEndpoint endpoint(lease.domain(), profiles, kPingTopic, kPongTopic);
    if (!endpoint.wait_matched(kMatchTimeout)) {
      echo.stop();
      throw std::runtime_error("the echo process did not match: " +
                               integration::read_file_tail(dir.path() + "/echo.stderr", 2000));
    }
    ping = measure_ping_pong(endpoint, reply_msg, request_bytes, warmup, pings);
    echo_exit = echo.stop();
  }

  const Summary plan_s = summarize(planning);
  const Summary e2e_s = summarize(e2e.latency_ms);
  const Summary svc_s = summarize(e2e.service_planning_ms);
  const Summary sym_s = summarize(ping.symmetric_ms);
  const Summary asym_s = summarize(ping.asymmetric_ms);

  std::printf("## bench_e2e: straight_shoulder over loopback DDS\n\n");
  std::printf("load average before: %s, after: %s; %u cores\n", load_before.c_str(), load_text().c_str(),
              std::thread::hardware_concurrency());
  std::printf("request %zu B, reply %zu B (%zu points, %zu segment(s)); serialized CDR sizes\n\n", request_bytes,
              reply_bytes, reply_points, e2e.reply.partial_paths.size());
  std::printf("| measurement [ms] | n | p50 | p90 | p99 | max |\n|---|---|---|---|---|---|\n");
  print_row("e2e: send() -> path received (service process, pullout::Client)", e2e_s);
  print_row("e2e with DDS Security (authenticated, encrypted)", summarize(secure.latency_ms));
  print_row("service planning time (status.planning_time_ms)", svc_s);
  print_row("in-process StartPlanner::plan", plan_s);
  print_row("DDS round trip, reply-sized both ways", sym_s);
  print_row("DDS round trip, request-sized ping / reply-sized pong", asym_s);
  std::printf("\n");
  const double floor = plan_s.p50 + asym_s.p50;
  std::printf(
      "e2e p50 %.3f ms vs floor %.3f ms (planning p50 %.3f + round trip p50 %.3f, request-sized ping /"
      " reply-sized pong): overhead %.3f ms\n",
      e2e_s.p50, floor, plan_s.p50, asym_s.p50, e2e_s.p50 - floor);
  std::printf("with the reply-sized round trip both ways: floor %.3f ms, overhead %.3f ms\n", plan_s.p50 + sym_s.p50,
              e2e_s.p50 - plan_s.p50 - sym_s.p50);
  std::printf(
      "lost: e2e %zu, secure e2e %zu, ping-pong %zu; service %s, %zu file(s) left in /dev/shm; secure "
      "service %s, %zu file(s); echo %s\n",
      e2e.lost, secure.lost, ping.lost, service_report.exit.describe().c_str(), service_report.leaked_shm_files.size(),
      secure_report.exit.describe().c_str(), secure_report.leaked_shm_files.size(), echo_exit.describe().c_str());
  const bool clean = e2e.lost == 0 && secure.lost == 0 && ping.lost == 0 && service_report.clean() &&
                     secure_report.clean() && echo_exit.clean();
  return clean ? 0 : 1;
}

}  // namespace

namespace {

int run(int argc, char** argv) {
  CLI::App app{"bench_e2e: end-to-end latency of pullout_service over loopback DDS, with its floors"};
  int requests = 200;
  int warmup = 20;
  int pings = 200;
  int plans = 200;
  bool echo = false;
  int domain = -1;
  std::string profiles = source_path("config/dds/loopback.xml");
  app.add_option("--requests", requests, "measured requests")->check(CLI::Range(1, 100000));
  app.add_option("--warmup", warmup, "unmeasured requests/pings first")->check(CLI::Range(0, 10000));
  app.add_option("--pings", pings, "measured ping-pong round trips per series")->check(CLI::Range(1, 100000));
  app.add_option("--plans", plans, "measured in-process plans")->check(CLI::Range(1, 100000));
  app.add_flag("--echo", echo, "internal: run as the ping-pong echo process");
  app.add_option("--domain", domain, "internal (--echo): DDS domain")->check(CLI::Range(0, 232));
  app.add_option("--profiles", profiles, "internal (--echo): DDS profiles file");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (echo) {
    if (domain < 0) {
      std::fprintf(stderr, "bench_e2e: --echo needs --domain\n");
      return 1;
    }
    return run_echo(domain, profiles);
  }
  return run_bench(requests, warmup, pings, plans);
}

}  // namespace

// Exit codes: 0 a clean run, 1 a run with lost replies or an unclean child exit (or bad usage),
// 2 the benchmark could not run.
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_e2e: %s\n", e.what());
    return 2;
  }
}
