// The service's vehicles: one VehicleSession (pullout/session/vehicle_session.hpp, the departure
// rules) per vehicle id, each under its own lock, and the publication of what the sessions say.
//
// Per vehicle, a session's effects are published in the order the session produced them: the
// session's lock is handed over to the vehicle's publish lock before it is released, so that the
// next input of the vehicle can be worked on while the previous effects are still being written,
// and samples of one vehicle never overtake each other (kPlanning before the result, a result
// only if no newer request arrived meanwhile). Different vehicles never wait for each other
// beyond a map lookup.
//
// The registry also owns each vehicle's cancellation flag: a session's cancel_search sets the
// flag of the running search, and a search order gets a fresh one.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/session/vehicle_session.hpp"
#include "service/outbox.hpp"
#include "service/planning_queue.hpp"

namespace pullout::service {

// Nanoseconds since the epoch, for the stamps of outgoing samples.
std::int64_t now_ns();

class VehicleRegistry {
 public:
  using Clock = VehicleSession::Clock;

  // `planner` validates requests and configures the sessions; it must outlive the registry.
  VehicleRegistry(const StartPlanner& planner, Outbox& outbox, SessionOptions options = {});

  // A request; `conversion_issues` are the problems found while decoding it. Returns the search
  // to queue, if the session ordered one.
  std::optional<PlanningJob> on_request(PullOutRequest request, const std::vector<RequestIssue>& conversion_issues);
  // A finished search; publishes nothing when a newer request of the vehicle came meanwhile.
  void on_result(const PlanningJob& job, const PlanningResult& result);
  // The search threw (a bug in the core).
  void on_search_failed(const PlanningJob& job, const std::string& what);
  // One odometry sample (decoded without problems).
  void on_progress(const ExecutionProgress& progress);
  // Time passes: every session's on_time (the odometry watchdog).
  void on_time();

  // Cancels every running search (shutdown).
  void cancel_all();

 private:
  struct Slot {
    Slot(const std::string& id, const StartPlanner& planner, SessionOptions options) : session(id, planner, options) {}
    std::mutex mutex;          // guards session and cancel
    std::mutex publish_mutex;  // held while this vehicle's effects are written
    VehicleSession session;
    std::shared_ptr<std::atomic<bool>> cancel;  // of the running search
  };

  std::shared_ptr<Slot> find(const std::string& vehicle_id) const;
  std::shared_ptr<Slot> find_or_add(const std::string& vehicle_id);
  // Applies cancel/search effects (caller holds slot.mutex), then hands the lock over to the
  // publish lock and writes path and status. Returns the job for a search order.
  std::optional<PlanningJob> settle(Slot& slot, std::unique_lock<std::mutex>& lock, SessionEffects effects,
                                    const std::string& vehicle_id);

  const StartPlanner& planner_;
  Outbox& outbox_;
  SessionOptions options_;
  mutable std::mutex mutex_;  // guards vehicles_ (the map, not the sessions)
  std::unordered_map<std::string, std::shared_ptr<Slot>> vehicles_;
};

}  // namespace pullout::service
