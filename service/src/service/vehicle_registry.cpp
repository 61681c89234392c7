#include "service/vehicle_registry.hpp"

#include <chrono>
#include <utility>

#include <spdlog/spdlog.h>

#include "pullout/model/names.hpp"

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

}  // namespace

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

VehicleRegistry::VehicleRegistry(const StartPlannerParameters& parameters, Outbox& outbox)
    : parameters_(parameters), outbox_(outbox) {}

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
}

PlanningJob VehicleRegistry::accept(PullOutRequest request) {
  auto v = find_or_add(request.vehicle_id);
  std::lock_guard<std::mutex> lock(v->mutex);
  supersede(*v);
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
      status.state = ExecutionState::kExecuting;
      status.current_path_idx = 0;
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
  if (status.state == ExecutionState::kExecuting) v->tracker.start(path);
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
  if (!outbox_.publish_path(path) && status.state == ExecutionState::kExecuting) {
    v.tracker.clear();
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
  if (v->status.state != ExecutionState::kExecuting || !v->tracker.active() ||
      v->tracker.request_id() != progress.request_id) {
    spdlog::debug("progress of vehicle '{}' for request {} ignored (state {}, request {})", progress.vehicle_id,
                  progress.request_id, to_string(v->status.state), v->status.request_id);
    return;
  }
  const ExecutionTracker::Update update = v->tracker.on_progress(progress);
  if (!update.changed) return;
  v->status.current_path_idx = update.current_path_idx;
  if (update.completed) v->status.state = ExecutionState::kCompleted;
  v->status.stamp_ns = now_ns();
  spdlog::info("vehicle '{}' request {}: {} segment {}/{}", progress.vehicle_id, progress.request_id,
               to_string(v->status.state), v->status.current_path_idx + 1, v->status.segment_count);
  outbox_.publish_status(v->status);
}

void VehicleRegistry::cancel_all() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, v] : vehicles_) {
    std::lock_guard<std::mutex> vehicle_lock(v->mutex);
    if (v->cancel) v->cancel->store(true);
  }
}

}  // namespace pullout::service
