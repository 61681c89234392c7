#include "view/view_server.hpp"

#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include <CivetServer.h>
#include <civetweb.h>

#include "fleet_view.hpp"

namespace pullout::cli {

namespace {

constexpr auto kMinEventGap = std::chrono::milliseconds(100);
constexpr auto kMaxEventGap = std::chrono::seconds(1);

bool send_all(mg_connection* conn, const std::string& data) {
  return mg_write(conn, data.data(), data.size()) == static_cast<int>(data.size());
}

void send_body(mg_connection* conn, const char* content_type, const std::string& body) {
  mg_printf(conn,
            "HTTP/1.1 200 OK\r\nContent-Type: %s\r\nContent-Length: %zu\r\nCache-Control: no-store\r\n"
            "Connection: close\r\n\r\n",
            content_type, body.size());
  send_all(conn, body);
}

std::string fleet_text(const FleetMonitor& monitor, const VehicleInfo& vehicle, std::uint64_t& version) {
  const FleetSnapshot snapshot = monitor.snapshot();
  version = snapshot.version;
  // Strings from DDS may hold invalid UTF-8: replace rather than throw.
  return fleet_json(snapshot, vehicle, std::chrono::system_clock::now())
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

class ViewServer::Handlers {
 public:
  explicit Handlers(ViewServer& owner) : fleet(owner), events(owner) {}

  class Page : public CivetHandler {
   public:
    bool handleGet(CivetServer* /*server*/, mg_connection* conn) override {
      const mg_request_info* info = mg_get_request_info(conn);
      if (info == nullptr || info->local_uri == nullptr || std::strcmp(info->local_uri, "/") != 0) {
        return false;  // civetweb answers 404
      }
      send_body(conn, "text/html; charset=utf-8", kViewPageHtml);
      return true;
    }
  };

  class Fleet : public CivetHandler {
   public:
    explicit Fleet(ViewServer& owner) : owner_(owner) {}
    bool handleGet(CivetServer* /*server*/, mg_connection* conn) override {
      std::uint64_t version = 0;
      send_body(conn, "application/json", fleet_text(owner_.monitor_, owner_.options_.vehicle, version));
      return true;
    }

   private:
    ViewServer& owner_;
  };

  class Events : public CivetHandler {
   public:
    explicit Events(ViewServer& owner) : owner_(owner) {}
    bool handleGet(CivetServer* /*server*/, mg_connection* conn) override {
      mg_printf(conn,
                "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n"
                "Connection: close\r\n\r\n");
      std::uint64_t version = 0;
      auto sent_at = std::chrono::steady_clock::now() - kMaxEventGap;
      while (!owner_.stopping_.load()) {
        const auto since = std::chrono::steady_clock::now() - sent_at;
        const std::uint64_t now_version = owner_.monitor_.wait_for_change(
            version, std::max<std::chrono::steady_clock::duration>(kMaxEventGap - since, kMinEventGap));
        if (owner_.stopping_.load()) break;
        if (now_version == version && std::chrono::steady_clock::now() - sent_at < kMaxEventGap) continue;
        const std::string data = "data: " + fleet_text(owner_.monitor_, owner_.options_.vehicle, version) + "\n\n";
        if (!send_all(conn, data)) break;  // the page went away
        sent_at = std::chrono::steady_clock::now();
        std::this_thread::sleep_for(kMinEventGap);
      }
      return true;
    }

   private:
    ViewServer& owner_;
  };

  Page page;
  Fleet fleet;
  Events events;
};

ViewServer::ViewServer(const FleetMonitor& monitor, ViewServerOptions options)
    : monitor_(monitor), options_(std::move(options)), handlers_(std::make_unique<Handlers>(*this)) {
  const std::string where = options_.address + ":" + std::to_string(options_.port);
  const std::vector<std::string> civet_options{
      "listening_ports", where, "num_threads", std::to_string(options_.threads), "request_timeout_ms", "10000"};
  try {
    server_ = std::make_unique<CivetServer>(civet_options);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot listen on " + where + ": " + e.what());
  }
  if (server_->getContext() == nullptr) throw std::runtime_error("cannot listen on " + where);
  server_->addHandler("/fleet.json", handlers_->fleet);
  server_->addHandler("/events", handlers_->events);
  server_->addHandler("/", handlers_->page);
  const std::vector<int> ports = server_->getListeningPorts();
  port_ = ports.empty() ? options_.port : ports.front();
}

ViewServer::~ViewServer() {
  stopping_.store(true);
  server_.reset();  // joins civetweb's threads; the event streams notice stopping_ within a second
}

}  // namespace pullout::cli
