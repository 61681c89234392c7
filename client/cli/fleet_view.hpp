// What `pullout watch` prints and what `pullout view` sends to its web page, made from a
// FleetSnapshot (no DDS, no I/O: tested directly).
#pragma once

#include <chrono>
#include <string>

#include <nlohmann/json.hpp>

#include "fleet_monitor.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout::cli {

// One row of the fleet table.
struct FleetRow {
  std::string vehicle;
  std::string state;    // execution state name ("-": no status yet)
  std::string planner;  // planner name ("-": none)
  std::string segment;  // "i/n": the segment being driven counted from 1 (current_path_idx + 1) of
                        // segment_count; "-" when the status has no segments
  std::string safe;     // "yes", "no", "no (object N)", "-"
  std::string age;      // time since the vehicle's latest sample: "0.4s", "12s", "3m05s"
  std::string note;     // stop reason or error (first line), shortened
};

FleetRow fleet_row(const VehicleView& vehicle, std::chrono::system_clock::time_point now);

// The table: a header line and one row per vehicle in id order, columns padded to their widest
// cell, each line ending in '\n'. No vehicles: the header and "(no vehicles)".
std::string render_fleet_table(const FleetSnapshot& snapshot, std::chrono::system_clock::time_point now);

// The web page's model of the fleet (README, Operating): per vehicle its row (as the table), its
// footprint at its latest pose (progress, else the request's ego pose) drawn with `vehicle_info`,
// the lanes and objects of its latest request, and its latest path's segments (points x, y;
// reverse flag) with the current one marked. Coordinates in metres, map frame.
nlohmann::json fleet_json(const FleetSnapshot& snapshot, const VehicleInfo& vehicle_info,
                          std::chrono::system_clock::time_point now);

}  // namespace pullout::cli
