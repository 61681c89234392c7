#include "pullout/session/vehicle_session.hpp"

#include <cmath>
#include <utility>

#include "pullout/geometry/polyline.hpp"
#include "pullout/model/names.hpp"
#include "pullout/safety/stop_path.hpp"

namespace pullout {
namespace {

// A re-sent request asks for the same goal when it is this close to the previous one.
constexpr double kSameGoalDistance = 0.1;  // [m]
constexpr double kSameGoalYaw = 0.05;      // [rad]

bool same_goal(const Pose2& a, const Pose2& b) {
  return std::hypot(a.x - b.x, a.y - b.y) <= kSameGoalDistance &&
         std::abs(normalize_angle(a.yaw - b.yaw)) <= kSameGoalYaw;
}

// The fields of a status whose change is worth a new sample.
bool same_status(const PullOutStatus& a, const PullOutStatus& b) {
  return a.state == b.state && a.current_path_idx == b.current_path_idx && a.stop_reason == b.stop_reason &&
         a.safe == b.safe && a.unsafe_object_id == b.unsafe_object_id && a.departed == b.departed &&
         a.turn_signal_start_ns == b.turn_signal_start_ns && a.waiting_for_vehicle_id == b.waiting_for_vehicle_id;
}

std::vector<std::string> issue_lines(const std::vector<RequestIssue>& issues) {
  std::vector<std::string> lines;
  lines.reserve(issues.size());
  for (const auto& i : issues) lines.push_back(i.field + ": " + i.problem);
  return lines;
}

double seconds(VehicleSession::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

VehicleSession::VehicleSession(std::string vehicle_id, const StartPlanner& planner, SessionOptions options)
    : vehicle_id_(std::move(vehicle_id)), planner_(planner), options_(options), tracker_(planner.parameters()) {
  status_.vehicle_id = vehicle_id_;
}

PullOutStatus VehicleSession::make_status(std::uint64_t request_id, ExecutionState state) const {
  PullOutStatus s;
  s.vehicle_id = vehicle_id_;
  s.request_id = request_id;
  s.state = state;
  return s;
}

PullOutPath VehicleSession::stamped(PullOutPath path) const {
  path.vehicle_id = vehicle_id_;
  path.stamp_ns = 0;
  return path;
}

VehicleSession::Retained VehicleSession::retained() const {
  const auto points = [](const PullOutPath& p) {
    std::size_t n = 0;
    for (const auto& segment : p.partial_paths) n += segment.points.size();
    return n;
  };
  Retained r;
  r.objects = objects_.size();
  r.path_points = (path_ ? points(*path_) : 0) + points(published_);
  return r;
}

void VehicleSession::forget_path() {
  tracker_.clear();
  path_.reset();
  safety_.reset();
  published_ = PullOutPath{};  // its storage goes with it
  stop_inserted_ = false;
  last_sample_.reset();
  refused_.reset();
  refused_in_a_row_ = 0;
}

void VehicleSession::supersede() {
  ++sequence_;
  pending_ = 0;
  forget_path();
}

SessionEffects VehicleSession::reject(std::uint64_t request_id, const std::vector<RequestIssue>& issues) {
  supersede();
  objects_ = std::vector<Object>{};  // clear() would keep the capacity
  last_world_.reset();
  SessionEffects out;
  out.cancel_search = true;
  PullOutPath path;
  path.request_id = request_id;
  path.found = false;
  path.reasons = issue_lines(issues);
  out.path = stamped(std::move(path));
  status_ = make_status(request_id, ExecutionState::kRejected);
  status_.error = format_issues(issues);
  out.status = status_;
  out.note = "rejected: " + std::to_string(issues.size()) + " problem(s), first: " + issues.front().field + ": " +
             issues.front().problem;
  return out;
}

SessionEffects VehicleSession::on_request(PullOutRequest request, const std::vector<RequestIssue>& conversion_issues,
                                          Clock::time_point now) {
  last_input_ = now;
  // A repeated request (the client re-sends the sample it wrote until it is answered): the same
  // id and stamp as the latest request. No second search and no change: the session answers with
  // what it has, the status (planning while the search runs) and the path it follows for that id.
  if (status_.state != ExecutionState::kIdle && request.request_id == status_.request_id &&
      request.stamp_ns == request_stamp_ns_) {
    SessionEffects out;
    if (path_ && has_path(status_.state) && published_.request_id == request.request_id) out.path = stamped(published_);
    out.status = status_;
    out.note = "repeated request " + std::to_string(request.request_id) + ": answered with the current state";
    return out;
  }
  request_stamp_ns_ = request.stamp_ns;
  // Validated in full before anything of it is kept, whatever happens to it next.
  const std::vector<RequestIssue> issues = conversion_issues.empty() ? planner_.validate(request) : conversion_issues;
  if (!issues.empty()) return reject(request.request_id, issues);

  const StartPlannerParameters& p = planner_.parameters();
  // The same goal for the same vehicle: a request for other dimensions is a new situation.
  const bool same_vehicle = planner_.vehicle_for(request) == planned_vehicle_;
  if (path_ && safety_ && tracker_.active() && status_.state != ExecutionState::kCompleted && same_vehicle &&
      same_goal(goal_, request.goal_pose)) {
    const bool latched = status_.departed;
    // Before departure the vehicle stands where the path starts; elsewhere it is a new situation.
    const Pose2& start = path_->partial_paths.front().points.front().pose;
    const bool at_start =
        std::hypot(request.ego_pose.x - start.x, request.ego_pose.y - start.y) <= p.th_arrived_distance;
    const bool throttled = at_start && seconds(now - planned_at_) < p.backward_path_update_duration;
    if (latched || throttled) {
      // Objects only: the same path under the new request id, segment index kept.
      ++sequence_;
      safety_->update_objects(std::move(request.objects));
      path_->request_id = request.request_id;
      published_.request_id = request.request_id;
      tracker_.adopt(request.request_id);
      status_.request_id = request.request_id;
      SessionEffects out;
      out.path = stamped(published_);
      out.status = status_;
      out.note = std::string("objects updated on the ") + (latched ? "latched" : "current") + " path";
      return out;
    }
  }
  // A re-plan before departure for the same goal keeps the turn signal's start, so that periodic
  // re-plans do not restart prepare_time_before_start.
  const bool same_situation =
      has_path(status_.state) && !status_.departed && same_vehicle && same_goal(goal_, request.goal_pose);
  signal_carry_ =
      same_situation && status_.turn_signal_start_ns != 0
          ? std::make_optional(SignalStart{status_.turn_signal, status_.turn_signal_start_ns, signal_on_at_})
          : std::nullopt;
  supersede();
  goal_ = request.goal_pose;
  request_ego_ = request.ego_pose;
  request_ego_velocity_ = request.ego_velocity_mps;
  planned_at_ = now;
  objects_ = request.objects;
  pending_ = sequence_;
  status_ = make_status(request.request_id, ExecutionState::kPlanning);

  SessionEffects out;
  out.status = status_;
  out.cancel_search = true;
  out.search = SearchOrder{sequence_, std::move(request), last_world_};
  return out;
}

SessionEffects VehicleSession::on_result(std::uint64_t sequence, const PlanningResult& result, Clock::time_point now) {
  SessionEffects out;
  if (sequence == 0 || sequence != pending_) return out;  // a newer request came meanwhile
  pending_ = 0;
  const std::uint64_t request_id = status_.request_id;
  if (result.world && result.world->lane_world) last_world_ = result.world;

  PullOutStatus status = make_status(request_id, ExecutionState::kNoPath);
  status.evaluation_table = result.evaluation_table;
  status.planning_time_ms = result.planning_time_ms;
  PullOutPath path;
  switch (result.outcome) {
    case PlanningResult::Outcome::kFound:
      path = result.path;
      path.found = true;
      status.state = ExecutionState::kWaitingApproval;
      status.stop_reason = "waiting approval";
      status.turn_signal = path.turn_signal;
      status.path_end = result.path_end.note;
      break;
    case PlanningResult::Outcome::kNoPath:
      path = result.path;
      path.found = false;
      status.stop_reason = result.stop_reason;
      if (status.stop_reason.empty()) {
        status.stop_reason = result.timed_out ? "planning deadline expired" : "no path found";
      }
      break;
    case PlanningResult::Outcome::kRejected:
      path.found = false;
      path.reasons = issue_lines(result.issues);
      status.state = ExecutionState::kRejected;
      status.error = format_issues(result.issues);
      break;
  }
  path.request_id = request_id;  // the reply belongs to this request whatever the core filled in
  status.planner_type = path.planner_type;
  status.segment_count = static_cast<std::uint32_t>(path.partial_paths.size());

  forget_path();
  if (status.state == ExecutionState::kWaitingApproval) {
    if (!result.world || path.partial_paths.empty() || path.partial_paths.front().points.empty()) {
      // A found path must come with the world it was planned on: without it, no safety check.
      status = make_status(request_id, ExecutionState::kNoPath);
      status.stop_reason = "internal error: the planning result carries no world for the safety check";
      path = PullOutPath{};
      path.request_id = request_id;
      path.reasons = {status.stop_reason};
    } else {
      tracker_.start(path);
      path_ = path;
      published_ = path;
      planned_vehicle_ = result.world->vehicle;
      // The lane world the path was planned on, shared rather than built again.
      if (result.world->lane_world) {
        safety_.emplace(planner_.parameters(), planned_vehicle_, result.world->lane_world, objects_, path);
      } else {
        safety_.emplace(planner_.parameters(), planned_vehicle_, result.world->lanes, objects_, path);
      }
      if (signal_carry_ && signal_carry_->signal == path.turn_signal) {
        status.turn_signal_start_ns = signal_carry_->stamp_ns;
        signal_on_at_ = signal_carry_->at;
      }
      // The verdict the vehicle sees before it moves: the safety at the start, at its speed then.
      const SafetyVerdict verdict =
          safety_->evaluate(path.partial_paths.front().points.front().pose, request_ego_velocity_, 0, false);
      status.safe = verdict.safe;
      status.unsafe_object_id = verdict.safe ? 0 : verdict.object_id;
    }
  }
  signal_carry_.reset();
  objects_ = std::vector<Object>{};  // the safety monitor has its copy; nothing else needs them
  (void)now;
  status_ = status;
  out.path = stamped(std::move(path));
  out.status = status_;
  return out;
}

SessionEffects VehicleSession::on_search_failed(std::uint64_t sequence, const std::string& what,
                                                Clock::time_point now) {
  SessionEffects out;
  if (sequence == 0 || sequence != pending_) return out;
  (void)now;
  pending_ = 0;
  forget_path();
  objects_ = std::vector<Object>{};
  const std::string reason = "internal error: " + what;
  PullOutPath path;
  path.request_id = status_.request_id;
  path.reasons = {reason};
  status_ = make_status(status_.request_id, ExecutionState::kNoPath);
  status_.stop_reason = reason;
  out.path = stamped(std::move(path));
  out.status = status_;
  return out;
}

std::optional<ExecutingPath> VehicleSession::executing() const {
  if (!path_ || !status_.departed || status_.state == ExecutionState::kCompleted || !has_path(status_.state)) {
    return std::nullopt;
  }
  ExecutingPath e;
  e.vehicle_id = vehicle_id_;
  e.vehicle = planned_vehicle_;
  e.path = *path_;
  e.current_path_idx = status_.current_path_idx;
  e.pose = last_sample_ ? last_sample_->pose : path_->partial_paths.front().points.front().pose;
  e.velocity_mps = last_sample_ ? last_sample_->velocity : 0.0;
  return e;
}

SessionEffects VehicleSession::on_progress(const ExecutionProgress& progress, Clock::time_point now,
                                           const std::vector<FleetObstacle>& fleet) {
  SessionEffects out;
  last_input_ = now;
  if (!path_ || !has_path(status_.state) || status_.state == ExecutionState::kCompleted || !tracker_.active() ||
      tracker_.request_id() != progress.request_id) {
    out.note = "progress for request " + std::to_string(progress.request_id) + " ignored (state " +
               std::to_string(static_cast<int>(status_.state)) + ", request " + std::to_string(status_.request_id) +
               ")";
    return out;
  }
  if (const std::vector<RequestIssue> issues = planner_.validate(progress); !issues.empty()) {
    // Nothing to measure or to stop from (the stop profile grows with the speed): the vehicle
    // hears why on a status of its own; the session's state is unchanged.
    out.status = status_;
    out.status->error = format_issues(issues);
    out.note = "progress ignored: " + out.status->error;
    return out;
  }
  const Accepted current{progress.stamp_ns, now, progress.pose, progress.velocity_mps};
  std::string why;
  if (last_sample_ && !follows(*last_sample_, current, why)) {
    std::string ignored;
    refused_in_a_row_ = refused_ && follows(*refused_, current, ignored) ? refused_in_a_row_ + 1 : 1;
    refused_ = current;
    if (refused_in_a_row_ < kReanchorSamples) {
      out.note = "progress ignored: " + why;
      return out;
    }
    // The vehicle's clock is not the one of the reference: measure afresh on the new one.
    tracker_.restart_standstill();
    if (status_.turn_signal_start_ns != 0 && !status_.departed) {
      status_.turn_signal_start_ns = progress.stamp_ns;
      signal_on_at_ = now;
    }
    out.note = "progress stamps re-anchored after " + std::to_string(refused_in_a_row_) + " consistent samples";
  }
  refused_.reset();
  refused_in_a_row_ = 0;
  last_sample_ = current;
  if (!apply_departure_rules(progress, now, fleet, out)) return out;
  out.status = status_;
  return out;
}

bool VehicleSession::follows(const Accepted& previous, const Accepted& sample, std::string& why) {
  if (sample.stamp_ns <= previous.stamp_ns) {
    why = "stamp " + std::to_string(sample.stamp_ns) + " ns is not after the last accepted " +
          std::to_string(previous.stamp_ns) + " ns";
    return false;
  }
  const double lead =
      static_cast<double>(sample.stamp_ns - previous.stamp_ns) * 1e-9 - seconds(sample.at - previous.at);
  if (lead > kMaxStampLead) {
    why = "stamp runs " + std::to_string(lead) + " s ahead of the service's clock";
    return false;
  }
  return true;
}

SessionEffects VehicleSession::on_time(Clock::time_point now) {
  SessionEffects out;
  if (options_.progress_timeout_s <= 0.0 || !path_ || !status_.departed || stop_inserted_ ||
      status_.state != ExecutionState::kExecuting || !last_sample_) {
    return out;
  }
  const double silent = seconds(now - last_sample_->at);
  if (silent < options_.progress_timeout_s) return out;
  // The vehicle's motion is unknown: stop from the last known one.
  insert_stop(last_sample_->pose, last_sample_->velocity,
              "odometry lost: no progress sample for " + std::to_string(static_cast<int>(silent * 10.0) / 10.0) + " s",
              out);
  status_.state = ExecutionState::kWaitingSafety;
  out.status = status_;
  return out;
}

SessionEffects VehicleSession::restore(const SessionSnapshot& snapshot,
                                       const std::shared_ptr<const PlannedWorld>& world, Clock::time_point now) {
  const PullOutStatus& st = snapshot.status;
  const PullOutRequest& request = snapshot.request;
  if (st.state == ExecutionState::kPlanning && world && request.request_id == st.request_id) {
    // The search died with the process that ran it: run it again.
    request_stamp_ns_ = 0;  // not a repeat of anything this session has seen
    return on_request(request, {}, now);
  }
  last_input_ = now;
  forget_path();
  ++sequence_;
  pending_ = 0;
  request_stamp_ns_ = request.stamp_ns;
  goal_ = request.goal_pose;
  request_ego_ = request.ego_pose;
  request_ego_velocity_ = request.ego_velocity_mps;
  planned_at_ = now;
  objects_ = std::vector<Object>{};
  status_ = st;
  status_.vehicle_id = vehicle_id_;
  SessionEffects out;
  // With a later request, the path may already carry its id (the owner latched the path onto it
  // and left before its status went out).
  const bool path_answers =
      snapshot.path && (snapshot.path->request_id == st.request_id ||
                        (snapshot.request_is_later && snapshot.path->request_id == request.request_id));
  const bool found = path_answers && snapshot.path->found && !snapshot.path->partial_paths.empty() &&
                     !snapshot.path->partial_paths.front().points.empty();
  if (has_path(st.state) || st.state == ExecutionState::kPlanning) {
    if (!found || !world || (request.request_id != st.request_id && !snapshot.request_is_later)) {
      // No safety check without the world the path was planned on: nothing may drive.
      status_ = make_status(st.request_id, ExecutionState::kNoPath);
      status_.stop_reason = "service takeover: the request " + std::to_string(st.request_id) +
                            " that the path answers is not known here; send the request again";
      PullOutPath path;
      path.request_id = st.request_id;
      path.reasons = {status_.stop_reason};
      out.path = stamped(std::move(path));
      out.status = status_;
      out.note = status_.stop_reason;
      return out;
    }
    path_ = *snapshot.path;
    path_->request_id = st.request_id;
    published_ = *path_;
    tracker_.resume(*path_, st.current_path_idx, st.state == ExecutionState::kCompleted);
    status_.current_path_idx = tracker_.current_path_idx();
    planned_vehicle_ = world->vehicle;  // a van's path is checked with the van's footprint
    safety_.emplace(planner_.parameters(), planned_vehicle_, world->lanes, world->objects, *path_);
    // A stop inserted before the takeover is in the published path: resume like after one.
    stop_inserted_ = st.departed && st.state == ExecutionState::kWaitingSafety;
    signal_on_at_ = now;  // prepare time measured afresh here: never shorter than asked
    out.path = stamped(published_);
    out.note = "restored: " + std::string(to_string(st.state)) + " segment " +
               std::to_string(status_.current_path_idx + 1) + "/" + std::to_string(path_->partial_paths.size()) +
               (st.departed ? ", departed" : "");
  } else if (snapshot.path) {
    out.path = stamped(*snapshot.path);
  }
  out.status = status_;
  return out;
}

SessionEffects VehicleSession::on_path_undeliverable(std::uint64_t request_id) {
  SessionEffects out;
  if (!path_ || status_.request_id != request_id) return out;
  forget_path();
  status_.state = ExecutionState::kNoPath;
  status_.stop_reason = "internal error: the path could not be published";
  out.status = status_;
  return out;
}

void VehicleSession::insert_stop(const Pose2& pose, double velocity, const std::string& reason, SessionEffects& out) {
  stop_inserted_ = true;
  published_ =
      insert_feasible_stop(*path_, status_.current_path_idx, pose, velocity, planner_.parameters().stop_condition);
  out.path = stamped(published_);
  status_.state = ExecutionState::kWaitingSafety;
  status_.stop_reason = reason;
}

bool VehicleSession::apply_departure_rules(const ExecutionProgress& progress, Clock::time_point now,
                                           const std::vector<FleetObstacle>& fleet, SessionEffects& out) {
  const StartPlannerParameters& p = planner_.parameters();
  const PullOutStatus before = status_;
  PullOutStatus& s = status_;
  const ExecutionTracker::Update update = tracker_.on_progress(progress, now);
  s.current_path_idx = update.current_path_idx;
  if (update.completed) {
    s.state = ExecutionState::kCompleted;
    s.stop_reason.clear();
    return true;
  }
  SafetyVerdict verdict = safety_->evaluate(progress.pose, progress.velocity_mps, s.current_path_idx, s.departed);
  s.waiting_for_vehicle_id.clear();
  if (verdict.safe) {
    // Another vehicle's remaining path (or body) in the way of ours: wait for it.
    if (const auto conflict = first_fleet_conflict(*path_, s.current_path_idx, progress.pose, planned_vehicle_,
                                                   options_.fleet_clearance_m, fleet)) {
      verdict.safe = false;
      verdict.object_id = conflict->object_id;
      verdict.reason = "waiting for vehicle '" + conflict->vehicle_id + "': its path crosses this one";
      s.waiting_for_vehicle_id = conflict->vehicle_id;
    }
  }
  s.safe = verdict.safe;
  s.unsafe_object_id = verdict.safe ? 0 : verdict.object_id;

  if (!s.departed) {
    if (!progress.approved) {
      s.state = ExecutionState::kWaitingApproval;
      s.stop_reason = "waiting approval";
    } else {
      if (s.turn_signal_start_ns == 0) {
        s.turn_signal_start_ns = progress.stamp_ns;
        signal_on_at_ = now;
      }
      // On the vehicle's stamps, never more than the service's clock saw pass.
      const double on_stamps = static_cast<double>(progress.stamp_ns - s.turn_signal_start_ns) * 1e-9;
      const double signal_on_s = std::min(on_stamps, seconds(now - signal_on_at_));
      if (signal_on_s < p.prepare_time_before_start) {
        s.state = ExecutionState::kWaitingSafety;
        s.stop_reason = "turn signal prepare time";
      } else if (!verdict.safe) {
        s.state = ExecutionState::kWaitingSafety;
        s.stop_reason = verdict.reason;
      } else {
        s.state = ExecutionState::kExecuting;
        s.stop_reason.clear();
        s.departed = true;
      }
    }
  } else if (stop_inserted_) {
    const bool stopped = std::abs(progress.velocity_mps) < p.th_stopped_velocity;
    if (verdict.safe && progress.approved && stopped) {
      stop_inserted_ = false;
      published_ = *path_;
      out.path = stamped(published_);
      s.state = ExecutionState::kExecuting;
      s.stop_reason.clear();
    } else {
      s.state = ExecutionState::kWaitingSafety;
      s.stop_reason = !verdict.safe        ? verdict.reason
                      : !progress.approved ? std::string("waiting approval")
                                           : std::string("stopping before resuming");
    }
  } else if (!verdict.safe || !progress.approved) {
    insert_stop(progress.pose, progress.velocity_mps, verdict.safe ? std::string("approval withdrawn") : verdict.reason,
                out);
  }
  return !same_status(before, s);
}

}  // namespace pullout
