// Per-vehicle state of the service: the latest accepted request, its execution tracker and the
// last published status, and the rules that turn requests, planning results and progress into
// published paths and statuses.
//
// Per vehicle, everything happens under that vehicle's lock, so the samples of one vehicle are
// published in a consistent order (kPlanning before the result, a result only if no newer request
// arrived meanwhile); different vehicles never wait for each other beyond a map lookup.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/execution_tracker.hpp"
#include "pullout/pipeline/parameters.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "service/outbox.hpp"
#include "service/planning_queue.hpp"

namespace pullout::service {

// Nanoseconds since the epoch, for the stamps of outgoing samples.
std::int64_t now_ns();

class VehicleRegistry {
 public:
  // `parameters` configure the execution trackers (th_arrived_distance, th_stopped_*).
  VehicleRegistry(const StartPlannerParameters& parameters, Outbox& outbox);

  // A request that converted cleanly. It replaces the vehicle's path (the tracker forgets it) and
  // cancels the vehicle's running search; publishes kPlanning. Returns the job to queue.
  PlanningJob accept(PullOutRequest request);

  // A request that failed conversion: replaces the vehicle's path like accept(), publishes a path
  // with found = false and the issues as reasons, and kRejected with the issues as `error`.
  void reject(const std::string& vehicle_id, std::uint64_t request_id, const std::vector<RequestIssue>& issues);

  // A finished search. Publishes the path and the status (kExecuting, kNoPath or kRejected) and
  // starts tracking a found path. Returns false, publishing nothing, when a newer request of the
  // vehicle was accepted meanwhile.
  bool complete(const PlanningJob& job, const PlanningResult& result);

  // The search threw (a bug in the core): publishes found = false and kNoPath with the reason.
  void fail(const PlanningJob& job, const std::string& what);

  // One odometry sample. Ignored (debug log) for an unknown vehicle, a request id other than the
  // one being executed, or when nothing is being executed; else feeds the tracker and publishes
  // the status when the segment index or completion changes.
  void on_progress(const ExecutionProgress& progress);

  // Cancels every running search (shutdown).
  void cancel_all();

  std::size_t vehicle_count() const;

 private:
  struct Vehicle {
    explicit Vehicle(const StartPlannerParameters& parameters) : tracker(parameters) {}
    std::mutex mutex;
    std::uint64_t sequence{0};                  // number of requests received, accepted or not
    std::shared_ptr<std::atomic<bool>> cancel;  // of the latest accepted request's search
    ExecutionTracker tracker;
    PullOutStatus status;  // the last status published
  };

  std::shared_ptr<Vehicle> find(const std::string& vehicle_id) const;
  std::shared_ptr<Vehicle> find_or_add(const std::string& vehicle_id);
  // A new request of the vehicle: invalidates the previous one. Caller holds v.mutex.
  void supersede(Vehicle& v);
  // Publishes path then status; if the path cannot be written, tells the vehicle so with kNoPath
  // instead of a status it would wait on forever. Caller holds v.mutex.
  void publish_result(Vehicle& v, const PullOutPath& path, PullOutStatus status);

  StartPlannerParameters parameters_;
  Outbox& outbox_;
  mutable std::mutex mutex_;  // guards vehicles_ (the map, not the vehicles)
  std::unordered_map<std::string, std::shared_ptr<Vehicle>> vehicles_;
};

}  // namespace pullout::service
