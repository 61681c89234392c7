// A passive DDS participant that follows every vehicle on a domain: it reads the four pullout
// topics (requests, paths and statuses of every vehicle, their progress) and writes nothing, so
// the service and the vehicles behave exactly as without it. `pullout watch` and `pullout view`
// draw what it holds.
//
// DDS setup: the participant profile and the reader profiles of a Fast DDS XML profiles file
// (pullout_participant; pullout_request_reader, pullout_path_reader, pullout_status_reader,
// pullout_progress_reader), by default the built-in copy of config/dds/loopback.xml (loopback
// only), as the service does. Path and status readers are transient local, so a monitor started
// late receives each vehicle's latest path and status at once; requests and progress are
// volatile: a vehicle's lanes and pose are known from its next request (or re-send) and progress
// sample. No content filter: the monitor receives every vehicle's samples. The participant is
// named "pullout_view" and carries no service user data (a service does not take it for a second
// service). No DDS Security support: on a secure domain the monitor sees nothing.
//
// Threading: samples are taken on the monitor's own thread (a wait set, not a listener);
// snapshot() and wait_for_change() may be called from any thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"

namespace pullout::cli {

struct FleetMonitorOptions {
  int domain_id{0};           // 0..232
  std::string profiles_file;  // empty: built-in loopback profiles
  std::string participant_profile{"pullout_participant"};
  // At most this many vehicles are kept; beyond it the one updated longest ago is forgotten.
  std::size_t max_vehicles{4096};
};

// What the monitor knows of one vehicle: the latest sample of each topic (null: none yet) and
// when the latest sample of any of them was written (its DDS source timestamp: the writer's
// system clock, so a path received late still shows its age; clocks of other hosts may be skewed).
struct VehicleView {
  std::string vehicle_id;
  std::shared_ptr<const PullOutRequest> request;
  std::shared_ptr<const PullOutPath> path;
  std::shared_ptr<const PullOutStatus> status;
  std::shared_ptr<const ExecutionProgress> progress;
  std::chrono::system_clock::time_point last_update{};
};

struct FleetSnapshot {
  std::uint64_t version{0};           // increases with every sample taken
  std::vector<VehicleView> vehicles;  // sorted by vehicle id
  bool service_matched{false};        // a path and a status writer are matched (a service is up)
};

// A DDS setup failure (participant, topic or reader, profiles file); the message names it.
class FleetMonitorError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FleetMonitor {
 public:
  using Duration = std::chrono::nanoseconds;

  // Creates the participant, topics and readers and starts the thread. Throws
  // std::invalid_argument for a bad domain id, FleetMonitorError when DDS cannot be set up.
  explicit FleetMonitor(FleetMonitorOptions options);
  ~FleetMonitor();  // stops the thread, deletes the participant
  FleetMonitor(const FleetMonitor&) = delete;
  FleetMonitor& operator=(const FleetMonitor&) = delete;

  FleetSnapshot snapshot() const;
  // Blocks until the version is past `seen` or `timeout` passes; returns the current version.
  std::uint64_t wait_for_change(std::uint64_t seen, Duration timeout) const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pullout::cli
