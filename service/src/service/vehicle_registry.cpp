#include "service/vehicle_registry.hpp"

#include <chrono>
#include <cmath>
#include <utility>

#include <spdlog/spdlog.h>

#include "pullout/model/names.hpp"
#include "pullout/safety/stop_path.hpp"

namespace pullout::service {
namespace {

PullOutStatus status_for(const std::string& vehicle_id, std::uint64_t request_id, ExecutionState state) {
  PullOutStatus s;
  s.vehicle_id = vehicle_id;
  s.request_id = request_id;
  s.stamp_ns = now_ns();
  s.state = state;
  return s;
}

// found = false and no segments: the vehicle must not move on behalf of this request.
PullOutPath empty_path(const std::string& vehicle_id, std::uint64_t request_id, std::vector<std::string> reasons) {
  PullOutPath p;
  p.vehicle_id = vehicle_id;
  p.request_id = request_id;
  p.stamp_ns = now_ns();
  p.found = false;
  p.planner_type = PlannerType::kNone;
  p.reasons = std::move(reasons);
  return p;
}

std::vector<std::string> issue_lines(const std::vector<RequestIssue>& issues) {
  std::vector<std::string> lines;
  lines.reserve(issues.size());
  for (const auto& i : issues) lines.push_back(i.field + ": " + i.problem);
  return lines;
}

// A re-sent request asks for the same goal when it is this close to the previous one.
constexpr double kSameGoalDistance = 0.1;  // [m]
constexpr double kSameGoalYaw = 0.05;      // [rad]

bool same_goal(const Pose2& a, const Pose2& b) {
  return std::hypot(a.x - b.x, a.y - b.y) <= kSameGoalDistance &&
         std::abs(std::remainder(a.yaw - b.yaw, 2.0 * M_PI)) <= kSameGoalYaw;
}

// The fields of a status whose change is worth a new sample.
bool same_status(const PullOutStatus& a, const PullOutStatus& b) {
  return a.state == b.state && a.current_path_idx == b.current_path_idx && a.stop_reason == b.stop_reason &&
         a.safe == b.safe && a.unsafe_object_id == b.unsafe_object_id && a.departed == b.departed &&
         a.turn_signal_start_ns == b.turn_signal_start_ns;
}

}  // namespace

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

VehicleRegistry::VehicleRegistry(const VehicleInfo& vehicle, const StartPlannerParameters& parameters, Outbox& outbox)
    : vehicle_(vehicle), parameters_(parameters), outbox_(outbox) {}

std::shared_ptr<VehicleRegistry::Vehicle> VehicleRegistry::find(const std::string& vehicle_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = vehicles_.find(vehicle_id);
  return it == vehicles_.end() ? nullptr : it->second;
}

std::shared_ptr<VehicleRegistry::Vehicle> VehicleRegistry::find_or_add(const std::string& vehicle_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& slot = vehicles_[vehicle_id];
  if (!slot) slot = std::make_shared<Vehicle>(parameters_);
  return slot;
}

std::size_t VehicleRegistry::vehicle_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return vehicles_.size();
}

void VehicleRegistry::supersede(Vehicle& v) {
  ++v.sequence;
  if (v.cancel) v.cancel->store(true);
  v.cancel.reset();
  v.tracker.clear();
  v.path.reset();
  v.safety.reset();
  v.stop_inserted = false;
}

std::optional<PlanningJob> VehicleRegistry::accept(PullOutRequest request) {
  auto v = find_or_add(request.vehicle_id);
  std::lock_guard<std::mutex> lock(v->mutex);
  const auto now = std::chrono::steady_clock::now();
  if (v->path && v->safety && v->tracker.active() && v->status.state != ExecutionState::kCompleted &&
      same_goal(v->goal, request.goal_pose)) {
    const bool latched = v->status.departed;
    // Before departure the vehicle stands where the path starts; elsewhere it is a new situation.
    const Pose2& start = v->path->partial_paths.front().points.front().pose;
    const bool at_start =
        std::hypot(request.ego_pose.x - start.x, request.ego_pose.y - start.y) <= parameters_.th_arrived_distance;
    const bool throttled = at_start && std::chrono::duration<double>(now - v->planned_at).count() <
                                           parameters_.backward_path_update_duration;
    if (latched || throttled) {
      // Objects only: the same path under the new request id, segment index kept.
      ++v->sequence;
      v->objects = request.objects;
      v->safety->update_objects(std::move(request.objects));
      v->path->request_id = request.request_id;
      v->published.request_id = request.request_id;
      v->published.stamp_ns = now_ns();
      v->tracker.adopt(request.request_id);
      v->status.request_id = request.request_id;
      v->status.stamp_ns = now_ns();
      spdlog::info("vehicle '{}' request {}: objects updated on the {} path", request.vehicle_id, request.request_id,
                   latched ? "latched" : "current");
      outbox_.publish_path(v->published);
      outbox_.publish_status(v->status);
      return std::nullopt;
    }
  }
  // A re-plan before departure for the same goal keeps the turn signal's start (below), so that
  // periodic re-plans do not restart prepare_time_before_start.
  const bool same_situation = has_path(v->status.state) && !v->status.departed && same_goal(v->goal, request.goal_pose);
  v->signal_carry = same_situation
                        ? std::make_optional(std::make_pair(v->status.turn_signal, v->status.turn_signal_start_ns))
                        : std::nullopt;
  supersede(*v);
  v->goal = request.goal_pose;
  v->planned_at = now;
  v->lanes = request.lanes;
  v->objects = request.objects;
  v->cancel = std::make_shared<std::atomic<bool>>(false);
  v->status = status_for(request.vehicle_id, request.request_id, ExecutionState::kPlanning);
  outbox_.publish_status(v->status);

  PlanningJob job;
  job.sequence = v->sequence;
  job.cancel = v->cancel;
  job.accepted_at = std::chrono::steady_clock::now();
  job.request = std::move(request);
  return job;
}

void VehicleRegistry::reject(const std::string& vehicle_id, std::uint64_t request_id,
                             const std::vector<RequestIssue>& issues) {
  auto v = find_or_add(vehicle_id);
  std::lock_guard<std::mutex> lock(v->mutex);
  supersede(*v);
  PullOutStatus status = status_for(vehicle_id, request_id, ExecutionState::kRejected);
  status.error = format_issues(issues);
  publish_result(*v, empty_path(vehicle_id, request_id, issue_lines(issues)), std::move(status));
}

bool VehicleRegistry::complete(const PlanningJob& job, const PlanningResult& result) {
  const PullOutRequest& request = job.request;
  auto v = find(request.vehicle_id);
  if (!v) return false;
  std::lock_guard<std::mutex> lock(v->mutex);
  if (v->sequence != job.sequence) return false;
  v->cancel.reset();

  PullOutStatus status = status_for(request.vehicle_id, request.request_id, ExecutionState::kNoPath);
  status.evaluation_table = result.evaluation_table;
  status.planning_time_ms = result.planning_time_ms;

  PullOutPath path;
  switch (result.outcome) {
    case PlanningResult::Outcome::kFound:
      path = result.path;
      path.found = true;
      status.state = ExecutionState::kWaitingApproval;
      status.stop_reason = "waiting approval";
      status.current_path_idx = 0;
      status.turn_signal = path.turn_signal;
      if (v->signal_carry && v->signal_carry->first == path.turn_signal) {
        status.turn_signal_start_ns = v->signal_carry->second;
      }
      break;
    case PlanningResult::Outcome::kNoPath:
      path = result.path;
      path.found = false;
      status.state = ExecutionState::kNoPath;
      status.stop_reason = result.stop_reason;
      if (status.stop_reason.empty()) {
        status.stop_reason = result.timed_out ? "planning deadline expired" : "no path found";
      }
      break;
    case PlanningResult::Outcome::kRejected:
      path = empty_path(request.vehicle_id, request.request_id, issue_lines(result.issues));
      status.state = ExecutionState::kRejected;
      status.error = format_issues(result.issues);
      break;
  }
  // The reply belongs to this request whatever the core filled in.
  path.vehicle_id = request.vehicle_id;
  path.request_id = request.request_id;
  status.planner_type = path.planner_type;
  status.segment_count = static_cast<std::uint32_t>(path.partial_paths.size());

  v->tracker.clear();
  v->path.reset();
  v->safety.reset();
  v->stop_inserted = false;
  if (status.state == ExecutionState::kWaitingApproval) {
    v->tracker.start(path);
    v->path = path;
    v->published = path;
    v->safety.emplace(parameters_, vehicle_, v->lanes, v->objects, path);
  }
  publish_result(*v, path, std::move(status));
  return true;
}

void VehicleRegistry::fail(const PlanningJob& job, const std::string& what) {
  const PullOutRequest& request = job.request;
  auto v = find(request.vehicle_id);
  if (!v) return;
  std::lock_guard<std::mutex> lock(v->mutex);
  if (v->sequence != job.sequence) return;
  v->cancel.reset();
  v->tracker.clear();
  const std::string reason = "internal error: " + what;
  PullOutStatus status = status_for(request.vehicle_id, request.request_id, ExecutionState::kNoPath);
  status.stop_reason = reason;
  publish_result(*v, empty_path(request.vehicle_id, request.request_id, {reason}), std::move(status));
}

void VehicleRegistry::publish_result(Vehicle& v, const PullOutPath& path, PullOutStatus status) {
  if (!outbox_.publish_path(path) && has_path(status.state)) {
    v.tracker.clear();
    v.path.reset();
    v.safety.reset();
    status.state = ExecutionState::kNoPath;
    status.stop_reason = "internal error: the path could not be published";
  }
  v.status = std::move(status);
  outbox_.publish_status(v.status);
}

void VehicleRegistry::on_progress(const ExecutionProgress& progress) {
  auto v = find(progress.vehicle_id);
  if (!v) {
    spdlog::debug("progress of unknown vehicle '{}' ignored", progress.vehicle_id);
    return;
  }
  std::lock_guard<std::mutex> lock(v->mutex);
  if (!has_path(v->status.state) || v->status.state == ExecutionState::kCompleted || !v->tracker.active() ||
      v->tracker.request_id() != progress.request_id) {
    spdlog::debug("progress of vehicle '{}' for request {} ignored (state {}, request {})", progress.vehicle_id,
                  progress.request_id, to_string(v->status.state), v->status.request_id);
    return;
  }
  if (!apply_departure_rules(*v, progress)) return;
  v->status.stamp_ns = now_ns();
  spdlog::info("vehicle '{}' request {}: {} segment {}/{}{}{}", progress.vehicle_id, progress.request_id,
               to_string(v->status.state), v->status.current_path_idx + 1, v->status.segment_count,
               v->status.stop_reason.empty() ? "" : ": ", v->status.stop_reason);
  outbox_.publish_status(v->status);
}

bool VehicleRegistry::apply_departure_rules(Vehicle& v, const ExecutionProgress& progress) {
  const PullOutStatus before = v.status;
  PullOutStatus& s = v.status;
  const ExecutionTracker::Update update = v.tracker.on_progress(progress);
  s.current_path_idx = update.current_path_idx;
  if (update.completed) {
    s.state = ExecutionState::kCompleted;
    s.stop_reason.clear();
    return true;
  }
  const SafetyVerdict verdict =
      v.safety ? v.safety->evaluate(progress.pose, progress.velocity_mps, s.current_path_idx, s.departed)
               : SafetyVerdict{};
  s.safe = verdict.safe;
  s.unsafe_object_id = verdict.safe ? 0 : verdict.object_id;

  if (!s.departed) {
    if (!progress.approved) {
      s.state = ExecutionState::kWaitingApproval;
      s.stop_reason = "waiting approval";
    } else {
      if (s.turn_signal_start_ns == 0) s.turn_signal_start_ns = progress.stamp_ns;
      const double signal_on_s = static_cast<double>(progress.stamp_ns - s.turn_signal_start_ns) * 1e-9;
      if (signal_on_s < parameters_.prepare_time_before_start) {
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
  } else if (v.stop_inserted) {
    const bool stopped = std::abs(progress.velocity_mps) < parameters_.th_stopped_velocity;
    if (verdict.safe && progress.approved && stopped) {
      v.stop_inserted = false;
      v.published = *v.path;
      v.published.stamp_ns = now_ns();
      outbox_.publish_path(v.published);
      s.state = ExecutionState::kExecuting;
      s.stop_reason.clear();
    } else {
      s.state = ExecutionState::kWaitingSafety;
      s.stop_reason = !verdict.safe        ? verdict.reason
                      : !progress.approved ? std::string("waiting approval")
                                           : std::string("stopping before resuming");
    }
  } else if (!verdict.safe || !progress.approved) {
    v.stop_inserted = true;
    v.published = insert_feasible_stop(*v.path, s.current_path_idx, progress.pose, progress.velocity_mps,
                                       parameters_.stop_condition);
    v.published.stamp_ns = now_ns();
    outbox_.publish_path(v.published);
    s.state = ExecutionState::kWaitingSafety;
    s.stop_reason = verdict.safe ? std::string("approval withdrawn") : verdict.reason;
  }
  return !same_status(before, s);
}

void VehicleRegistry::cancel_all() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, v] : vehicles_) {
    std::lock_guard<std::mutex> vehicle_lock(v->mutex);
    if (v->cancel) v->cancel->store(true);
  }
}

}  // namespace pullout::service
