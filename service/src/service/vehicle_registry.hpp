// Per-vehicle state of the service: the latest accepted request, its execution tracker and the
// last published status, and the rules that turn requests, planning results and progress into
// published paths and statuses.
//
// Departure (per found path): the status is kWaitingApproval until a progress sample carries
// approved = true; then the turn signal is on (turn_signal_start_ns = that sample's stamp) and the
// status is kWaitingSafety while prepare_time_before_start has not elapsed on the progress clock
// or the safety monitor (pullout/safety/safety_monitor.hpp) says unsafe; then kExecuting (the
// vehicle has departed). After departure, when the path becomes unsafe (or approval is withdrawn),
// the path is re-published under the same request id with a jerk-limited stop
// (pullout/safety/stop_path.hpp) and the status goes back to kWaitingSafety; once safe, approved
// and stopped, the original path is re-published and the status is kExecuting again.
//
// Re-sent requests: a request of a vehicle that has a found path for the same goal (within 0.1 m
// and 0.05 rad) does not re-plan when the vehicle has departed (the path is latched) or when the
// last search was accepted less than backward_path_update_duration ago and the ego pose is within
// th_arrived_distance of the path's first point; it only replaces the
// objects of the safety check, and the current path (as published: with or without the stop) is
// re-published under the new request id, keeping the segment index (ExecutionTracker::adopt).
// Otherwise it replaces the path (a new search); before departure, a new path for the same goal
// with the same turn signal keeps the signal's start, so periodic re-plans do not restart the
// prepare time.
//
// Per vehicle, everything happens under that vehicle's lock, so the samples of one vehicle are
// published in a consistent order (kPlanning before the result, a result only if no newer request
// arrived meanwhile); different vehicles never wait for each other beyond a map lookup.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "pullout/execution/execution_tracker.hpp"
#include "pullout/model/types.hpp"
#include "pullout/pipeline/parameters.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/safety/safety_monitor.hpp"
#include "pullout/vehicle/vehicle_info.hpp"
#include "service/outbox.hpp"
#include "service/planning_queue.hpp"

namespace pullout::service {

// Nanoseconds since the epoch, for the stamps of outgoing samples.
std::int64_t now_ns();

class VehicleRegistry {
 public:
  // `parameters` configure the execution trackers (th_arrived_distance, th_stopped_*) and the
  // safety checks; `vehicle` gives the footprint of the safety checks.
  VehicleRegistry(const VehicleInfo& vehicle, const StartPlannerParameters& parameters, Outbox& outbox);

  // A request that converted cleanly. Either it only updates the objects of a latched path (see
  // above; returns nothing), or it replaces the vehicle's path (the tracker forgets it), cancels
  // the vehicle's running search, publishes kPlanning and returns the job to queue.
  std::optional<PlanningJob> accept(PullOutRequest request);

  // A request that failed conversion: replaces the vehicle's path like accept(), publishes a path
  // with found = false and the issues as reasons, and kRejected with the issues as `error`.
  void reject(const std::string& vehicle_id, std::uint64_t request_id, const std::vector<RequestIssue>& issues);

  // A finished search. Publishes the path and the status (kWaitingApproval, kNoPath or
  // kRejected) and starts tracking a found path. Returns false, publishing nothing, when a newer request of the
  // vehicle was accepted meanwhile.
  bool complete(const PlanningJob& job, const PlanningResult& result);

  // The search threw (a bug in the core): publishes found = false and kNoPath with the reason.
  void fail(const PlanningJob& job, const std::string& what);

  // One odometry sample. Ignored (debug log) for an unknown vehicle, a request id other than the
  // one of the found path, or when there is none; else feeds the tracker, runs the departure and
  // safety rules above, and publishes the status when anything in it changes.
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
    // The latest accepted request's goal and when its search was accepted (re-planning throttle).
    Pose2 goal;
    std::chrono::steady_clock::time_point planned_at;
    std::vector<Lane> lanes;              // of the latest accepted request
    std::vector<Object> objects;          // of the latest request
    std::optional<PullOutPath> path;      // the found path being followed (as planned)
    std::optional<SafetyMonitor> safety;  // of `path`
    bool stop_inserted{false};            // the published path is `path` with a stop
    PullOutPath published;                // what was published last for `path`
    // Turn signal and its start carried from the path a same-goal re-plan replaces.
    std::optional<std::pair<TurnSignal, std::int64_t>> signal_carry;
  };

  std::shared_ptr<Vehicle> find(const std::string& vehicle_id) const;
  std::shared_ptr<Vehicle> find_or_add(const std::string& vehicle_id);
  // A new request of the vehicle: invalidates the previous one. Caller holds v.mutex.
  void supersede(Vehicle& v);
  // Publishes path then status; if the path cannot be written, tells the vehicle so with kNoPath
  // instead of a status it would wait on forever. Caller holds v.mutex.
  void publish_result(Vehicle& v, const PullOutPath& path, PullOutStatus status);
  // The departure and safety rules for one sample; returns true when the status changed.
  // Caller holds v.mutex.
  bool apply_departure_rules(Vehicle& v, const ExecutionProgress& progress);

  VehicleInfo vehicle_;
  StartPlannerParameters parameters_;
  Outbox& outbox_;
  mutable std::mutex mutex_;  // guards vehicles_ (the map, not the vehicles)
  std::unordered_map<std::string, std::shared_ptr<Vehicle>> vehicles_;
};

}  // namespace pullout::service
