// The service's HTTP port (observability.metrics): Prometheus's /metrics (prometheus::Exposer,
// civetweb) and two health endpoints answered before civetweb routes the request:
//
//   /healthz  200 "ok" while the dispatcher loop turns (its heartbeat is younger than
//             kLivenessTimeout), else 503: for a liveness probe (restart when it fails).
//   /readyz   200 once the config is loaded, the DDS participant and endpoints exist, the planning
//             threads run and the dispatcher turns; else 503 naming what is missing. The body also
//             says how many other pullout_service participants are on the domain (it stays 200:
//             a second service is warned about, see observability.on_duplicate_service).
//
// Everything else is 404 (civetweb). Health answers are plain text, one line per fact.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

namespace prometheus {
class Exposer;
class Registry;
}  // namespace prometheus

namespace pullout::service {

// What the health endpoints report; written by the service's threads, read by the HTTP threads.
struct HealthState {
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::seconds kLivenessTimeout{5};

  std::atomic<bool> config_loaded{false};
  std::atomic<bool> dds_ready{false};
  std::atomic<bool> workers_running{false};
  // Replica mode: false until the start-up sync with the other replicas is over (until then the
  // service answers no request).
  std::atomic<bool> in_step{true};
  std::atomic<Clock::rep> heartbeat{0};  // steady_clock ticks of the dispatcher's last turn (0: never)
  std::atomic<std::uint32_t> other_services{0};

  void beat() { heartbeat.store(Clock::now().time_since_epoch().count()); }
  bool alive() const;
  // The /readyz body; `ready` says whether it is a 200.
  std::string readiness(bool& ready) const;
};

class HttpEndpoint {
 public:
  // Listens on address:port (throws std::runtime_error naming them when it cannot) and serves
  // `registry` at /metrics and `health` at /healthz and /readyz. Both must outlive the endpoint.
  // One endpoint per process at a time (civetweb's request hook has no user pointer).
  HttpEndpoint(const std::string& address, int port, std::shared_ptr<prometheus::Registry> registry,
               const HealthState& health);
  ~HttpEndpoint();
  HttpEndpoint(const HttpEndpoint&) = delete;
  HttpEndpoint& operator=(const HttpEndpoint&) = delete;

  // The port actually listened on.
  int port() const { return port_; }

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  std::unique_ptr<prometheus::Exposer> exposer_;
  int port_{0};
};

}  // namespace pullout::service
