// Load: N simulated vehicles, real pullout::Clients spread over several processes, against one
// pullout_service on loopback, bounded in time.
//
//   bench_load [--vehicles 1000] [--processes 4] [--rate 1] [--duration 30]
//              [--participant-per-vehicle | --endpoints-per-client] [--no-netns] [--service PATH]
//              [--config FILE] [--replicas N]
//
// On a DDS domain leased for the run: the real pullout_service (config/pullout.yaml with
// config/dds/loopback.xml) and `processes` worker processes (this binary with --worker), each
// with its share of the vehicles as pullout::Clients on one shared pullout::ClientParticipant,
// whose Clients share one request writer, one progress writer and one vehicle-set-filtered path
// and status reader (--endpoints-per-client: each Client with endpoints of its own on the shared
// participant, as before; --participant-per-vehicle: one participant per vehicle, the
// single-vehicle constructor; both for comparison). Once every client matched the service, each vehicle sends a
// straight_shoulder request `rate` times a second for `duration` seconds, its start pose varied per vehicle and per
// request (x in [6, 30] m, y in [3.0, 3.4] m: real plans), the vehicles' phases spread evenly over
// the period. A request is answered when its path and a status past planning have arrived
// (latency = send() -> the later of the two, in the worker's callbacks); planned when that path is
// found and the status waits for approval. After the last send the workers wait kDrain for
// outstanding answers; what is still unanswered is lost. A reply whose vehicle id is not the
// client's, or whose request id that vehicle never sent, is mismatched. Lost and mismatched must
// be 0.
//
// Reported: replies/s (answered requests / duration), latency p50/p99/max, lost, mismatched, not
// planned; the service's CPU over the send window (/proc/PID/stat, % of one core) and peak RSS
// (VmHWM); the workers' CPU; the machine's CPU busy share (/proc/stat) and, by second, its steal
// (a shared VM's CPUs given to another guest: a slow second with steal is not the service's);
// the workers' largest lag behind their send schedule (a lag means the clients, not the service,
// are the limit); loopback bytes per request. As root the bench re-runs itself in a network
// namespace of its own (as bench_fleet_bytes: `ip netns add pullout-load-<pid>`, lo up, deleted
// at the end), so lo's tx_bytes counts only this run: bytes per request = (window bytes - idle
// rate x window) / sent. Without root (or with --no-netns) that figure is n/a.
//
// --replicas N (N >= 1): the service as N pullout_service processes on the domain, each with
// service.replica.enabled (N = 1: one replica-mode service; 0, the default: the plain service).
// Every service (plain too, unless --config is given) runs with its metrics on a port of its own;
// once every replica is past its start-up sync (kReplicaSync after it was ready) and every client
// matched all N services (Client::matched_services), the run starts. Reported per service: CPU
// over the send window, peak RSS, vehicle sessions held in mid-window (pullout_vehicles) and
// replies published after the drain (pullout_replies_total): how the vehicles were spread. The
// replies of all services add up to the requests answered when each request was answered once.
//
// Bounded: matching kSetupTimeout, then duration + kDrain; the workers and the service are
// stopped by PID (SIGTERM, then SIGKILL) on exit, on SIGINT/SIGTERM and on failure, and any
// /dev/shm file this run left is removed. Prints one markdown row; results go to bench/RESULTS.md.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "load_average.hpp"
#include "percentiles.hpp"
#include "pullout/client/client.hpp"
#include "pullout/config/scenario.hpp"
#include "service_process.hpp"

namespace {

namespace integration = pullout::integration;
using SteadyClock = std::chrono::steady_clock;
using SystemClock = std::chrono::system_clock;
using namespace std::chrono_literals;

constexpr auto kSetupTimeout = 90s;                      // every worker's clients matched with the service
constexpr auto kDrain = 5s;                              // after the last send, for outstanding answers
constexpr auto kIdleWindow = 2s;                         // idle loopback traffic, measured before the send window
constexpr auto kStartMargin = 1s;                        // go -> first send
constexpr auto kReplicaSync = 2500ms;                    // > a replica's start-up sync (4 leases of 500 ms)
constexpr integration::Millis kWorkerStopTimeout{5000};  // SIGTERM -> SIGKILL

std::atomic<bool> g_stop{false};
void on_signal(int /*signal*/) { g_stop.store(true); }

std::string source_path(const std::string& relative) { return std::string(PULLOUT_SOURCE_DIR) + "/" + relative; }

std::string self_exe() {
  char self[4096];
  const ssize_t len = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (len <= 0) throw std::runtime_error("cannot find this executable");
  self[len] = '\0';
  return self;
}

std::int64_t system_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(SystemClock::now().time_since_epoch()).count();
}

// Sleeps until `t` (system clock ns) in short steps; false when stopped by a signal.
bool sleep_until_ns(std::int64_t t) {
  while (!g_stop.load()) {
    const std::int64_t left = t - system_ns();
    if (left <= 0) return true;
    std::this_thread::sleep_for(std::chrono::nanoseconds(std::min<std::int64_t>(left, 50'000'000)));
  }
  return false;
}

// ------------------------------------------------------------------------------------------------
// Worker: its vehicles on one participant, sending on schedule, recording answers.

struct Answer {
  SteadyClock::time_point sent{};
  std::optional<SteadyClock::time_point> path_at;
  std::optional<SteadyClock::time_point> final_at;
  std::int64_t sent_ns{0};       // system clock at send()
  std::int64_t published_ns{0};  // the final status's stamp (the service's clock: same host)
  std::int64_t arrived_ns{0};    // system clock when it arrived
  bool sent_by_us{false};
  bool found{false};
  bool waiting_approval{false};
};

struct VehicleState {
  std::string id;
  std::mutex mutex;
  std::map<std::uint64_t, Answer> answers;  // by request id
  int mismatched_vehicle{0};
};

struct WorkerArgs {
  int domain{0};
  int first{0};  // global index of the first vehicle
  int count{0};
  int total{0};
  int services{1};  // every client waits until its requests reach this many services
  double rate{1.0};
  double duration{10.0};
  bool participant_per_vehicle{false};
  bool endpoints_per_client{false};
  std::string dir;
};

int run_worker(const WorkerArgs& a) {
  const pullout::PullOutRequest base =
      pullout::load_scenario(source_path("tests/scenarios/straight_shoulder.yaml")).request;
  std::optional<pullout::ClientParticipant> participant;
  if (!a.participant_per_vehicle) {
    pullout::ClientParticipantOptions po;
    po.domain_id = a.domain;
    po.shared_endpoints = !a.endpoints_per_client;
    participant.emplace(po);
  }
  const auto t0 = SteadyClock::now();
  const auto note = [&](const char* what) {
    std::printf("%.2f s: %s\n", std::chrono::duration<double>(SteadyClock::now() - t0).count(), what);
    std::fflush(stdout);
  };
  std::vector<std::unique_ptr<VehicleState>> states;
  std::vector<std::unique_ptr<pullout::Client>> clients;
  for (int i = 0; i < a.count && !g_stop.load(); ++i) {
    auto state = std::make_unique<VehicleState>();
    state->id = "load-" + std::to_string(a.first + i);
    pullout::ClientOptions options;
    options.vehicle_id = state->id;
    options.domain_id = a.domain;
    auto client = participant ? std::make_unique<pullout::Client>(*participant, options)
                              : std::make_unique<pullout::Client>(options);
    VehicleState* s = state.get();
    client->on_path([s](const pullout::PullOutPath& p) {
      const auto now = SteadyClock::now();
      std::lock_guard<std::mutex> lock(s->mutex);
      if (p.vehicle_id != s->id) {
        ++s->mismatched_vehicle;
        return;
      }
      Answer& answer = s->answers[p.request_id];
      if (!answer.path_at) {
        answer.path_at = now;
        answer.found = p.found;
      }
    });
    client->on_status([s](const pullout::PullOutStatus& st) {
      const auto now = SteadyClock::now();
      std::lock_guard<std::mutex> lock(s->mutex);
      if (st.vehicle_id != s->id) {
        ++s->mismatched_vehicle;
        return;
      }
      if (st.state == pullout::ExecutionState::kPlanning) return;
      Answer& answer = s->answers[st.request_id];
      if (!answer.final_at) {
        answer.final_at = now;
        answer.published_ns = st.stamp_ns;
        answer.arrived_ns = system_ns();
        answer.waiting_approval = st.state == pullout::ExecutionState::kWaitingApproval;
      }
    });
    states.push_back(std::move(state));
    clients.push_back(std::move(client));
  }
  note("clients created");
  const auto setup_deadline = SteadyClock::now() + kSetupTimeout;
  for (auto& client : clients) {
    if (g_stop.load()) return 3;
    const auto left = setup_deadline - SteadyClock::now();
    if (left <= 0s || !client->wait_for_service(left)) {
      std::fprintf(stderr, "worker %d: %s did not match the service\n", a.first, client->vehicle_id().c_str());
      return 3;
    }
    while (!client->wait_for_services(static_cast<std::size_t>(a.services), 100ms)) {
      if (g_stop.load() || SteadyClock::now() >= setup_deadline) {
        std::fprintf(stderr, "worker %d: %s matched %zu of %d services\n", a.first, client->vehicle_id().c_str(),
                     client->matched_services(), a.services);
        return 3;
      }
    }
  }
  note("clients matched");
  std::ofstream(a.dir + "/ready." + std::to_string(a.first)) << "ready\n";

  // The coordinator writes the start time (system clock ns) into the go file.
  std::int64_t start_ns = 0;
  while (!g_stop.load() && SteadyClock::now() < setup_deadline + kSetupTimeout) {
    std::ifstream go(a.dir + "/go");
    if (go >> start_ns) break;
    std::this_thread::sleep_for(10ms);
  }
  if (start_ns == 0) return 3;

  // Schedule: vehicle g sends at start + g / (total * rate) + k / rate.
  const auto period_ns = static_cast<std::int64_t>(1e9 / a.rate);
  const auto rounds = static_cast<int>(std::llround(a.duration * a.rate));
  double max_lag_ms = 0.0;
  std::uint64_t serial = 0;
  for (int k = 0; k < rounds && !g_stop.load(); ++k) {
    for (int i = 0; i < a.count && !g_stop.load(); ++i) {
      const std::int64_t due =
          start_ns + static_cast<std::int64_t>(k) * period_ns +
          static_cast<std::int64_t>(static_cast<double>(a.first + i) / a.total * static_cast<double>(period_ns));
      if (!sleep_until_ns(due)) break;
      max_lag_ms = std::max(max_lag_ms, static_cast<double>(system_ns() - due) / 1e6);
      // A pose that differs per vehicle and per request (golden-ratio steps: no two alike).
      ++serial;
      const double u = std::fmod(0.618033988749895 * static_cast<double>(serial + a.first), 1.0);
      const double v = std::fmod(0.754877666246693 * static_cast<double>(serial + 7 * a.first), 1.0);
      pullout::PullOutRequest request = base;
      request.ego_pose.x = 6.0 + 24.0 * u;
      request.ego_pose.y = 3.0 + 0.4 * v;
      const auto sent = SteadyClock::now();
      const std::int64_t sent_ns = system_ns();
      const std::uint64_t id = clients[i]->send(request);
      std::lock_guard<std::mutex> lock(states[i]->mutex);
      Answer& answer = states[i]->answers[id];
      answer.sent = sent;
      answer.sent_ns = sent_ns;
      answer.sent_by_us = true;
    }
  }
  note("sending done");
  // Drain: until everything is answered or kDrain.
  const auto drain_end = SteadyClock::now() + kDrain;
  while (!g_stop.load() && SteadyClock::now() < drain_end) {
    bool all = true;
    for (auto& s : states) {
      std::lock_guard<std::mutex> lock(s->mutex);
      for (const auto& [id, answer] : s->answers) all = all && answer.path_at && answer.final_at;
    }
    if (all) break;
    std::this_thread::sleep_for(50ms);
  }

  // One line per request: latency [ms] (-1: lost), planned (0/1); then mismatched.
  std::ofstream out(a.dir + "/result." + std::to_string(a.first) + ".tmp");
  int mismatched = 0;
  for (auto& s : states) {
    std::lock_guard<std::mutex> lock(s->mutex);
    mismatched += s->mismatched_vehicle;
    for (const auto& [id, answer] : s->answers) {
      if (!answer.sent_by_us) {
        ++mismatched;  // a reply to a request this vehicle never sent
        continue;
      }
      double latency = -1.0;
      if (answer.path_at && answer.final_at) {
        latency = std::chrono::duration<double, std::milli>(std::max(*answer.path_at, *answer.final_at) - answer.sent)
                      .count();
      }
      out << latency << ' ' << (answer.found && answer.waiting_approval ? 1 : 0) << ' '
          << (answer.final_at ? static_cast<double>(answer.published_ns - answer.sent_ns) / 1e6 : -1.0) << ' '
          << (answer.final_at ? static_cast<double>(answer.arrived_ns - answer.published_ns) / 1e6 : -1.0) << ' '
          << static_cast<double>(answer.sent_ns - start_ns) / 1e9 << '\n';
    }
  }
  out << "mismatched " << mismatched << "\nmax_lag_ms " << max_lag_ms << '\n';
  out.close();
  std::filesystem::rename(a.dir + "/result." + std::to_string(a.first) + ".tmp",
                          a.dir + "/result." + std::to_string(a.first));
  note("results written");
  // Clients leave only once every worker has its results: a worker that finished first and
  // deleted its clients would load the service (evictions, unregistered instances) while the
  // others still measure their last requests.
  const auto leave_deadline = SteadyClock::now() + kDrain + 30s;
  while (!g_stop.load() && SteadyClock::now() < leave_deadline && !std::filesystem::exists(a.dir + "/leave")) {
    std::this_thread::sleep_for(10ms);
  }
  clients.clear();
  note("clients deleted");
  return 0;
}

// ------------------------------------------------------------------------------------------------
// Coordinator

std::uint64_t lo_tx_bytes() {
  std::ifstream in("/sys/class/net/lo/statistics/tx_bytes");
  std::uint64_t bytes = 0;
  if (!(in >> bytes)) throw std::runtime_error("cannot read /sys/class/net/lo/statistics/tx_bytes");
  return bytes;
}

// utime + stime of a process [clock ticks] (0 if gone).
std::uint64_t cpu_ticks(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');  // the command name may contain spaces
  if (close == std::string::npos) return 0;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  std::uint64_t utime = 0;
  std::uint64_t stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return utime + stime;
}

// Machine CPU from /proc/stat, in jiffies: busy (user to softirq, without idle and iowait),
// steal (time the hypervisor gave this VM's CPUs to someone else) and the total of all eight.
struct MachineJiffies {
  std::uint64_t busy = 0;
  std::uint64_t steal = 0;
  std::uint64_t total = 0;
};

MachineJiffies machine_jiffies() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  in >> cpu;
  MachineJiffies m;
  std::uint64_t v = 0;
  for (int i = 0; i < 8 && in >> v; ++i) {  // user nice system idle iowait irq softirq steal
    m.total += v;
    if (i == 7) {
      m.steal += v;
    } else if (i != 3 && i != 4) {
      m.busy += v;
    }
  }
  return m;
}

double share_percent(std::uint64_t part, std::uint64_t total) {
  return 100.0 * static_cast<double>(part) / static_cast<double>(std::max<std::uint64_t>(1, total));
}

double vm_kb(pid_t pid, const std::string& key) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string k;
  while (in >> k) {
    if (k == key + ":") {
      double kb = 0;
      in >> kb;
      return kb;
    }
    in.ignore(4096, '\n');
  }
  return -1.0;
}

// UDP datagrams dropped for a full receive buffer (RcvbufErrors in /proc/net/snmp: this network
// namespace's counters).
std::uint64_t udp_rcvbuf_errors() {
  std::ifstream in("/proc/net/snmp");
  std::string line;
  std::vector<std::string> names;
  while (std::getline(in, line)) {
    if (line.rfind("Udp:", 0) != 0) continue;
    std::istringstream fields(line.substr(4));
    std::vector<std::string> values{std::istream_iterator<std::string>(fields), std::istream_iterator<std::string>()};
    if (names.empty()) {
      names = values;
      continue;
    }
    for (std::size_t i = 0; i < names.size() && i < values.size(); ++i) {
      if (names[i] == "RcvbufErrors") return std::stoull(values[i]);
    }
  }
  return 0;
}

// GET http://127.0.0.1:port/path (HTTP/1.0); the body, or "" on any failure (2 s timeouts).
std::string http_get(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "";
  timeval timeout{2, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof(timeout));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string response;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) {
    const std::string request = "GET " + path + " HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n";
    if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(request.size())) {
      char buf[8192];
      ssize_t n = 0;
      while ((n = ::recv(fd, buf, sizeof(buf), 0)) > 0) response.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  const auto body = response.find("\r\n\r\n");
  return body == std::string::npos ? "" : response.substr(body + 4);
}

// The sum of a metric's samples (every label set) in Prometheus text; -1 when absent.
double metric_sum(const std::string& text, const std::string& name) {
  std::istringstream lines(text);
  std::string line;
  double sum = -1.0;
  while (std::getline(lines, line)) {
    if (line.rfind(name, 0) != 0 || line.size() <= name.size()) continue;
    const char next = line[name.size()];
    if (next != ' ' && next != '{') continue;
    const auto space = line.rfind(' ');
    sum = std::max(sum, 0.0) + std::stod(line.substr(space + 1));
  }
  return sum;
}

using pullout::bench::load_text;

struct Options {
  int vehicles{1000};
  int processes{4};
  double rate{1.0};
  double duration{30.0};
  bool participant_per_vehicle{false};
  bool endpoints_per_client{false};
  bool no_netns{false};
  bool inside{false};
  int replicas{0};  // 0: the plain service
  bool config_given{false};
  std::string service_exe{PULLOUT_SERVICE_EXE};
  std::string config_path{source_path("config/pullout.yaml")};
};

int run_coordinator(const Options& o) {
  const bool count_bytes = o.inside;
  const std::set<std::string> shm_before = integration::list_dev_shm();
  integration::TempDir dir;
  // The services: one plain, or o.replicas in replica mode, each with its metrics port (unless
  // --config: then as that file says, and no per-service counts).
  const int services_n = std::max(1, o.replicas);
  const bool metrics = !o.config_given;
  const int port_base = 20000 + (::getpid() % 10000) * 4;
  std::vector<std::unique_ptr<integration::ServiceProcess>> services;
  for (int r = 0; r < services_n; ++r) {
    integration::ServiceOptions service_options;
    service_options.executable = o.service_exe;
    service_options.config_path = o.config_path;
    if (metrics) {
      service_options.config_path = dir.write_file(
          "service." + std::to_string(r) + ".yaml",
          std::string(o.replicas > 0 ? "service:\n  replica:\n    enabled: true\n" : "") +
              "observability:\n  metrics:\n    enabled: true\n    port: " + std::to_string(port_base + r) + "\n");
    }
    if (!services.empty()) service_options.domain = services.front()->domain();
    services.push_back(std::make_unique<integration::ServiceProcess>(service_options));
  }
  integration::ServiceProcess& service = *services.front();
  // Each replica past its start-up sync, which is bounded by four leases (default 500 ms; the
  // bench sets no other): no metric tells it apart from a replica still syncing, and a request
  // read meanwhile waits in the reader, so this only keeps the sync out of the send window.
  if (o.replicas > 0) std::this_thread::sleep_for(kReplicaSync);
  std::printf("bench_load: %d vehicles in %d processes (%s), %.2f Hz each, %.0f s; %s; domain %d; load %s\n",
              o.vehicles, o.processes,
              o.participant_per_vehicle ? "one participant per vehicle"
              : o.endpoints_per_client  ? "shared participant, endpoints per client"
                                        : "shared participant and endpoints",
              o.rate, o.duration,
              o.replicas == 0 ? "plain service" : (std::to_string(o.replicas) + " replica(s)").c_str(),
              service.domain(), load_text().c_str());
  std::fflush(stdout);

  std::vector<std::unique_ptr<integration::ChildProcess>> workers;
  std::vector<int> firsts;
  // On every exit: SIGTERM to all workers at once, then each is reaped (SIGKILL after a timeout).
  struct StopWorkers {
    std::vector<std::unique_ptr<integration::ChildProcess>>& workers;
    ~StopWorkers() {
      for (auto& w : workers) {
        if (w->running()) ::kill(w->pid(), SIGTERM);
      }
      for (auto& w : workers) w->stop(kWorkerStopTimeout);
    }
  } stop_workers{workers};
  const auto setup_start = SteadyClock::now();
  for (int p = 0; p < o.processes; ++p) {
    const int first = o.vehicles * p / o.processes;
    const int count = o.vehicles * (p + 1) / o.processes - first;
    std::vector<std::string> argv{self_exe(),   "--worker",
                                  "--domain",   std::to_string(service.domain()),
                                  "--first",    std::to_string(first),
                                  "--count",    std::to_string(count),
                                  "--vehicles", std::to_string(o.vehicles),
                                  "--rate",     std::to_string(o.rate),
                                  "--duration", std::to_string(o.duration),
                                  "--services", std::to_string(services_n),
                                  "--dir",      dir.path()};
    if (o.participant_per_vehicle) argv.push_back("--participant-per-vehicle");
    if (o.endpoints_per_client) argv.push_back("--endpoints-per-client");
    workers.push_back(
        std::make_unique<integration::ChildProcess>(argv, dir.path() + "/worker." + std::to_string(first) + ".out",
                                                    dir.path() + "/worker." + std::to_string(first) + ".err"));
    firsts.push_back(first);
  }
  // Every worker ready (its clients matched), bounded.
  const auto ready = [&] {
    for (int first : firsts) {
      if (!std::filesystem::exists(dir.path() + "/ready." + std::to_string(first))) return false;
    }
    return true;
  };
  while (!ready()) {
    for (std::size_t i = 0; i < workers.size(); ++i) {
      if (!workers[i]->running()) {
        throw std::runtime_error(
            "worker " + std::to_string(firsts[i]) + " exited during setup: " +
            integration::read_file_tail(dir.path() + "/worker." + std::to_string(firsts[i]) + ".err", 2000));
      }
    }
    if (g_stop.load() || SteadyClock::now() - setup_start > kSetupTimeout) {
      std::string progress;
      for (int first : firsts) {
        progress += "\nworker " + std::to_string(first) + ":\n" +
                    integration::read_file_tail(dir.path() + "/worker." + std::to_string(first) + ".out", 500);
      }
      throw std::runtime_error("the workers' clients did not all match the service in time" + progress);
    }
    std::this_thread::sleep_for(50ms);
  }
  const double setup_s = std::chrono::duration<double>(SteadyClock::now() - setup_start).count();

  // Idle loopback traffic, then go.
  std::uint64_t idle_bytes = 0;
  if (count_bytes) {
    std::this_thread::sleep_for(1s);
    const std::uint64_t b0 = lo_tx_bytes();
    std::this_thread::sleep_for(kIdleWindow);
    idle_bytes = lo_tx_bytes() - b0;
  }
  const std::int64_t start_ns = system_ns() + std::chrono::nanoseconds(kStartMargin).count();
  {
    std::ofstream go(dir.path() + "/go.tmp");
    go << start_ns << '\n';
  }
  std::filesystem::rename(dir.path() + "/go.tmp", dir.path() + "/go");
  if (!sleep_until_ns(start_ns)) throw std::runtime_error("stopped by a signal");
  const std::uint64_t bytes0 = count_bytes ? lo_tx_bytes() : 0;
  std::vector<std::uint64_t> service0;
  for (auto& sp : services) service0.push_back(cpu_ticks(sp->pid()));
  std::uint64_t workers0 = 0;
  for (auto& w : workers) workers0 += cpu_ticks(w->pid());
  const auto machine0 = machine_jiffies();
  const std::uint64_t drops0 = udp_rcvbuf_errors();
  const std::int64_t end_ns = start_ns + static_cast<std::int64_t>(o.duration * 1e9);
  // The machine's steal by second of the window: on a shared VM, a second in which the hypervisor
  // ran someone else on these CPUs shows up as a slow second that is not the service's.
  std::vector<double> steal_by_second;
  std::vector<double> vehicles_mid;
  bool mid_sampled = false;
  MachineJiffies machine1 = machine0;
  for (std::int64_t k = 1;; ++k) {
    const std::int64_t t = std::min<std::int64_t>(end_ns, start_ns + k * 1'000'000'000);
    if (!sleep_until_ns(t)) throw std::runtime_error("stopped by a signal");
    const MachineJiffies now = machine_jiffies();
    steal_by_second.push_back(share_percent(now.steal - machine1.steal, now.total - machine1.total));
    machine1 = now;
    // Per service: vehicle sessions held in mid-window (every vehicle has asked by then, and none
    // has left: the workers delete their clients once all results are in).
    if (!mid_sampled && t >= start_ns + (end_ns - start_ns) / 2) {
      mid_sampled = true;
      for (int r = 0; metrics && r < services_n; ++r) {
        vehicles_mid.push_back(metric_sum(http_get(port_base + r, "/metrics"), "pullout_vehicles"));
      }
    }
    if (t >= end_ns) break;
  }
  const std::uint64_t bytes1 = count_bytes ? lo_tx_bytes() : 0;
  std::vector<std::uint64_t> service1;
  for (auto& sp : services) service1.push_back(cpu_ticks(sp->pid()));
  std::uint64_t workers1 = 0;
  for (auto& w : workers) workers1 += cpu_ticks(w->pid());
  const std::uint64_t drops = udp_rcvbuf_errors() - drops0;
  const std::string load_after = load_text();

  // Results: each worker writes its file after its drain (then deletes its clients).
  const auto results_deadline = SteadyClock::now() + kDrain + 30s;
  for (std::size_t i = 0; i < workers.size(); ++i) {
    const std::string file = dir.path() + "/result." + std::to_string(firsts[i]);
    while (!std::filesystem::exists(file)) {
      if (g_stop.load() || SteadyClock::now() > results_deadline || !workers[i]->running()) {
        throw std::runtime_error(
            "worker " + std::to_string(firsts[i]) + " wrote no result: " +
            integration::read_file_tail(dir.path() + "/worker." + std::to_string(firsts[i]) + ".out", 2000) +
            integration::read_file_tail(dir.path() + "/worker." + std::to_string(firsts[i]) + ".err", 2000));
      }
      std::this_thread::sleep_for(50ms);
    }
  }
  std::ofstream(dir.path() + "/leave") << "leave\n";
  std::printf(
      "worker %d: %s", firsts.front(),
      integration::read_file_tail(dir.path() + "/worker." + std::to_string(firsts.front()) + ".out", 2000).c_str());
  std::vector<double> hwm_mb;
  std::vector<double> replies_after_drain;
  for (int r = 0; r < services_n; ++r) {
    hwm_mb.push_back(vm_kb(services[r]->pid(), "VmHWM") / 1024.0);
    if (metrics)
      replies_after_drain.push_back(metric_sum(http_get(port_base + r, "/metrics"), "pullout_replies_total"));
  }
  std::vector<double> latencies;
  std::vector<std::vector<double>> by_second;  // latencies by the second of the send window (lost: inf)
  // The two parts of the answered ones by second: at the service or in delivery.
  std::vector<std::vector<double>> to_service_by_second;
  std::vector<std::vector<double>> from_service_by_second;
  std::vector<double> to_service_ms;    // send() -> the final status published
  std::vector<double> from_service_ms;  // published -> arrived
  std::size_t sent = 0;
  std::size_t lost = 0;
  std::size_t not_planned = 0;
  int mismatched = 0;
  double max_lag_ms = 0.0;
  for (int first : firsts) {
    std::ifstream in(dir.path() + "/result." + std::to_string(first));
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string head;
      fields >> head;
      if (head == "mismatched") {
        int m = 0;
        fields >> m;
        mismatched += m;
      } else if (head == "max_lag_ms") {
        double lag = 0;
        fields >> lag;
        max_lag_ms = std::max(max_lag_ms, lag);
      } else if (!head.empty()) {
        const double latency = std::stod(head);
        int planned = 0;
        double to_service = -1.0;
        double from_service = -1.0;
        double sent_s = 0.0;
        fields >> planned >> to_service >> from_service >> sent_s;
        const auto second = static_cast<std::size_t>(std::clamp(sent_s, 0.0, 1e4));
        if (by_second.size() <= second) by_second.resize(second + 1);
        by_second[second].push_back(latency < 0 ? std::numeric_limits<double>::infinity() : latency);
        if (to_service >= 0.0 || from_service >= 0.0) {
          to_service_ms.push_back(to_service);
          from_service_ms.push_back(from_service);
          if (to_service_by_second.size() <= second) {
            to_service_by_second.resize(second + 1);
            from_service_by_second.resize(second + 1);
          }
          to_service_by_second[second].push_back(to_service);
          from_service_by_second[second].push_back(from_service);
        }
        ++sent;
        if (latency < 0) {
          ++lost;
        } else {
          latencies.push_back(latency);
          if (planned == 0) ++not_planned;
        }
      }
    }
  }
  const pullout::bench::Summary s = pullout::bench::summarize(latencies);
  const double ticks = static_cast<double>(::sysconf(_SC_CLK_TCK));
  std::string service_cpu_text;
  std::string hwm_text;
  std::string spread_text;
  double replies_sum = 0.0;
  for (int r = 0; r < services_n; ++r) {
    const char* sep = r == 0 ? "" : " / ";
    char buf[96];
    std::snprintf(buf, sizeof(buf), "%s%.0f", sep,
                  100.0 * static_cast<double>(service1[r] - service0[r]) / ticks / o.duration);
    service_cpu_text += buf;
    std::snprintf(buf, sizeof(buf), "%s%.1f", sep, hwm_mb[r]);
    hwm_text += buf;
    if (metrics) {
      std::snprintf(buf, sizeof(buf), "%s%.0f (%.0f)", sep, vehicles_mid[r], replies_after_drain[r]);
      spread_text += buf;
      replies_sum += replies_after_drain[r];
    }
  }
  if (!metrics) spread_text = "n/a";
  const double workers_cpu = 100.0 * static_cast<double>(workers1 - workers0) / ticks / o.duration;
  const double machine_busy = share_percent(machine1.busy - machine0.busy, machine1.total - machine0.total);
  const double machine_steal = share_percent(machine1.steal - machine0.steal, machine1.total - machine0.total);
  std::string bytes_text = "n/a";
  if (count_bytes && sent > 0) {
    const double window_s = static_cast<double>(end_ns - start_ns) / 1e9;
    const double idle_rate = static_cast<double>(idle_bytes) / std::chrono::duration<double>(kIdleWindow).count();
    const double per_request =
        (static_cast<double>(bytes1 - bytes0) - idle_rate * window_s) / static_cast<double>(sent);
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.0f", per_request);
    bytes_text = buf;
  }
  std::printf(
      "setup (all clients matched) %.1f s; load after: %s; max send lag %.1f ms; UDP receive-buffer drops %llu%s\n",
      setup_s, load_after.c_str(), max_lag_ms, static_cast<unsigned long long>(drops),
      count_bytes ? "" : " (host-wide)");
  const pullout::bench::Summary to = pullout::bench::summarize(to_service_ms);
  const pullout::bench::Summary from = pullout::bench::summarize(from_service_ms);
  std::printf("send -> final status published: p50 %.2f p99 %.2f ms; published -> arrived: p50 %.2f p99 %.2f ms\n",
              to.p50, to.p99, from.p50, from.p99);
  // Where in the window the slow replies are (warm-up, a stall, or throughout).
  std::printf("p99 [ms] by second of the send window:");
  for (const std::vector<double>& second : by_second) std::printf(" %.0f", pullout::bench::summarize(second).p99);
  std::printf("\n");
  std::printf("  of which send -> published:");
  for (const std::vector<double>& second : to_service_by_second) {
    std::printf(" %.0f", pullout::bench::summarize(second).p99);
  }
  std::printf("\n  and published -> arrived:  ");
  for (const std::vector<double>& second : from_service_by_second) {
    std::printf(" %.0f", pullout::bench::summarize(second).p99);
  }
  std::printf("\n");
  std::printf("machine steal [%%] by second (whole window %.1f %%):", machine_steal);
  for (const double steal : steal_by_second) std::printf(" %.0f", steal);
  std::printf("\n");
  if (metrics) {
    std::printf("replies published by the services after the drain: %.0f (requests answered: %zu)\n", replies_sum,
                latencies.size());
  }
  std::printf("\n");
  std::printf(
      "| service | vehicles | processes | participants | rate [Hz] | sent | replies/s | p50 [ms] | p99 [ms] | max [ms] "
      "| "
      "lost | mismatched | not planned | service CPU [%% core] | service peak RSS [MB] | vehicles (replies) per "
      "service | workers CPU [%% core] | machine busy [%%] | bytes/request |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::printf(
      "| %s | %d | %d | %s | %.2f | %zu | %.1f | %.2f | %.2f | %.2f | %zu | %d | %zu | %s | %s | %s | %.0f | %.0f | %s "
      "|\n",
      o.replicas == 0 ? "plain" : (std::to_string(o.replicas) + (o.replicas == 1 ? " replica" : " replicas")).c_str(),
      o.vehicles, o.processes,
      o.participant_per_vehicle ? "1 per vehicle"
      : o.endpoints_per_client  ? "1 per process, endpoints per client"
                                : "1 per process, shared endpoints",
      o.rate, sent, static_cast<double>(latencies.size()) / o.duration, s.p50, s.p99, s.max, lost, mismatched,
      not_planned, service_cpu_text.c_str(), hwm_text.c_str(), spread_text.c_str(), workers_cpu, machine_busy,
      bytes_text.c_str());

  for (auto& w : workers) {
    if (w->running()) ::kill(w->pid(), SIGTERM);
  }
  for (auto& w : workers) w->stop(kWorkerStopTimeout);
  for (std::size_t r = 0; r < services.size(); ++r) {
    const integration::StopReport report = services[r]->stop();
    if (!report.clean()) std::printf("service %zu stop: %s\n", r, report.describe().c_str());
  }
  // Anything this run left in /dev/shm and no live process holds.
  const std::set<std::string> in_use = integration::dev_shm_files_in_use();
  for (const auto& name : integration::list_dev_shm()) {
    if (shm_before.count(name) == 0 && in_use.count(name) == 0) {
      std::error_code ec;
      std::filesystem::remove("/dev/shm/" + name, ec);
    }
  }
  return lost == 0 && mismatched == 0 && sent > 0 ? 0 : 1;
}

// Outside: runs the coordinator in a network namespace of its own, forwarding SIGINT/SIGTERM to
// it, and deletes the namespace afterwards.
int run_in_netns(int argc, char** argv) {
  const std::string ns = "pullout-load-" + std::to_string(::getpid());
  if (std::system(("ip netns add " + ns).c_str()) != 0) throw std::runtime_error("ip netns add " + ns + " failed");
  int rc = 1;
  if (std::system(("ip -n " + ns + " link set lo up").c_str()) == 0) {
    std::vector<std::string> args{"ip", "netns", "exec", ns, self_exe(), "--inside"};
    for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
    const pid_t child = ::fork();
    if (child == 0) {
      std::vector<char*> c_args;
      for (auto& a : args) c_args.push_back(a.data());
      c_args.push_back(nullptr);
      ::execvp("ip", c_args.data());
      ::_exit(127);
    }
    int status = 0;
    while (::waitpid(child, &status, 0) < 0) {
      if (errno != EINTR) break;
      if (g_stop.load()) ::kill(child, SIGTERM);
    }
    rc = WIFEXITED(status) ? WEXITSTATUS(status) : 1;
  } else {
    std::fprintf(stderr, "bench_load: cannot bring lo up in %s\n", ns.c_str());
  }
  std::system(("ip netns delete " + ns).c_str());
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  struct sigaction action {};
  action.sa_handler = on_signal;  // no SA_RESTART: waitpid returns EINTR
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);

  CLI::App app{"Load: many vehicles over several processes against one pullout_service"};
  Options o;
  WorkerArgs w;
  bool worker = false;
  app.add_option("--vehicles", o.vehicles, "vehicles in all")->check(CLI::Range(1, 4000));
  app.add_option("--processes", o.processes, "worker processes")->check(CLI::Range(1, 16));
  app.add_option("--rate", o.rate, "requests per second per vehicle")->check(CLI::Range(0.01, 100.0));
  app.add_option("--duration", o.duration, "seconds of sending")->check(CLI::Range(1.0, 150.0));
  app.add_flag("--participant-per-vehicle", o.participant_per_vehicle, "one DDS participant per vehicle");
  app.add_flag("--endpoints-per-client", o.endpoints_per_client,
               "each client with endpoints of its own on the shared participant (as before)");
  app.add_flag("--no-netns", o.no_netns, "do not use a network namespace (no byte count)");
  app.add_option("--service", o.service_exe, "the pullout_service binary");
  app.add_option("--config", o.config_path, "the service's config (then no per-service counts)");
  app.add_option("--replicas", o.replicas, "0: the plain service; N: N services in replica mode on the domain")
      ->check(CLI::Range(0, 8));
  app.add_flag("--inside", o.inside, "(internal) inside the namespace");
  app.add_flag("--worker", worker, "(internal) a worker process");
  app.add_option("--domain", w.domain, "(internal)");
  app.add_option("--first", w.first, "(internal)");
  app.add_option("--count", w.count, "(internal)");
  app.add_option("--dir", w.dir, "(internal)");
  app.add_option("--services", w.services, "(internal)");
  CLI11_PARSE(app, argc, argv);
  o.config_given = app.count("--config") > 0;
  try {
    if (worker) {
      w.total = o.vehicles;
      w.rate = o.rate;
      w.duration = o.duration;
      w.participant_per_vehicle = o.participant_per_vehicle;
      w.endpoints_per_client = o.endpoints_per_client;
      return run_worker(w);
    }
    if (o.processes > o.vehicles) throw std::runtime_error("--processes exceeds --vehicles");
    if (!o.inside && !o.no_netns && ::geteuid() == 0) return run_in_netns(argc, argv);
    return run_coordinator(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_load%s: %s\n", worker ? " worker" : "", e.what());
    return 1;
  }
}
