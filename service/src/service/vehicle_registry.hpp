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
//
// Eviction (the registry holds at most options.max_vehicles sessions over a lifetime of any number
// of vehicle ids). A session is idle when no search of it is awaited and it is not driving a path
// (departed and not completed). It is evicted
//   - kGone:     idle, and its vehicle's request and progress instances are no longer alive on the
//                service's readers (on_instance_gone: unregistered, disposed, or no writer left);
//                a vehicle driving a path only once it was also silent for the idle timeout;
//   - kIdle:     idle, and no request and no progress for session_idle_timeout_s;
//   - kCapacity: when a new vehicle comes and max_vehicles sessions are held: the least recently
//                active idle session (one of kGone first). When none is idle, the new vehicle
//                gets a kRejected path and status naming service.max_vehicles, and no session.
// on_time() sweeps for kGone and kIdle (at most kMaxEvictionsPerSweep per call). Eviction removes
// the session and calls Outbox::forget_vehicle (unregisters the vehicle's path and status
// instances) after any of its samples in flight; each is logged with the reason and idle time.
// A departed vehicle that still sends progress is never idle, so never evicted.
//
// Vehicles that see each other: the registry keeps a FleetBoard of every vehicle driving a path
// (departed, not completed), refreshed whenever a session's effects are settled and cleared on
// eviction. Each progress sample's session gets the other vehicles' executing paths near it
// (FleetBoard::obstacles_for) for its departure and safety rules, and each search gets them as
// objects (their bodies and timed predicted motion). Progress samples are dispatched on one
// thread, so two vehicles never decide to depart at the same instant without seeing each other.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/session/fleet.hpp"
#include "pullout/session/vehicle_session.hpp"
#include "service/outbox.hpp"
#include "service/planning_queue.hpp"

namespace pullout::service {

// Nanoseconds since the epoch, for the stamps of outgoing samples.
std::int64_t now_ns();

// How many evictions one on_time() sweep does at most (each is two unregister writes); the rest
// wait for the next sweep.
inline constexpr std::size_t kMaxEvictionsPerSweep = 256;

struct RegistryOptions {
  SessionOptions session;
  // [s] See the eviction rules above; 0 = no kIdle eviction.
  double session_idle_timeout_s{300.0};
  // Sessions held at once (>= 1).
  std::size_t max_vehicles{2048};
  // [m] Vehicles that see each other: another vehicle's executing path counts for a vehicle when
  // it comes this close to the vehicle's pose (bounds the work per sample).
  double fleet_radius_m{200.0};
  // The registry's time (sessions, idle times); tests inject a fake. Empty: steady_clock::now.
  std::function<VehicleSession::Clock::time_point()> clock;
  // Observers for statistics (the service's metrics); empty: none. Called on the publishing
  // thread, after the samples are written; they must be quick and must not call the registry.
  //   on_reply:   the first status of a request with an outcome (rejected, no path, or a found
  //               path), once per request and outcome, and every rejection for a full registry;
  //   on_evicted: each eviction.
  std::function<void(const PullOutStatus&)> on_reply;
  std::function<void(int /*EvictionReason*/)> on_evicted;
};

// The reader a vehicle's instance lived on.
enum class VehicleInput { kRequest, kProgress };

enum class EvictionReason { kGone, kIdle, kCapacity };
const char* to_string(EvictionReason reason);

class VehicleRegistry {
 public:
  using Clock = VehicleSession::Clock;

  // `planner` validates requests and configures the sessions; it must outlive the registry.
  VehicleRegistry(const StartPlanner& planner, Outbox& outbox, RegistryOptions options = {});

  // A request; `conversion_issues` are the problems found while decoding it. Returns the search
  // to queue, if the session ordered one. `hold_planning`: the `planning` status of a search
  // order is kept back instead of written (the caller tries the search at once, so that a quick
  // answer is the vehicle's first sample); release_planning writes it, and any later sample of
  // the vehicle (the result above all) drops it.
  std::optional<PlanningJob> on_request(PullOutRequest request, const std::vector<RequestIssue>& conversion_issues,
                                        bool hold_planning = false);
  // Writes the `planning` status on_request kept back for `job`, unless something newer of the
  // vehicle was written since (then nothing).
  void release_planning(const PlanningJob& job);
  // A finished search; publishes nothing when a newer request of the vehicle came meanwhile.
  void on_result(const PlanningJob& job, const PlanningResult& result);
  // The search threw (a bug in the core).
  void on_search_failed(const PlanningJob& job, const std::string& what);
  // One odometry sample (decoded without problems).
  void on_progress(const ExecutionProgress& progress);
  // The vehicle's instance on that reader is no longer alive (unregistered, disposed, or no writer
  // left). A later valid sample makes it alive again. Unknown vehicles are ignored.
  void on_instance_gone(const std::string& vehicle_id, VehicleInput input);
  // Rebuilds the vehicle's session from a snapshot (VehicleSession::restore; `world`:
  // StartPlanner::planned_world of snapshot.request, null when unknown) and publishes its path and
  // status: a replica taking the vehicle over, or the service restarting. Replaces a session held
  // for it. Returns the search to queue (a search that died with its process). Null when the
  // registry is full of busy sessions (logged).
  std::optional<PlanningJob> restore(const SessionSnapshot& snapshot, std::shared_ptr<const PlannedWorld> world);
  // Drops the vehicle's session without a word on DDS (another replica serves it now): its
  // search is cancelled, nothing more is published for it. Returns whether one was held.
  bool release(const std::string& vehicle_id);
  // Time passes: every session's on_time (the odometry watchdog), then the eviction sweep.
  void on_time();

  // Sessions held, and whether one is held for `vehicle_id` (for tests and statistics).
  std::size_t size() const;
  bool holds(const std::string& vehicle_id) const;
  // Sessions evicted so far, by any reason, and new vehicles rejected because the registry was full.
  std::size_t evicted_count() const { return evicted_count_.load(); }
  std::size_t rejected_full_count() const { return rejected_full_count_.load(); }

  // Cancels every running search (shutdown).
  void cancel_all();

 private:
  struct Slot {
    Slot(const std::string& id, const StartPlanner& planner, SessionOptions options) : session(id, planner, options) {}
    std::mutex mutex;          // guards session and cancel
    std::mutex publish_mutex;  // held while this vehicle's effects are written
    VehicleSession session;
    std::shared_ptr<std::atomic<bool>> cancel;  // of the running search
    // Whether the vehicle's instance is alive on the request / progress reader (guarded by mutex).
    bool request_alive{false};
    bool progress_alive{false};
    bool evicted{false};  // removed from the map: publishes nothing more (guarded by mutex)
    // The `planning` status of search `held_sequence`, kept back by on_request(hold_planning)
    // (guarded by mutex; dropped when any later sample of the vehicle is written).
    std::optional<PullOutStatus> held_planning;
    std::uint64_t held_sequence{0};
    // The last request and outcome reported to on_reply (guarded by publish_mutex).
    std::uint64_t replied_request_id{0};
    int replied_outcome{-1};
  };

  std::shared_ptr<Slot> find(const std::string& vehicle_id) const;
  // The vehicle's slot; a new one if there is room or an idle session can be evicted for it;
  // null when the registry is full of sessions that are not idle.
  std::shared_ptr<Slot> find_or_admit(const std::string& vehicle_id, Clock::time_point now);
  // Why `slot` should go now (caller holds slot.mutex); nullopt: it stays. `for_capacity`: also
  // any idle session (kCapacity).
  std::optional<EvictionReason> eviction_reason(const Slot& slot, Clock::time_point now, bool for_capacity) const;
  // Unregisters the vehicle's instances after its samples in flight, and logs. The slot is
  // already marked evicted and out of the map.
  void forget(Slot& slot, const std::string& vehicle_id, EvictionReason reason, Clock::time_point now);
  // A new vehicle while the registry is full: kRejected path and status, instances unregistered.
  void reject_full(const PullOutRequest& request);
  // Applies cancel/search effects (caller holds slot.mutex), then hands the lock over to the
  // publish lock and writes path and status. Returns the job for a search order.
  std::optional<PlanningJob> settle(Slot& slot, std::unique_lock<std::mutex>& lock, SessionEffects effects,
                                    const std::string& vehicle_id);

  // The vehicle's entry on the fleet board from its session (caller holds slot.mutex).
  void refresh_fleet(const Slot& slot, const std::string& vehicle_id);
  // The other vehicles' executing paths as objects of a search about to run (before departure
  // they count in planning: their bodies as obstacles, their motion predicted).
  void add_fleet_objects(PlanningJob& job);

  const StartPlanner& planner_;
  Outbox& outbox_;
  // Vehicles that see each other: every vehicle driving a path (pullout/session/fleet.hpp). Locked
  // after a slot's mutex, never before one.
  mutable std::mutex fleet_mutex_;
  FleetBoard fleet_;
  RegistryOptions options_;
  mutable std::mutex mutex_;  // guards vehicles_ (the map, not the sessions)
  std::unordered_map<std::string, std::shared_ptr<Slot>> vehicles_;
  std::atomic<std::size_t> evicted_count_{0};
  std::atomic<std::size_t> rejected_full_count_{0};
  Clock::time_point last_full_log_{};  // rate limit of reject_full's log line (dispatcher only)
  std::size_t full_since_log_{0};
};

}  // namespace pullout::service
