// Loopback bytes per request against the size of the fleet: does a reply to one vehicle cross the
// wire to every vehicle?
//
//   bench_fleet_bytes [--clients 1,10,50,100] [--requests 20] [--fleet] [--service PATH] [--config FILE]
//
// Needs root (it creates a network namespace). The bench re-runs itself inside a namespace of its
// own (`ip netns add pullout-bytes-<pid>`, `ip -n NS link set lo up`, `ip netns exec NS ...`), so
// that /sys/class/net/lo/statistics/tx_bytes counts only the traffic of this run, and deletes the
// namespace afterwards (also on failure). Inside, for each fleet size N: the real pullout_service
// (--service, default the one built with this tree; --config, default config/pullout.yaml with
// config/dds/loopback.xml) and N pullout::Client participants of distinct vehicles in this
// process (built-in loopback QoS). Once every client matched the service, it measures
//   idle      tx_bytes over a window with no request (discovery announcements, heartbeats), then
//   requests  `requests` straight_shoulder requests, one every kRequestSpacing, from the vehicles
//             in turn, each waited for (path, then a status past planning), then kTail (so late
//             acknowledgements are counted); with --fleet, `requests` rounds one second apart in
//             which every vehicle sends one request (the whole fleet at 1 Hz), all waited for;
// bytes per request = (requests window bytes - idle bytes scaled to the same duration) / requests
// sent.
// A service that delivers each vehicle only its own samples keeps that figure flat in N; one that
// sends every reply to every reader makes it grow with N (N^2 for the fleet).
//
// Prints a markdown table. Results go to bench/RESULTS.md by hand. Every wait is bounded.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "pullout/client/client.hpp"
#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"
#include "service_process.hpp"

namespace {

namespace integration = pullout::integration;
using SteadyClock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr auto kMatchTimeout = 30s;
constexpr auto kReplyTimeout = 10s;
// Long enough for the writer's heartbeat round (200 ms in the profiles) to finish between requests.
constexpr auto kRequestSpacing = 300ms;
constexpr auto kTail = 1s;
constexpr auto kSettle = 2s;  // after matching, before the idle window

std::string source_path(const std::string& relative) { return std::string(PULLOUT_SOURCE_DIR) + "/" + relative; }

std::uint64_t lo_tx_bytes() {
  std::ifstream in("/sys/class/net/lo/statistics/tx_bytes");
  std::uint64_t bytes = 0;
  if (!(in >> bytes)) throw std::runtime_error("cannot read /sys/class/net/lo/statistics/tx_bytes");
  return bytes;
}

std::string self_exe() {
  char self[4096];
  const ssize_t len = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (len <= 0) throw std::runtime_error("cannot find this executable");
  self[len] = '\0';
  return self;
}

int run_command(const std::vector<std::string>& argv) {
  std::string line;
  for (const auto& a : argv) line += (line.empty() ? "" : " ") + a;
  const int rc = std::system(line.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

struct Row {
  int clients{0};
  int answered{0};
  int sent{0};
  double idle_bytes_per_s{0};
  double bytes_per_request{0};
};

bool answered(pullout::Client& client, std::uint64_t id) {
  const bool path = client.wait_for_path(id, kReplyTimeout).has_value();
  const bool status =
      client
          .wait_for_status(
              id, [](const pullout::PullOutStatus& s) { return s.state != pullout::ExecutionState::kPlanning; },
              kReplyTimeout)
          .has_value();
  return path && status;
}

Row measure(int clients, int requests, bool fleet_mode, const std::string& service_exe,
            const std::string& config_path) {
  const pullout::Config config = pullout::load_config(config_path);
  const pullout::Scenario scenario =
      pullout::load_scenario(source_path("tests/scenarios/straight_shoulder.yaml"), config);
  integration::DomainLease lease;
  integration::ServiceOptions options;
  options.executable = service_exe;
  options.config_path = config_path;
  options.domain = lease.domain();
  integration::ServiceProcess service(options);

  std::vector<std::unique_ptr<pullout::Client>> fleet;
  for (int i = 0; i < clients; ++i) {
    pullout::ClientOptions o;
    o.vehicle_id = "bench-vehicle-" + std::to_string(i);
    o.domain_id = lease.domain();
    fleet.push_back(std::make_unique<pullout::Client>(o));
  }
  for (auto& c : fleet) {
    if (!c->wait_for_service(kMatchTimeout)) throw std::runtime_error(c->vehicle_id() + " did not match the service");
  }
  std::this_thread::sleep_for(kSettle);

  const auto spacing = fleet_mode ? std::chrono::milliseconds(1000) : kRequestSpacing;
  const auto window = spacing * requests + kTail;
  const std::uint64_t idle0 = lo_tx_bytes();
  const auto idle_t0 = SteadyClock::now();
  std::this_thread::sleep_for(window);
  const double idle_s = std::chrono::duration<double>(SteadyClock::now() - idle_t0).count();
  const std::uint64_t idle_bytes = lo_tx_bytes() - idle0;

  Row row;
  row.clients = clients;
  const std::uint64_t t0_bytes = lo_tx_bytes();
  const auto t0 = SteadyClock::now();
  int sent = 0;
  for (int r = 0; r < requests; ++r) {
    const auto next = t0 + spacing * (r + 1);
    if (fleet_mode) {
      std::vector<std::uint64_t> ids;
      for (auto& c : fleet) ids.push_back(c->send(scenario.request));
      for (std::size_t i = 0; i < fleet.size(); ++i) row.answered += answered(*fleet[i], ids[i]) ? 1 : 0;
      sent += static_cast<int>(fleet.size());
    } else {
      pullout::Client& client = *fleet[static_cast<std::size_t>(r) % fleet.size()];
      row.answered += answered(client, client.send(scenario.request)) ? 1 : 0;
      ++sent;
    }
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(kTail);
  const double busy_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  const std::uint64_t busy_bytes = lo_tx_bytes() - t0_bytes;
  row.idle_bytes_per_s = static_cast<double>(idle_bytes) / idle_s;
  row.bytes_per_request = (static_cast<double>(busy_bytes) - row.idle_bytes_per_s * busy_s) / sent;
  row.sent = sent;
  fleet.clear();
  service.stop();
  return row;
}

int run_inside(const std::vector<int>& sizes, int requests, bool fleet_mode, const std::string& service_exe,
               const std::string& config_path) {
  std::vector<Row> rows;
  for (int n : sizes) {
    rows.push_back(measure(n, requests, fleet_mode, service_exe, config_path));
    std::fprintf(stderr, "clients %d: %.0f bytes/request\n", n, rows.back().bytes_per_request);
  }
  std::printf("service: %s; %s\n\n", service_exe.c_str(),
              fleet_mode ? "every vehicle once a second" : "one request at a time, vehicles in turn");
  std::printf("| clients | answered | idle [B/s] | bytes per request |\n|---|---|---|---|\n");
  for (const Row& r : rows) {
    std::printf("| %d | %d/%d | %.0f | %.0f |\n", r.clients, r.answered, r.sent, r.idle_bytes_per_s,
                r.bytes_per_request);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"loopback bytes per request against the number of client participants"};
  std::string sizes_text = "1,10,50,100";
  int requests = 20;
  std::string service_exe = PULLOUT_SERVICE_EXE;
  std::string config_path = source_path("config/pullout.yaml");
  bool inside = false;
  bool fleet_mode = false;
  app.add_option("--clients", sizes_text, "fleet sizes, comma separated");
  app.add_option("--requests", requests, "requests per fleet size")->check(CLI::Range(1, 10000));
  app.add_option("--service", service_exe, "the pullout_service binary");
  app.add_option("--config", config_path, "the service's config");
  app.add_flag("--fleet", fleet_mode, "every vehicle sends once a second (rounds), instead of one at a time");
  app.add_flag("--inside", inside, "(internal) already inside the namespace");
  CLI11_PARSE(app, argc, argv);
  std::vector<int> sizes;
  {
    std::stringstream in(sizes_text);
    std::string item;
    while (std::getline(in, item, ',')) sizes.push_back(std::stoi(item));
  }
  try {
    if (inside) return run_inside(sizes, requests, fleet_mode, service_exe, config_path);
    if (::geteuid() != 0) {
      std::fprintf(stderr, "bench_fleet_bytes: needs root (ip netns)\n");
      return 2;
    }
    const std::string ns = "pullout-bytes-" + std::to_string(::getpid());
    if (run_command({"ip", "netns", "add", ns}) != 0) throw std::runtime_error("ip netns add " + ns + " failed");
    int rc = 1;
    if (run_command({"ip", "-n", ns, "link", "set", "lo", "up"}) == 0) {
      std::vector<std::string> argv{"ip",       "netns",     "exec",     ns,           self_exe(),
                                    "--inside", "--clients", sizes_text, "--requests", std::to_string(requests),
                                    "--config", config_path};
      // Only when not the default: the inner command line then does not name pullout_service
      // (a cleanup by process name elsewhere on a shared machine would take the bench for it).
      if (service_exe != PULLOUT_SERVICE_EXE) {
        argv.push_back("--service");
        argv.push_back(service_exe);
      }
      if (fleet_mode) argv.push_back("--fleet");
      rc = run_command(argv);
    } else {
      std::fprintf(stderr, "bench_fleet_bytes: cannot bring lo up in %s\n", ns.c_str());
    }
    run_command({"ip", "netns", "delete", ns});
    return rc;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_fleet_bytes: %s\n", e.what());
    return 1;
  }
}
