// The pullout service: DDS in and out, a dispatcher thread and a pool of planning threads.
//
//   DDS readers --(WaitSet: DATA_AVAILABLE / shutdown guard)--> dispatcher thread
//     request  -> convert + check -> kRejected, or a per-vehicle job -> planning workers, its
//                 kPlanning status held back: a search that ends within service.quick_answer_ms
//                 is answered with path + status only, a longer one writes kPlanning first
//                 (quick_answer_on_dispatcher: the quick attempt on the dispatcher itself)
//     progress -> convert + check -> the vehicle's execution tracker -> status on change
//   planning worker -> StartPlanner::plan(request, deadline) -> path + status
//
// Nothing is planned inside DDS callbacks (there are none: no listeners). The deadline of a search
// is the request's deadline_ms, or service.default_deadline_ms when it gives none, capped by
// service.limits.max_deadline_ms; it is also cancelled when a newer request of the same vehicle
// arrives or the service stops.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>

#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/dds/core/condition/GuardCondition.hpp>

#include "observability/http_endpoint.hpp"
#include "observability/service_metrics.hpp"
#include "pullout/config/config.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "service/dds_edge.hpp"
#include "service/planning_queue.hpp"
#include "service/replicas.hpp"
#include "service/state_journal.hpp"
#include "service/vehicle_registry.hpp"

namespace eprosima::fastdds::dds {
struct SampleInfo;
}  // namespace eprosima::fastdds::dds

namespace pullout::msg {
class PullOutRequest;
class ExecutionProgress;
}  // namespace pullout::msg

namespace pullout::service {

class PulloutService {
 public:
  // Creates the DDS entities (throws DdsSetupError) and the planning threads. `config` must be
  // valid (load_config validates it). `map`: the Lanelet2 map of config.map.path (null: none);
  // requests naming route lanelets plan on it.
  explicit PulloutService(const Config& config, std::shared_ptr<const LaneletMap> map = nullptr);
  ~PulloutService();
  PulloutService(const PulloutService&) = delete;
  PulloutService& operator=(const PulloutService&) = delete;

  // Starts the dispatcher thread.
  void start();
  // Stops taking samples, cancels the searches and joins every thread; the DDS entities are deleted
  // with the object. Thread-safe and idempotent: concurrent callers return once the first one has
  // finished. Not async-signal-safe, and not to be called from the service's own threads.
  void stop();

  // The planning budget for a request's deadline_ms [ms].
  double effective_deadline_ms(double requested_ms) const;

  // Other pullout_service participants on the domain now (DdsEdge::other_services).
  std::size_t other_services() const { return dds_.other_services(); }
  // The HTTP port of /metrics, /healthz and /readyz; 0 when observability.metrics is off.
  int http_port() const { return http_ ? http_->port() : 0; }

 private:
  void dispatch_loop();
  void take_requests();
  void take_progress();
  // Replica mode: the other replicas' paths and statuses (shadows), and the vehicles of replicas
  // that left (taken over when this replica wins them).
  // Returns how many samples were taken.
  std::size_t take_replica_samples();
  // Replica mode, at start: waits (bounded by a few leases) until the other replicas' paths and
  // statuses are here, so that no vehicle they serve is planned afresh by this one.
  void sync_with_replicas();
  void take_over_departed();
  bool serving(const std::string& vehicle_id) const;
  // Whether the sample's writer may speak for vehicle_id (DdsEdge::sender_may_act_for); logs a
  // refusal, rate-limited.
  bool sender_allowed(const eprosima::fastdds::dds::SampleInfo& info, const std::string& vehicle_id, const char* what);
  // Which vehicle each instance of a reader belongs to: a sample telling that an instance is no
  // longer alive carries no key fields. An entry lives as long as the reader's instance (erased
  // when it is reported gone), so max_instances bounds the map.
  using InstanceNames = std::map<eprosima::fastrtps::rtps::InstanceHandle_t, std::string>;
  void instance_gone(InstanceNames& names, const eprosima::fastdds::dds::SampleInfo& info, VehicleInput input);
  // `waited_ms`: how long the sample waited in the reader (planned on the dispatcher only when short).
  void handle_request(const msg::PullOutRequest& sample, double waited_ms);
  void handle_progress(const msg::ExecutionProgress& sample);
  void run_job(PlanningJob& job);
  // Searches the job within service.quick_answer_ms (on the calling thread) and publishes the
  // result. False when the search needs longer (or threw): it must be searched again with the
  // whole budget, after its held `planning` status is written.
  bool quick_attempt(PlanningJob& job);
  // A search's result to the registry (published unless a newer request came), and the log.
  void finish(const PlanningJob& job, const PlanningResult& result, double waited_ms);
  // service.state_dir: every vehicle of the journal restored (before the dispatcher starts).
  void restore_from_journal();
  // A snapshot's session rebuilt in the registry, its search (if any) queued.
  void restore(const SessionSnapshot& snapshot, const std::vector<RequestIssue>& request_issues);

  Config config_;
  // First: the registry's and the queue's observers use them until those are gone.
  HealthState health_;
  std::unique_ptr<ServiceMetrics> metrics_;  // null when observability.metrics is off
  // Listening before the DDS endpoints exist: a client that matched the service can reach it
  // (/readyz says not ready until the dispatcher runs). Serves only health_ and metrics_; stop()
  // stops it first.
  std::unique_ptr<HttpEndpoint> http_;
  DdsEdge dds_;
  // service.state_dir: journals what the registry publishes, then hands it to dds_ (null: off).
  std::unique_ptr<StateJournal> journal_;
  StartPlanner planner_;
  VehicleRegistry registry_;
  std::atomic<bool> stopping_{false};
  std::once_flag stop_once_;
  eprosima::fastdds::dds::GuardCondition shutdown_;
  std::thread dispatcher_;
  // Dispatcher thread only: when each vehicle last had a malformed progress sample logged, so that
  // a sender stuck at 50 Hz does not flood the log.
  std::unordered_map<std::string, std::chrono::steady_clock::time_point> progress_warned_;
  // Dispatcher thread only: samples refused because their writer may not speak for their vehicle.
  std::uint64_t refused_samples_{0};
  std::chrono::steady_clock::time_point refused_logged_{};
  // Dispatcher thread only.
  InstanceNames request_instances_;
  InstanceNames progress_instances_;
  // Replica mode (null otherwise): the vehicles other replicas serve. Dispatcher thread only.
  std::unique_ptr<ReplicaShadows> shadows_;
  InstanceNames replica_status_instances_;
  // Last: destroyed (workers joined) before the registry and the DDS entities they use.
  std::unique_ptr<PlanningQueue> queue_;
};

}  // namespace pullout::service
