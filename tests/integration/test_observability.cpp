// Operating the real pullout_service: Prometheus metrics and health endpoints over HTTP, JSON log
// lines, and a second service on the same DDS domain. Every check talks to the real processes
// (DDS on loopback, HTTP on 127.0.0.1); nothing reads the text log except the JSON-format test,
// whose contract is the log format.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <dirent.h>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration_support.hpp"
#include "pullout/model/names.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

// A TCP port on 127.0.0.1 that was free a moment ago (bound to port 0, then closed). The service
// takes it right after; a clash only fails the start-up, which the test reports.
int free_loopback_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof addr;
  int port = -1;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port = ntohs(addr.sin_port);
  }
  ::close(fd);
  return port;
}

struct HttpReply {
  int status{0};  // 0: no answer
  std::string body;
};

// A minimal HTTP/1.0 GET on 127.0.0.1 (independent of the CLI's probe, which is tested through
// the pullout binary below).
HttpReply http_get(int port, const std::string& path) {
  HttpReply reply;
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return reply;
  timeval timeout{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return reply;
  }
  const std::string request = "GET " + path + " HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) {
    ::close(fd);
    return reply;
  }
  std::string raw;
  char buf[4096];
  for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) raw.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  const auto space = raw.find(' ');
  const auto header_end = raw.find("\r\n\r\n");
  if (raw.compare(0, 5, "HTTP/") != 0 || space == std::string::npos || header_end == std::string::npos) return reply;
  reply.status = std::atoi(raw.c_str() + space + 1);
  reply.body = raw.substr(header_end + 4);
  return reply;
}

// The samples of a Prometheus text exposition: "name{labels}" -> value (labels as written).
std::map<std::string, double> parse_metrics(const std::string& text) {
  std::map<std::string, double> samples;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto space = line.rfind(' ');
    if (space == std::string::npos) continue;
    samples[line.substr(0, space)] = std::strtod(line.c_str() + space + 1, nullptr);
  }
  return samples;
}

double sample(const std::map<std::string, double>& samples, const std::string& key) {
  const auto it = samples.find(key);
  return it == samples.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

double sum_prefixed(const std::map<std::string, double>& samples, const std::string& prefix) {
  double sum = 0.0;
  for (const auto& [key, value] : samples) {
    if (key.compare(0, prefix.size(), prefix) == 0) sum += value;
  }
  return sum;
}

std::map<std::string, double> scrape(int port) {
  const HttpReply r = http_get(port, "/metrics");
  EXPECT_EQ(r.status, 200) << "GET /metrics";
  return parse_metrics(r.body);
}

// Polls /metrics until `key` has `value` (gauges are refreshed by the dispatcher every 250 ms).
bool wait_for_sample(int port, const std::string& key, double value, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (sample(parse_metrics(http_get(port, "/metrics").body), key) == value) return true;
    std::this_thread::sleep_for(50ms);
  }
  return false;
}

// TCP ports the process listens on (its socket inodes matched against /proc/net/tcp{,6}).
std::set<int> listening_ports(pid_t pid) {
  std::set<std::string> inodes;
  const std::string fd_dir = "/proc/" + std::to_string(pid) + "/fd";
  if (DIR* dir = ::opendir(fd_dir.c_str())) {
    while (const dirent* e = ::readdir(dir)) {
      char target[256] = {};
      const std::string link = fd_dir + "/" + e->d_name;
      const ssize_t n = ::readlink(link.c_str(), target, sizeof target - 1);
      if (n <= 0) continue;
      const std::string t(target, static_cast<std::size_t>(n));
      if (t.compare(0, 8, "socket:[") == 0) inodes.insert(t.substr(8, t.size() - 9));
    }
    ::closedir(dir);
  }
  std::set<int> ports;
  for (const char* table : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream in(table);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::istringstream f(line);
      std::string slot, local, remote, state, queues, timer, retr, uid, timeout, inode;
      f >> slot >> local >> remote >> state >> queues >> timer >> retr >> uid >> timeout >> inode;
      if (state != "0A" || inodes.count(inode) == 0) continue;  // 0A: LISTEN
      ports.insert(std::stoi(local.substr(local.find(':') + 1), nullptr, 16));
    }
  }
  return ports;
}

std::string config_with(const std::string& observability) {
  return "dds:\n  profiles_file: " + loopback_profiles_path() + "\nobservability:\n" + observability;
}

std::string metrics_on(int port) {
  return "  metrics:\n    enabled: true\n    address: 127.0.0.1\n    port: " + std::to_string(port) + "\n";
}

bool is_state(const PullOutStatus& s, ExecutionState state) { return s.state == state; }

class Observability : public ServiceTest {};

TEST_F(Observability, MetricsCountRequestsRepliesRejectionsAndPlanningTime) {
  const int port = free_loopback_port();
  ASSERT_GT(port, 0);
  start_service(temp_.write_file("metrics.yaml", config_with(metrics_on(port))));
  if (HasFatalFailure()) return;
  EXPECT_EQ(listening_ports(service().pid()), std::set<int>{port}) << "the service listens on other TCP ports";

  // Ready: the probe client matched the service, so everything /readyz checks is up.
  const HttpReply ready = http_get(port, "/readyz");
  EXPECT_EQ(ready.status, 200) << ready.body;
  EXPECT_NE(ready.body.find("other pullout services on the domain: 0"), std::string::npos) << ready.body;
  EXPECT_EQ(http_get(port, "/healthz").status, 200);
  EXPECT_EQ(http_get(port, "/no-such-page").status, 404);

  const std::map<std::string, double> before = scrape(port);
  const std::string requests = "pullout_requests_total";
  const std::string found = "pullout_replies_total{outcome=\"found\"}";
  const std::string no_path = "pullout_replies_total{outcome=\"no_path\"}";
  const std::string rejected = "pullout_replies_total{outcome=\"rejected\"}";
  const std::string none_count = "pullout_planning_seconds_count{planner=\"none\"}";
  ASSERT_EQ(sample(before, found), 0.0);
  ASSERT_EQ(sample(before, no_path), 0.0);
  ASSERT_EQ(sample(before, rejected), 0.0);
  // The probe client sent no request.
  ASSERT_EQ(sample(before, requests), 0.0);

  // 1. A found path: one request, one found reply, one planning time under its planner.
  const Scenario shoulder = load_test_scenario("straight_shoulder");
  auto car = connect("obs-found");
  ASSERT_NE(car, nullptr);
  const std::uint64_t found_id = car->send(shoulder.request);
  const auto path = car->wait_for_path(found_id, kReplyTimeout);
  ASSERT_TRUE(path && path->found);
  ASSERT_TRUE(car->wait_for_status(
      found_id, [](const PullOutStatus& s) { return has_path(s.state); }, kReplyTimeout));
  const std::string planner_count =
      std::string("pullout_planning_seconds_count{planner=\"") + to_string(path->planner_type) + "\"}";
  auto after = scrape(port);
  EXPECT_EQ(sample(after, requests), 1.0);
  EXPECT_EQ(sample(after, found), 1.0);
  EXPECT_EQ(sample(after, planner_count), 1.0) << planner_count;
  EXPECT_GT(
      sample(after, std::string("pullout_planning_seconds_sum{planner=\"") + to_string(path->planner_type) + "\"}"),
      0.0);

  // 2. A rejection naming ego_pose (NaN, caught when the sample is converted).
  auto bad = connect("obs-rejected");
  ASSERT_NE(bad, nullptr);
  PullOutRequest nan_request = shoulder.request;
  nan_request.ego_pose.x = std::numeric_limits<double>::quiet_NaN();
  const std::uint64_t rejected_id = bad->send(nan_request);
  ASSERT_TRUE(bad->wait_for_status(
      rejected_id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kRejected); }, kReplyTimeout));
  after = scrape(port);
  EXPECT_EQ(sample(after, requests), 2.0);
  EXPECT_EQ(sample(after, rejected), 1.0);
  // One field class (under ego_pose, indices removed), counted once.
  EXPECT_EQ(sum_prefixed(after, "pullout_rejections_total{field=\"ego_pose"), 1.0) << http_get(port, "/metrics").body;
  EXPECT_EQ(sum_prefixed(after, "pullout_rejections_total{"), 1.0) << http_get(port, "/metrics").body;
  EXPECT_EQ(sample(after, found), 1.0) << "a rejection counted as found";

  // 3. No path (boxed in): a no_path reply and a planning time under "none".
  auto boxed = connect("obs-no-path");
  ASSERT_NE(boxed, nullptr);
  const Scenario boxed_in = load_test_scenario("boxed_in");
  const std::uint64_t no_path_id = boxed->send(boxed_in.request);
  ASSERT_TRUE(boxed->wait_for_status(
      no_path_id, [](const PullOutStatus& s) { return is_state(s, ExecutionState::kNoPath); }, kReplyTimeout));
  after = scrape(port);
  EXPECT_EQ(sample(after, requests), 3.0);
  EXPECT_EQ(sample(after, no_path), 1.0);
  EXPECT_EQ(sample(after, none_count), 1.0);
  EXPECT_EQ(sample(after, found), 1.0);
  EXPECT_EQ(sample(after, rejected), 1.0);

  // Three sessions are held; nothing waits for a planning thread; nothing was evicted.
  // Gauges are sampled every 250 ms: a sample taken while the boxed-in search was queued may
  // still be shown.
  EXPECT_TRUE(wait_for_sample(port, "pullout_vehicles", 3.0, 5s)) << http_get(port, "/metrics").body;
  EXPECT_TRUE(wait_for_sample(port, "pullout_planning_queue_depth", 0.0, 5s)) << http_get(port, "/metrics").body;
  after = scrape(port);
  EXPECT_EQ(sample(after, "pullout_evictions_total{reason=\"idle\"}"), 0.0);
  EXPECT_EQ(sample(after, "pullout_other_services"), 0.0);
}

TEST_F(Observability, HealthProbeOfTheCliFollowsTheHttpStatus) {
  const int port = free_loopback_port();
  ASSERT_GT(port, 0);
  start_service(temp_.write_file("metrics.yaml", config_with(metrics_on(port))));
  if (HasFatalFailure()) return;
  const auto probe = [&](const std::string& url) {
    ChildProcess cli({PULLOUT_CLI_EXE, "health", url}, temp_.path() + "/probe.out", temp_.path() + "/probe.err");
    const auto exit = cli.wait_exit(10s);
    return exit && exit->exited ? exit->exit_code : -1;
  };
  const std::string base = "http://127.0.0.1:" + std::to_string(port);
  EXPECT_EQ(probe(base + "/readyz"), 0);
  EXPECT_EQ(probe(base + "/healthz"), 0);
  EXPECT_EQ(probe(base + "/no-such-page"), 1) << "a 404 must not count as healthy";
  EXPECT_EQ(probe("ftp://127.0.0.1/"), 2);
  // Nothing listens there once the service has stopped.
  const StopReport report = service().stop();
  EXPECT_TRUE(report.clean()) << report.describe();
  EXPECT_EQ(probe(base + "/readyz"), 3);
}

TEST_F(Observability, WithMetricsOffNothingListens) {
  start_service(temp_.write_file("plain.yaml", config_with("  log_format: text\n")));
  if (HasFatalFailure()) return;
  // The probe client has matched, so the service finished its start-up (the HTTP endpoint would
  // have been created before the DDS dispatcher started).
  EXPECT_TRUE(listening_ports(service().pid()).empty());
}

TEST_F(Observability, JsonLogLinesParse) {
  TempDir dir;
  const std::string config = temp_.write_file("json.yaml", config_with("  log_format: json\n"));
  DomainLease lease;
  ChildProcess service(
      {PULLOUT_SERVICE_EXE, "--config", config, "--domain", std::to_string(lease.domain()), "--log-level", "debug"},
      dir.path() + "/stdout", dir.path() + "/stderr");
  ClientOptions options;
  options.vehicle_id = "obs-json-car";
  options.domain_id = lease.domain();
  {
    Client client(options);
    ASSERT_TRUE(client.wait_for_service(kMatchTimeout));
    const Scenario shoulder = load_test_scenario("straight_shoulder");
    const std::uint64_t id = client.send(shoulder.request);
    ASSERT_TRUE(client.wait_for_path(id, kReplyTimeout));
  }
  const ExitResult exit = service.stop();
  EXPECT_TRUE(exit.clean()) << exit.describe();

  std::ifstream err(dir.path() + "/stderr");
  int lines = 0;
  bool vehicle_field = false;
  for (std::string line; std::getline(err, line);) {
    ++lines;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "line " << lines << " is not JSON (" << e.what() << "): " << line;
      continue;
    }
    ASSERT_TRUE(j.is_object()) << line;
    for (const char* key : {"time", "level", "logger", "message"}) {
      EXPECT_TRUE(j.contains(key) && j[key].is_string()) << key << " missing in " << line;
    }
    if (j.contains("vehicle_id")) {
      EXPECT_EQ(j["vehicle_id"], "obs-json-car") << line;
      vehicle_field = vehicle_field || j["vehicle_id"] == "obs-json-car";
    }
  }
  EXPECT_GE(lines, 3) << "expected start-up, request and stop lines";
  EXPECT_TRUE(vehicle_field) << "no line carries the vehicle_id field";
}

TEST_F(Observability, ASecondServiceOnTheDomainIsReportedByBoth) {
  const int port_a = free_loopback_port();
  ASSERT_GT(port_a, 0);
  start_service(temp_.write_file("a.yaml", config_with(metrics_on(port_a))));
  if (HasFatalFailure()) return;
  EXPECT_EQ(sample(scrape(port_a), "pullout_other_services"), 0.0);

  int port_b = free_loopback_port();
  while (port_b == port_a) port_b = free_loopback_port();
  ServiceOptions b_options;
  b_options.executable = PULLOUT_SERVICE_EXE;
  b_options.config_path = temp_.write_file("b.yaml", config_with(metrics_on(port_b)));
  b_options.domain = domain();
  std::optional<ServiceProcess> b;
  try {
    b.emplace(b_options);
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
  EXPECT_TRUE(wait_for_sample(port_a, "pullout_other_services", 1.0, 15s)) << http_get(port_a, "/metrics").body;
  EXPECT_TRUE(wait_for_sample(port_b, "pullout_other_services", 1.0, 15s)) << http_get(port_b, "/metrics").body;
  const HttpReply ready = http_get(port_a, "/readyz");
  EXPECT_EQ(ready.status, 200) << "policy warn: still ready";
  EXPECT_NE(ready.body.find("other pullout services on the domain: 1"), std::string::npos) << ready.body;

  // B leaves (deletes its participant): A counts it gone.
  const StopReport b_report = b->stop();
  EXPECT_TRUE(b_report.clean()) << b_report.describe();
  EXPECT_TRUE(wait_for_sample(port_a, "pullout_other_services", 0.0, 15s)) << http_get(port_a, "/metrics").body;
}

TEST_F(Observability, OnDuplicateExitStopsTheNewcomer) {
  start_service(temp_.write_file("first.yaml", config_with("  log_format: text\n")));
  if (HasFatalFailure()) return;
  const std::string config = temp_.write_file("exit.yaml", config_with("  on_duplicate_service: exit\n"));
  ChildProcess second({PULLOUT_SERVICE_EXE, "--config", config, "--domain", std::to_string(domain())},
                      temp_.path() + "/second.out", temp_.path() + "/second.err");
  const auto exit = second.wait_exit(20s);
  ASSERT_TRUE(exit) << "the second service did not stop on seeing the first";
  EXPECT_TRUE(exit->exited && exit->exit_code == 4) << exit->describe() << "\n"
                                                    << read_file_tail(temp_.path() + "/second.err", 4000);
  // The warning names the first service by host and pid (README): with the shipped profiles, whose
  // participants are all called "pullout", it said "participant 'pullout'", which names no process.
  const std::string err = read_file_tail(temp_.path() + "/second.err", 4000);
  EXPECT_NE(err.find("participant 'pullout_service@"), std::string::npos) << err;
  // The first one (policy warn) keeps serving.
  auto car = connect("obs-after-duplicate");
  ASSERT_NE(car, nullptr);
  const std::uint64_t id = car->send(load_test_scenario("straight_shoulder").request);
  EXPECT_TRUE(car->wait_for_path(id, kReplyTimeout));
}

}  // namespace
}  // namespace pullout::integration
