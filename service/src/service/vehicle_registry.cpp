#include "service/vehicle_registry.hpp"

#include <utility>

#include <spdlog/spdlog.h>

#include "pullout/model/names.hpp"

namespace pullout::service {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

VehicleRegistry::VehicleRegistry(const StartPlanner& planner, Outbox& outbox, SessionOptions options)
    : planner_(planner), outbox_(outbox), options_(options) {}

std::shared_ptr<VehicleRegistry::Slot> VehicleRegistry::find(const std::string& vehicle_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = vehicles_.find(vehicle_id);
  return it == vehicles_.end() ? nullptr : it->second;
}

std::shared_ptr<VehicleRegistry::Slot> VehicleRegistry::find_or_add(const std::string& vehicle_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& slot = vehicles_[vehicle_id];
  if (!slot) slot = std::make_shared<Slot>(vehicle_id, planner_, options_);
  return slot;
}

std::optional<PlanningJob> VehicleRegistry::settle(Slot& slot, std::unique_lock<std::mutex>& lock,
                                                   SessionEffects effects, const std::string& vehicle_id) {
  std::optional<PlanningJob> job;
  if (effects.cancel_search && slot.cancel) {
    slot.cancel->store(true);
    slot.cancel.reset();
  }
  if (effects.search) {
    slot.cancel = std::make_shared<std::atomic<bool>>(false);
    job.emplace();
    job->sequence = effects.search->sequence;
    job->cancel = slot.cancel;
    job->accepted_at = Clock::now();
    job->request = std::move(effects.search->request);
  }
  if (!effects.note.empty()) spdlog::debug("vehicle '{}': {}", vehicle_id, effects.note);
  if (!effects.path && !effects.status) return job;

  // Hand over: the next input of this vehicle may be worked on while these samples are written,
  // but its samples wait for these.
  std::unique_lock<std::mutex> publishing(slot.publish_mutex);
  lock.unlock();
  bool undeliverable = false;
  std::uint64_t request_id = 0;
  if (effects.path) {
    effects.path->stamp_ns = now_ns();
    request_id = effects.path->request_id;
    undeliverable = !outbox_.publish_path(*effects.path) && effects.path->found && effects.status &&
                    has_path(effects.status->state);
  }
  if (effects.status && !undeliverable) {
    effects.status->stamp_ns = now_ns();
    outbox_.publish_status(*effects.status);
  }
  publishing.unlock();
  if (undeliverable) {
    spdlog::error("vehicle '{}' request {}: the path could not be published", vehicle_id, request_id);
    lock.lock();
    settle(slot, lock, slot.session.on_path_undeliverable(request_id), vehicle_id);
  }
  return job;
}

std::optional<PlanningJob> VehicleRegistry::on_request(PullOutRequest request,
                                                       const std::vector<RequestIssue>& conversion_issues) {
  const std::string vehicle_id = request.vehicle_id;
  const std::uint64_t request_id = request.request_id;
  const auto slot = find_or_add(vehicle_id);
  std::unique_lock<std::mutex> lock(slot->mutex);
  SessionEffects effects = slot->session.on_request(std::move(request), conversion_issues, Clock::now());
  if (effects.status && effects.status->state == ExecutionState::kRejected) {
    spdlog::warn("vehicle '{}' request {}: {}", vehicle_id, request_id, effects.note);
    effects.note.clear();
  } else if (!effects.note.empty()) {
    spdlog::info("vehicle '{}' request {}: {}", vehicle_id, request_id, effects.note);
    effects.note.clear();
  }
  return settle(*slot, lock, std::move(effects), vehicle_id);
}

void VehicleRegistry::on_result(const PlanningJob& job, const PlanningResult& result) {
  const auto slot = find(job.request.vehicle_id);
  if (!slot) return;
  std::unique_lock<std::mutex> lock(slot->mutex);
  SessionEffects effects = slot->session.on_result(job.sequence, result, Clock::now());
  if (effects.empty()) {
    spdlog::debug("vehicle '{}' request {}: result dropped, a newer request arrived", job.request.vehicle_id,
                  job.request.request_id);
    return;
  }
  if (job.cancel && slot->cancel == job.cancel) slot->cancel.reset();
  settle(*slot, lock, std::move(effects), job.request.vehicle_id);
}

void VehicleRegistry::on_search_failed(const PlanningJob& job, const std::string& what) {
  const auto slot = find(job.request.vehicle_id);
  if (!slot) return;
  std::unique_lock<std::mutex> lock(slot->mutex);
  settle(*slot, lock, slot->session.on_search_failed(job.sequence, what, Clock::now()), job.request.vehicle_id);
}

void VehicleRegistry::on_progress(const ExecutionProgress& progress) {
  const auto slot = find(progress.vehicle_id);
  if (!slot) {
    spdlog::debug("progress of unknown vehicle '{}' ignored", progress.vehicle_id);
    return;
  }
  std::unique_lock<std::mutex> lock(slot->mutex);
  SessionEffects effects = slot->session.on_progress(progress, Clock::now());
  if (effects.status) {
    const PullOutStatus& s = *effects.status;
    spdlog::info("vehicle '{}' request {}: {} segment {}/{}{}{}", progress.vehicle_id, s.request_id, to_string(s.state),
                 s.current_path_idx + 1, s.segment_count, s.stop_reason.empty() ? "" : ": ", s.stop_reason);
  }
  settle(*slot, lock, std::move(effects), progress.vehicle_id);
}

void VehicleRegistry::on_time() {
  std::vector<std::pair<std::string, std::shared_ptr<Slot>>> slots;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    slots.assign(vehicles_.begin(), vehicles_.end());
  }
  const auto now = Clock::now();
  for (auto& [id, slot] : slots) {
    std::unique_lock<std::mutex> lock(slot->mutex);
    SessionEffects effects = slot->session.on_time(now);
    if (effects.status)
      spdlog::warn("vehicle '{}' request {}: {}", id, effects.status->request_id, effects.status->stop_reason);
    settle(*slot, lock, std::move(effects), id);
  }
}

void VehicleRegistry::cancel_all() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, slot] : vehicles_) {
    std::lock_guard<std::mutex> vehicle_lock(slot->mutex);
    if (slot->cancel) slot->cancel->store(true);
  }
}

}  // namespace pullout::service
