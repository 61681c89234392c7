// The per-vehicle session: one vehicle's departure state machine, as a pure core class.
//
// A session turns what arrives for one vehicle (requests, planning results, odometry samples, the
// passing of time) into what must be published (a path, then a status) and into searches to run.
// It holds no lock, reads no clock and knows no DDS: every input carries the caller's time, and
// every call returns its effects. The service keeps one session per vehicle under that vehicle's
// lock and publishes the effects in the order it got them.
//
// States and transitions (PullOutStatus::state):
//
//   on_request (valid)        -> kPlanning, and a SearchOrder to run (the previous search is void)
//   on_request (invalid)      -> kRejected: a path with found = false and the field-named issues
//   on_request (re-sent)      -> same state: only the objects of the safety check change, the
//                                current path (as published) is re-published under the new id
//   on_request (repeated: the same request id and stamp as the latest request, as the client's
//              retry sends it) -> nothing changes and no search: the status is re-published, and
//                                the path when one is followed for that id (idempotent)
//   on_result (found)         -> kWaitingApproval, with the safety verdict at the start pose
//   on_result (no path)       -> kNoPath (the stop path)       on_result (rejected) -> kRejected
//   on_progress, not approved -> kWaitingApproval
//   on_progress, approved     -> kWaitingSafety while the turn signal has not been on for
//                                prepare_time_before_start, or the safety monitor says unsafe;
//                                then kExecuting (departed = true)
//   after departure, unsafe or approval withdrawn, or odometry lost (on_time)
//                             -> kWaitingSafety, and the path is re-published with a feasible stop
//   stopped, safe and approved again -> kExecuting, the original path re-published
//   the vehicle passes the end pose of the last segment -> kCompleted
//
// Rules that make this safe by construction:
//   - Departure is never the default: only a progress sample with approved = true approves.
//   - Every request is validated in full (StartPlanner::validate) before anything of it is kept;
//     a re-sent request that only updates the objects is validated like a new one.
//   - Safety is evaluated on exactly the lanes and objects the path was planned on (the world the
//     PlanningResult carries), objects replaced by re-sent requests.
//   - Progress samples must belong to the followed request and have plausible stamps: strictly
//     after the last accepted sample, and not ahead of it by more than the time that passed on the
//     service's clock plus kMaxStampLead (kReanchorSamples consistent refused samples in a row
//     replace the reference). Standstill (th_stopped_time) and the turn signal's
//     prepare time are measured on the accepted samples' stamps and never credited more than the
//     service's clock saw pass.
//   - A departed vehicle whose odometry stops (no accepted sample for progress_timeout) gets a stop:
//     the service cannot check the safety of a vehicle it cannot see.
//
// Re-sent requests: a request for the same goal (within 0.1 m and 0.05 rad) while a found path is
// followed does not re-plan when the vehicle has departed (the path is latched), or when the last
// search is less than backward_path_update_duration old and the ego stands within
// th_arrived_distance of the path's start. Before departure, a re-plan for the same goal with the
// same turn signal keeps the signal's start.
//
// Outgoing samples carry vehicle id and request id; their stamp_ns is left 0 for the publisher.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pullout/execution/execution_tracker.hpp"
#include "pullout/model/types.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/safety/safety_monitor.hpp"
#include "pullout/session/fleet.hpp"

namespace pullout {

struct SessionOptions {
  // [s] A departed vehicle with no accepted progress sample for this long is told to stop
  // (kWaitingSafety, "odometry lost"). 0 disables the rule.
  double progress_timeout_s{2.0};
  // [m] Vehicles that see each other (fleet.hpp): the ego's footprint is pushed out this much on
  // each side when its remaining path is checked against another vehicle's.
  double fleet_clearance_m{0.5};
};

// [s] How far a progress stamp may run ahead of the service's clock since the previous accepted
// sample: the jitter of the vehicle's sending and of the network, and the samples that a
// keep-last-1 reader merges when they come in a burst (a replay or a test driving faster than
// real time). Standstill and prepare time are bounded by the service's clock anyway.
inline constexpr double kMaxStampLead = 10.0;
// A vehicle clock that stepped (or a first sample with a wrong stamp) is recovered from when this
// many consecutive refused samples agree with each other: they become the reference, and the
// standstill and the turn signal's prepare time are measured afresh.
inline constexpr int kReanchorSamples = 5;

// A search the caller must run: StartPlanner::plan(request), its result handed back with
// on_result(sequence, ...). Any earlier search of the vehicle is void (cancel it).
struct SearchOrder {
  std::uint64_t sequence{0};
  PullOutRequest request;
  // The world of the vehicle's previous search, for StartPlanner::plan's `previous` (it reuses the
  // lane world when the lanes are identical); null when there is none.
  std::shared_ptr<const PlannedWorld> previous_world;
};

struct SessionEffects {
  std::optional<PullOutPath> path;      // publish first
  std::optional<PullOutStatus> status;  // then this
  std::optional<SearchOrder> search;    // then start this search
  bool cancel_search{false};            // the vehicle's running search is void (also with `search`)
  std::string note;                     // what happened, for the log (empty: nothing worth saying)

  bool empty() const { return !path && !status && !search && !cancel_search; }
};

// What a vehicle was last told, and the request it answers: enough to rebuild its session in
// another process (a replica taking the vehicle over, the service after a restart).
struct SessionSnapshot {
  // The request status.request_id answers (for a path: planned for it, or the re-sent request
  // whose objects updated it). Its lanes and objects are what the safety check uses.
  PullOutRequest request;
  std::optional<PullOutPath> path;  // the path last published for it (found or not)
  PullOutStatus status;             // the status last published
  // `request` is a later request of the vehicle than the one status answers (a replica that took
  // the vehicle over saw the re-sent request but not the status that answered it): its lanes and
  // objects serve the safety check, and the caller hands it to on_request after the restore.
  bool request_is_later{false};
};

class VehicleSession {
 public:
  using Clock = std::chrono::steady_clock;

  // `planner` must outlive the session; it validates requests and gives the vehicle and the
  // parameters of the execution tracker, the departure rules and the safety checks.
  VehicleSession(std::string vehicle_id, const StartPlanner& planner, SessionOptions options = {});

  // A request of this vehicle. `conversion_issues`: problems found while decoding it (the request
  // is rejected with them, and not validated further).
  SessionEffects on_request(PullOutRequest request, const std::vector<RequestIssue>& conversion_issues,
                            Clock::time_point now);
  // The result of the search `sequence`; nothing happens when a newer request came meanwhile.
  SessionEffects on_result(std::uint64_t sequence, const PlanningResult& result, Clock::time_point now);
  // The search `sequence` failed with an exception (a bug): kNoPath with the reason.
  SessionEffects on_search_failed(std::uint64_t sequence, const std::string& what, Clock::time_point now);
  // One odometry sample of this vehicle. `fleet`: the other vehicles driving their paths
  // (FleetBoard::obstacles_for): before departure the vehicle waits (kWaitingSafety) while its
  // path crosses one of them, after departure it gets a stop; the status names that vehicle
  // (waiting_for_vehicle_id) and the stop reason does ("waiting for vehicle 'A': ...").
  SessionEffects on_progress(const ExecutionProgress& progress, Clock::time_point now,
                             const std::vector<FleetObstacle>& fleet = {});
  // Time passes with no input (called periodically).
  SessionEffects on_time(Clock::time_point now);
  // Rebuilds a fresh session (nothing received yet) from `snapshot`; `world` is what
  // StartPlanner::planned_world gives for snapshot.request (null: the request is unknown or not
  // valid). The vehicle keeps its path, current_path_idx, departure and approval state:
  //   - kPlanning: the request is searched again (a SearchOrder);
  //   - a found path and a world: the path is followed again from current_path_idx, the safety
  //     checked on `world`; not departed: the turn signal's prepare time is measured afresh on
  //     this session's clock (never shorter); departed and kWaitingSafety: resumes only stopped,
  //     safe and approved, like after an inserted stop;
  //   - a found path and no world: without a safety check nothing may drive: kNoPath, a path with
  //     found = false and the reason (the vehicle sends its request again);
  //   - any other state: kept as it is.
  // The effects re-publish the path and the status (the same request id and segments).
  SessionEffects restore(const SessionSnapshot& snapshot, const std::shared_ptr<const PlannedWorld>& world,
                         Clock::time_point now);
  // The found path of `request_id` could not be published (a transport failure): the vehicle
  // never got it, so it is not followed (kNoPath with the reason).
  SessionEffects on_path_undeliverable(std::uint64_t request_id);

  const PullOutStatus& status() const { return status_; }
  // The path this vehicle drives, for the other vehicles: set while it has departed on a found
  // path and not completed it (executing, or stopped on it for safety).
  std::optional<ExecutingPath> executing() const;
  // The sequence of the search whose result is awaited (0: none).
  std::uint64_t pending_search() const { return pending_; }
  // When the session last received anything from its vehicle.
  Clock::time_point last_input() const { return last_input_; }
  // What the session keeps of its vehicle's requests: the objects of the request whose search
  // is awaited (the safety check keeps its own copy once a path is found), and the points of the
  // followed and published paths. Zero objects once no search is awaited; zero points unless a
  // found path is followed: a rejected request, a no-path or a failed search keeps nothing.
  struct Retained {
    std::size_t objects{0};
    std::size_t path_points{0};
  };
  Retained retained() const;

 private:
  // No path is followed any more: tracker, safety monitor, stop and progress reference forgotten.
  void forget_path();
  // A request replaces whatever was followed: the running search is void, no path is followed.
  void supersede();
  SessionEffects reject(std::uint64_t request_id, const std::vector<RequestIssue>& issues);
  // The departure and safety rules for one accepted sample; fills `out` and returns whether the
  // status changed.
  bool apply_departure_rules(const ExecutionProgress& progress, Clock::time_point now,
                             const std::vector<FleetObstacle>& fleet, SessionEffects& out);
  // Re-publishes the path with a feasible stop from the vehicle's last known motion.
  void insert_stop(const Pose2& pose, double velocity, const std::string& reason, SessionEffects& out);
  PullOutStatus make_status(std::uint64_t request_id, ExecutionState state) const;
  PullOutPath stamped(PullOutPath path) const;

  std::string vehicle_id_;
  const StartPlanner& planner_;
  SessionOptions options_;
  ExecutionTracker tracker_;

  std::uint64_t sequence_{0};  // number of requests received, accepted or not
  std::uint64_t pending_{0};   // the search whose result is awaited (0: none)
  PullOutStatus status_;       // the last status published
  Clock::time_point last_input_{};

  std::int64_t request_stamp_ns_{0};  // of the latest request, accepted or not
  // Of the latest accepted request.
  Pose2 goal_;
  Pose2 request_ego_;
  double request_ego_velocity_{0.0};
  Clock::time_point planned_at_{};
  std::vector<Object> objects_;  // the latest objects (re-sent requests replace them)
  // The world of the latest search's result that has a lane world (kFound or kNoPath), handed to
  // the next search (SearchOrder::previous_world) so that a request with the same lanes does not
  // build the same lane world again. Only for that reuse, never for safety (safety_ has its own
  // reference). Dropped when a request is rejected.
  std::shared_ptr<const PlannedWorld> last_world_;

  // The found path being followed (as planned), its safety monitor and what was published of it.
  std::optional<PullOutPath> path_;
  std::optional<SafetyMonitor> safety_;
  VehicleInfo planned_vehicle_;  // the vehicle path_ was planned for (its own, a profile's, the default)
  PullOutPath published_;
  bool stop_inserted_{false};
  // Turn signal and its start (stamp, service time) carried from a path a same-goal re-plan replaces.
  struct SignalStart {
    TurnSignal signal{TurnSignal::kNone};
    std::int64_t stamp_ns{0};
    Clock::time_point at{};
  };
  std::optional<SignalStart> signal_carry_;
  Clock::time_point signal_on_at_{};  // service time of the sample that switched the signal on

  // The last accepted progress sample of the followed path.
  struct Accepted {
    std::int64_t stamp_ns{0};
    Clock::time_point at{};
    Pose2 pose;
    double velocity{0.0};
  };
  std::optional<Accepted> last_sample_;
  // Refused samples that agree with each other (they replace last_sample_ at kReanchorSamples).
  std::optional<Accepted> refused_;
  int refused_in_a_row_{0};
  // Whether `sample` may follow `previous` (strictly later, not ahead of the clock). Sets `why`.
  static bool follows(const Accepted& previous, const Accepted& sample, std::string& why);
};

}  // namespace pullout
