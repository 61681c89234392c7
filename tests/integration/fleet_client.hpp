// Test and benchmark harness: one DDS participant that speaks for many vehicles in turn, with
// plain Fast DDS entities (no pullout::Client, which is one participant per vehicle).
//
// A fleet churn: a request for a vehicle id, the service's answer (path and final status), then
// unregister_instance() of the vehicle's request instance, so that the service sees the vehicle
// go (NOT_ALIVE) and both sides can free the instance. Used by tests/service/test_service_eviction
// and bench/bench_fleet_churn.
//
// The readers keep only samples of vehicles with an outstanding request (so 50,000 vehicle ids
// over time hold no memory here), and record which vehicles' path instances the service
// unregistered or disposed. One thread per FleetClient (the generated type support keeps scratch
// buffers per participant's type object).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include <fastdds/rtps/common/InstanceHandle.h>

#include "pullout/model/types.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class DataWriter;
class DataReader;
class WaitSet;
}  // namespace eprosima::fastdds::dds

namespace pullout::integration {

class FleetClient {
 public:
  // A participant on `domain` from `profiles_file` (a Fast DDS XML file with the pullout profile
  // names), with a request writer and path and status readers. Throws std::runtime_error.
  FleetClient(int domain, const std::string& profiles_file);
  ~FleetClient();
  FleetClient(const FleetClient&) = delete;
  FleetClient& operator=(const FleetClient&) = delete;

  // Waits until the service's request reader and path/status writers are matched.
  bool wait_matched(std::chrono::milliseconds timeout);

  // Writes the request; its vehicle's answers are kept from now on.
  bool send(const PullOutRequest& request);
  // Unregisters the vehicle's request instance and stops keeping its answers; with
  // `await_gone`, wait_path_gone(vehicle_id) may still be called.
  bool forget(const std::string& vehicle_id, bool await_gone = false);

  // Waits for the first status of (vehicle, request) that is not kPlanning and the path of that
  // request; nullopt on timeout.
  struct Answer {
    PullOutStatus status;
    PullOutPath path;
  };
  std::optional<Answer> wait_answer(const std::string& vehicle_id, std::uint64_t request_id,
                                    std::chrono::milliseconds timeout);
  // Waits until the service has unregistered or disposed the vehicle's path instance.
  bool wait_path_gone(const std::string& vehicle_id, std::chrono::milliseconds timeout);

 private:
  void drain();
  // Sleeps until data arrives on a reader or `until` passes.
  void wait_data(std::chrono::steady_clock::time_point until);

  eprosima::fastdds::dds::DomainParticipant* participant_{nullptr};
  eprosima::fastdds::dds::DataWriter* request_writer_{nullptr};
  eprosima::fastdds::dds::DataReader* path_reader_{nullptr};
  eprosima::fastdds::dds::DataReader* status_reader_{nullptr};
  std::unique_ptr<eprosima::fastdds::dds::WaitSet> waitset_;
  std::set<std::string> watched_;  // vehicles whose answers are kept
  std::map<std::pair<std::string, std::uint64_t>, PullOutStatus> statuses_;
  std::map<std::pair<std::string, std::uint64_t>, PullOutPath> paths_;
  std::set<std::string> awaiting_gone_;  // forgotten, but wait_path_gone may come
  std::set<std::string> paths_gone_;     // of watched and awaiting vehicles
  // Path instances seen, until the service unregisters them (a notification carries no key).
  std::map<eprosima::fastrtps::rtps::InstanceHandle_t, std::string> path_instances_;
};

}  // namespace pullout::integration
