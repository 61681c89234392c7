// A lifetime of vehicles against one pullout_service on loopback: memory stays flat and the last
// vehicle is served like the first.
//
//   bench_fleet_churn [--vehicles 50000] [--clients 4] [--rate 600] [--max-seconds 300]
//                     [--huge 6] [--huge-objects 300000]
//
// On a DDS domain leased for the run, the real pullout_service with config/pullout.yaml
// (config/dds/loopback.xml: max_instances 4096, service.max_vehicles 2048):
//   1. huge rejections  `huge` requests of `huge-objects` objects each (over
//                       service.limits.max_objects, so rejected), each from a new vehicle that
//                       leaves after its answer; the service's RSS before and after.
//   2. churn            `clients` FleetClients (tests/integration/fleet_client.hpp: one
//                       participant each, speaking for ever new vehicle ids), together at most
//                       `rate` new vehicles per second: a straight_shoulder request, the answer
//                       (path and final status), then unregister the vehicle's request instance.
//                       Latency = write -> path and final status taken. The service's VmRSS
//                       (/proc/PID/status) is sampled every second.
// Prints markdown tables (RSS over time, latency of the first and last 1,000 vehicles, vehicles
// not answered or answered otherwise than waiting_approval: both must be 0). Bounded by
// --max-seconds; the service is stopped by PID (SIGTERM, SIGKILL after a timeout) also on failure.
#include <stdlib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "fleet_client.hpp"
#include "load_average.hpp"
#include "percentiles.hpp"
#include "pullout/config/scenario.hpp"
#include "service_process.hpp"

namespace {

namespace integration = pullout::integration;
using SteadyClock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr auto kAnswerTimeout = 5000ms;
constexpr std::size_t kWindow = 1000;  // first and last vehicles compared

std::string source_path(const std::string& relative) { return std::string(PULLOUT_SOURCE_DIR) + "/" + relative; }

// VmRSS of a process [MB] (-1 if it cannot be read).
double rss_mb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (in >> key) {
    if (key == "VmRSS:") {
      double kb = 0;
      in >> kb;
      return kb / 1024.0;
    }
    in.ignore(4096, '\n');
  }
  return -1.0;
}

using pullout::bench::summarize;
using pullout::bench::Summary;

using pullout::bench::load_text;

struct Outcome {
  double latency_ms{-1.0};  // < 0: not answered
  bool as_expected{false};  // waiting_approval with a found path
};

int run(int argc, char** argv) {
  CLI::App app{"Fleet churn: many distinct vehicle ids over time against one pullout_service"};
  std::size_t vehicles = 50000;
  int clients = 4;
  double rate = 600.0;
  double max_seconds = 300.0;
  int huge = 6;
  std::size_t huge_objects = 300000;
  app.add_option("--vehicles", vehicles, "distinct vehicle ids in the churn");
  app.add_option("--clients", clients, "client participants (one thread each)")->check(CLI::Range(1, 64));
  app.add_option("--rate", rate, "new vehicles per second, all clients together (0: as fast as answered)");
  app.add_option("--max-seconds", max_seconds, "stop the churn after this long");
  app.add_option("--huge", huge, "huge rejected requests before the churn");
  app.add_option("--huge-objects", huge_objects, "objects in each huge request");
  CLI11_PARSE(app, argc, argv);

  integration::ServiceOptions options;
  options.executable = PULLOUT_SERVICE_EXE;
  options.config_path = source_path("config/pullout.yaml");
  integration::ServiceProcess service(options);
  const pid_t pid = service.pid();
  const std::string profiles = source_path("config/dds/loopback.xml");
  const pullout::PullOutRequest base =
      pullout::load_scenario(source_path("tests/scenarios/straight_shoulder.yaml")).request;
  std::printf("bench_fleet_churn: domain %d, service pid %d, load %s\n\n", service.domain(), static_cast<int>(pid),
              load_text().c_str());

  // ---- 1. huge rejected requests ----
  {
    integration::FleetClient client(service.domain(), profiles);
    if (!client.wait_matched(15s)) throw std::runtime_error("the service did not match the client");
    std::this_thread::sleep_for(500ms);
    const double before = rss_mb(pid);
    std::printf("| huge rejected requests (%zu objects each) | service RSS [MB] |\n|---|---|\n| 0 | %.1f |\n",
                huge_objects, before);
    pullout::PullOutRequest r = base;
    r.objects.assign(huge_objects, pullout::Object{});
    for (std::size_t i = 0; i < r.objects.size(); ++i) {
      pullout::Object& o = r.objects[i];
      o.id = static_cast<std::int64_t>(i);
      o.pose = {60.0 + static_cast<double>(i % 100), -8.0, 0.0};
      o.length_m = 4.5;
      o.width_m = 1.8;
    }
    for (int i = 0; i < huge; ++i) {
      r.vehicle_id = "huge-" + std::to_string(i);
      r.request_id = static_cast<std::uint64_t>(i + 1);
      if (!client.send(r)) throw std::runtime_error("cannot write a huge request");
      const auto answer = client.wait_answer(r.vehicle_id, r.request_id, 60s);
      if (!answer) throw std::runtime_error("huge request " + std::to_string(i) + " not answered");
      if (answer->status.state != pullout::ExecutionState::kRejected) {
        std::printf("huge request %d: state %d, not rejected\n", i, static_cast<int>(answer->status.state));
      }
      client.forget(r.vehicle_id);
      std::printf("| %d | %.1f |\n", i + 1, rss_mb(pid));
    }
    std::this_thread::sleep_for(1s);  // evicted, instances unregistered and acknowledged
    std::printf("| %d, 1 s later | %.1f |\n\n", huge, rss_mb(pid));
  }

  // ---- 2. churn ----
  std::vector<Outcome> outcomes(vehicles);
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::atomic<bool> stop{false};
  const auto t0 = SteadyClock::now();
  const auto deadline =
      t0 + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(max_seconds));
  std::vector<std::pair<double, std::pair<std::size_t, double>>> rss_samples;  // t [s], (done, MB)
  std::thread monitor([&] {
    while (!stop) {
      const double t = std::chrono::duration<double>(SteadyClock::now() - t0).count();
      rss_samples.push_back({t, {done.load(), rss_mb(pid)}});
      for (int i = 0; i < 20 && !stop; ++i) std::this_thread::sleep_for(50ms);
    }
  });
  std::mutex error_mutex;
  std::string error;
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      try {
        integration::FleetClient client(service.domain(), profiles);
        if (!client.wait_matched(15s)) throw std::runtime_error("client " + std::to_string(c) + " did not match");
        while (!stop) {
          const std::size_t k = next.fetch_add(1);
          if (k >= vehicles || SteadyClock::now() >= deadline) break;
          if (rate > 0.0) {
            const auto due = t0 + std::chrono::duration_cast<SteadyClock::duration>(
                                      std::chrono::duration<double>(static_cast<double>(k) / rate));
            std::this_thread::sleep_until(due);
          }
          pullout::PullOutRequest r = base;
          r.vehicle_id = "churn-" + std::to_string(k);
          r.request_id = k + 1;
          const auto sent = SteadyClock::now();
          if (!client.send(r)) throw std::runtime_error("write failed for " + r.vehicle_id);
          const auto answer = client.wait_answer(r.vehicle_id, r.request_id, kAnswerTimeout);
          if (answer) {
            outcomes[k].latency_ms = std::chrono::duration<double, std::milli>(SteadyClock::now() - sent).count();
            outcomes[k].as_expected =
                answer->status.state == pullout::ExecutionState::kWaitingApproval && answer->path.found;
          }
          client.forget(r.vehicle_id);
          done.fetch_add(1);
        }
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(error_mutex);
        error = e.what();
        stop = true;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  const double wall_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  std::this_thread::sleep_for(1s);
  stop = true;
  monitor.join();
  if (!error.empty()) throw std::runtime_error(error);

  const std::size_t attempted = std::min(vehicles, next.load());
  std::size_t lost = 0;
  std::size_t unexpected = 0;
  for (std::size_t k = 0; k < attempted; ++k) {
    if (outcomes[k].latency_ms < 0.0) {
      ++lost;
    } else if (!outcomes[k].as_expected) {
      ++unexpected;
    }
  }
  std::printf(
      "churn: %zu vehicles in %.1f s (%.0f vehicles/s), %d clients; not answered %zu, answered otherwise %zu\n\n",
      attempted, wall_s, static_cast<double>(attempted) / wall_s, clients, lost, unexpected);

  std::printf("| t [s] | vehicles served | service RSS [MB] |\n|---|---|---|\n");
  const std::size_t step = std::max<std::size_t>(1, rss_samples.size() / 12);
  for (std::size_t i = 0; i < rss_samples.size(); i += step) {
    std::printf("| %.0f | %zu | %.1f |\n", rss_samples[i].first, rss_samples[i].second.first,
                rss_samples[i].second.second);
  }
  if (!rss_samples.empty()) {
    const auto& last = rss_samples.back();
    std::printf("| %.0f (end) | %zu | %.1f |\n", last.first, last.second.first, last.second.second);
  }

  const auto window = [&](std::size_t from, std::size_t to) {
    std::vector<double> v;
    for (std::size_t k = from; k < to; ++k) {
      if (outcomes[k].latency_ms >= 0.0) v.push_back(outcomes[k].latency_ms);
    }
    return summarize(v);
  };
  const std::size_t w = std::min(kWindow, attempted);
  const Summary first = window(0, w);
  const Summary last = window(attempted - w, attempted);
  std::printf("\n| vehicles | answered | p50 [ms] | p99 [ms] | max [ms] |\n|---|---|---|---|---|\n");
  std::printf("| first %zu | %zu | %.2f | %.2f | %.2f |\n", w, first.n, first.p50, first.p99, first.max);
  std::printf("| last %zu | %zu | %.2f | %.2f | %.2f |\n", w, last.n, last.p50, last.p99, last.max);
  std::printf("\nload after: %s\n", load_text().c_str());

  const integration::StopReport report = service.stop();
  if (!report.clean()) std::printf("service stop: %s\n", report.describe().c_str());
  return lost == 0 && unexpected == 0 && report.clean() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_fleet_churn: %s\n", e.what());
    return 1;
  }
}
