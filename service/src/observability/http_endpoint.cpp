#include "observability/http_endpoint.hpp"

#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <vector>

#include <CivetServer.h>
#include <civetweb.h>
#include <prometheus/exposer.h>
#include <prometheus/registry.h>

namespace pullout::service {
namespace {

// civetweb calls begin_request with the connection only; the endpoint's health state is found
// here. Set while an endpoint exists (at most one per process).
std::mutex g_health_mutex;
const HealthState* g_health = nullptr;

void send_text(mg_connection* conn, int code, const char* reason, const std::string& body) {
  mg_printf(conn,
            "HTTP/1.1 %d %s\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: %zu\r\n"
            "Cache-Control: no-store\r\nConnection: close\r\n\r\n",
            code, reason, body.size());
  mg_write(conn, body.data(), body.size());
}

// 0: not a health path, civetweb goes on (to /metrics or 404); else the status code sent.
int health_hook(mg_connection* conn) {
  const mg_request_info* info = mg_get_request_info(conn);
  if (info == nullptr || info->local_uri == nullptr) return 0;
  const bool healthz = std::strcmp(info->local_uri, "/healthz") == 0;
  const bool readyz = std::strcmp(info->local_uri, "/readyz") == 0;
  if (!healthz && !readyz) return 0;
  std::lock_guard<std::mutex> lock(g_health_mutex);
  if (g_health == nullptr) {
    send_text(conn, 503, "Service Unavailable", "stopping\n");
    return 503;
  }
  if (healthz) {
    const bool alive = g_health->alive();
    send_text(conn, alive ? 200 : 503, alive ? "OK" : "Service Unavailable",
              alive ? "ok\n" : "dispatcher loop not responding\n");
    return alive ? 200 : 503;
  }
  bool ready = false;
  const std::string body = g_health->readiness(ready);
  send_text(conn, ready ? 200 : 503, ready ? "OK" : "Service Unavailable", body);
  return ready ? 200 : 503;
}

}  // namespace

bool HealthState::alive() const {
  const Clock::rep last = heartbeat.load();
  if (last == 0) return false;
  return Clock::now() - Clock::time_point(Clock::duration(last)) < kLivenessTimeout;
}

std::string HealthState::readiness(bool& ready) const {
  std::string body;
  ready = true;
  const auto fact = [&](bool ok, const char* good, const char* bad) {
    ready = ready && ok;
    body += ok ? good : bad;
    body += '\n';
  };
  fact(config_loaded.load(), "config loaded", "config not loaded");
  fact(dds_ready.load(), "dds participant and endpoints created", "dds participant and endpoints not created");
  fact(workers_running.load(), "planning threads running", "planning threads not running");
  fact(alive(), "dispatcher loop responsive", "dispatcher loop not responding");
  fact(in_step.load(), "in step with the other replicas (or not a replica)",
       "not yet in step with the other replicas (start-up sync)");
  body += "other pullout services on the domain: " + std::to_string(other_services.load()) + '\n';
  body.insert(0, ready ? "ready\n" : "not ready\n");
  return body;
}

HttpEndpoint::HttpEndpoint(const std::string& address, int port, std::shared_ptr<prometheus::Registry> registry,
                           const HealthState& health)
    : registry_(std::move(registry)) {
  {
    std::lock_guard<std::mutex> lock(g_health_mutex);
    if (g_health != nullptr) throw std::logic_error("only one HTTP endpoint per process");
    g_health = &health;
  }
  CivetCallbacks callbacks;  // CivetServer keeps a copy
  callbacks.begin_request = &health_hook;
  const std::string where = address + ":" + std::to_string(port);
  try {
    // Two threads: a scrape and a health probe at the same time; nothing here is slow.
    exposer_ = std::make_unique<prometheus::Exposer>(
        std::vector<std::string>{"listening_ports", where, "num_threads", "2", "request_timeout_ms", "5000"},
        &callbacks);
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(g_health_mutex);
    g_health = nullptr;
    throw std::runtime_error("observability.metrics: cannot listen on " + where + ": " + e.what());
  }
  exposer_->RegisterCollectable(registry_);
  const std::vector<int> ports = exposer_->GetListeningPorts();
  port_ = ports.empty() ? port : ports.front();
}

HttpEndpoint::~HttpEndpoint() {
  {
    std::lock_guard<std::mutex> lock(g_health_mutex);
    g_health = nullptr;
  }
  exposer_.reset();  // joins civetweb's threads
}

}  // namespace pullout::service
