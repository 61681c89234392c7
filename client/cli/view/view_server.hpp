// The HTTP side of `pullout view`: a civetweb server (Debian's, the one under the service's
// Prometheus endpoint) that serves the fleet a FleetMonitor holds:
//
//   /            the page (view_page.html, compiled in): SVG of lanes, objects, footprints, paths
//                with the current segment highlighted, states, and a table
//   /fleet.json  the fleet now (fleet_json)
//   /events      Server-Sent Events: the fleet as one `data:` line whenever samples arrived (at most
//                every 100 ms) and at least every second (the ages)
//
// Every connection to /events holds one of the server's threads while it is open:
// ViewServerOptions::threads bounds the pages watching at once (one thread is kept for the other
// paths).
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "fleet_monitor.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

class CivetServer;

namespace pullout::cli {

struct ViewServerOptions {
  std::string address{"127.0.0.1"};
  int port{8080};  // 0: any free port (port() says which)
  int threads{8};
  VehicleInfo vehicle;  // the footprint drawn for every vehicle
};

class ViewServer {
 public:
  // Listens at once. Throws std::runtime_error naming the address when it cannot. `monitor` must
  // outlive the server.
  ViewServer(const FleetMonitor& monitor, ViewServerOptions options);
  ~ViewServer();  // ends the event streams, joins civetweb's threads
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  int port() const { return port_; }

 private:
  class Handlers;
  const FleetMonitor& monitor_;
  ViewServerOptions options_;
  std::atomic<bool> stopping_{false};
  std::unique_ptr<Handlers> handlers_;
  std::unique_ptr<CivetServer> server_;
  int port_{0};
};

// The page's HTML (view_page.html).
extern const char* const kViewPageHtml;

}  // namespace pullout::cli
