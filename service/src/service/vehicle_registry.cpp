#include "service/vehicle_registry.hpp"

#include <utility>

#include <spdlog/spdlog.h>

#include "pullout/model/names.hpp"

namespace pullout::service {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

namespace {

double seconds(VehicleSession::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// The outcome class of a status for on_reply: -1 none yet (idle, planning).
int outcome_class(ExecutionState s) {
  if (s == ExecutionState::kRejected) return 0;
  if (s == ExecutionState::kNoPath) return 1;
  if (has_path(s)) return 2;
  return -1;
}

// Driving a path: the vehicle may be moving on what the session checks.
bool driving(const PullOutStatus& s) { return s.departed && s.state != ExecutionState::kCompleted; }

}  // namespace

const char* to_string(EvictionReason reason) {
  switch (reason) {
    case EvictionReason::kGone:
      return "its request and progress writers are gone";
    case EvictionReason::kIdle:
      return "idle timeout";
    case EvictionReason::kCapacity:
      return "room for a new vehicle (service.max_vehicles)";
  }
  return "?";
}

VehicleRegistry::VehicleRegistry(const StartPlanner& planner, Outbox& outbox, RegistryOptions options)
    : planner_(planner), outbox_(outbox), options_(std::move(options)) {
  if (!options_.clock) options_.clock = [] { return Clock::now(); };
  if (options_.max_vehicles < 1) options_.max_vehicles = 1;
}

std::size_t VehicleRegistry::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return vehicles_.size();
}

bool VehicleRegistry::holds(const std::string& vehicle_id) const { return find(vehicle_id) != nullptr; }

std::shared_ptr<VehicleRegistry::Slot> VehicleRegistry::find(const std::string& vehicle_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = vehicles_.find(vehicle_id);
  return it == vehicles_.end() ? nullptr : it->second;
}

std::optional<EvictionReason> VehicleRegistry::eviction_reason(const Slot& slot, Clock::time_point now,
                                                               bool for_capacity) const {
  const VehicleSession& session = slot.session;
  if (session.pending_search() != 0) return std::nullopt;
  const bool gone = !slot.request_alive && !slot.progress_alive;
  const double timeout = options_.session_idle_timeout_s;
  const bool timed_out = timeout > 0.0 && seconds(now - session.last_input()) >= timeout;
  if (driving(session.status())) {
    // Never while the vehicle may be driving and reporting: only when it is gone and silent.
    if (gone && timed_out) return EvictionReason::kGone;
    return std::nullopt;
  }
  if (gone) return EvictionReason::kGone;
  if (timed_out) return EvictionReason::kIdle;
  if (for_capacity) return EvictionReason::kCapacity;
  return std::nullopt;
}

std::shared_ptr<VehicleRegistry::Slot> VehicleRegistry::find_or_admit(const std::string& vehicle_id,
                                                                      Clock::time_point now) {
  std::shared_ptr<Slot> victim;
  std::string victim_id;
  EvictionReason reason = EvictionReason::kCapacity;
  std::shared_ptr<Slot> slot;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = vehicles_.find(vehicle_id);
    if (it != vehicles_.end()) return it->second;
    if (vehicles_.size() >= options_.max_vehicles) {
      // The least recently active idle session, one whose vehicle is gone first. A session whose
      // lock is taken is busy (a worker publishes for it): not a candidate. O(max_vehicles), only
      // when full.
      Clock::time_point best_input{};
      bool best_gone = false;
      for (const auto& [id, candidate] : vehicles_) {
        std::unique_lock<std::mutex> candidate_lock(candidate->mutex, std::try_to_lock);
        if (!candidate_lock.owns_lock()) continue;
        const auto why = eviction_reason(*candidate, now, true);
        if (!why) continue;
        const bool gone = *why == EvictionReason::kGone;
        const Clock::time_point input = candidate->session.last_input();
        if (!victim || (gone && !best_gone) || (gone == best_gone && input < best_input)) {
          victim = candidate;
          victim_id = id;
          reason = *why;
          best_input = input;
          best_gone = gone;
        }
      }
      if (!victim) return nullptr;
      {
        std::lock_guard<std::mutex> victim_lock(victim->mutex);
        // Still idle (only the dispatcher makes a session busy, and it is here), now out of service.
        victim->evicted = true;
      }
      vehicles_.erase(victim_id);
    }
    slot = std::make_shared<Slot>(vehicle_id, planner_, options_.session);
    vehicles_.emplace(vehicle_id, slot);
  }
  if (victim) forget(*victim, victim_id, reason, now);
  return slot;
}

void VehicleRegistry::forget(Slot& slot, const std::string& vehicle_id, EvictionReason reason, Clock::time_point now) {
  PullOutStatus last;
  Clock::time_point last_input;
  {
    std::lock_guard<std::mutex> lock(slot.mutex);
    last = slot.session.status();
    last_input = slot.session.last_input();
  }
  {
    // After any sample of this vehicle still being written (a result handed over to the publish
    // lock just before the eviction): an unregister before it would be undone by the write.
    std::lock_guard<std::mutex> publishing(slot.publish_mutex);
    outbox_.forget_vehicle(vehicle_id);
  }
  {
    std::lock_guard<std::mutex> lock(fleet_mutex_);
    fleet_.remove(vehicle_id);
  }
  evicted_count_.fetch_add(1);
  if (options_.on_evicted) options_.on_evicted(static_cast<int>(reason));
  spdlog::info("vehicle '{}' evicted: {}; idle {:.1f} s, last request {} in state {}", vehicle_id, to_string(reason),
               seconds(now - last_input), last.request_id, pullout::to_string(last.state));
}

void VehicleRegistry::reject_full(const PullOutRequest& request) {
  const std::string reason = "service.max_vehicles: the service holds " + std::to_string(options_.max_vehicles) +
                             " vehicle sessions and none is idle (planning or driving); request not served, send it "
                             "again later";
  PullOutPath path;
  path.vehicle_id = request.vehicle_id;
  path.request_id = request.request_id;
  path.found = false;
  path.reasons = {reason};
  path.stamp_ns = now_ns();
  PullOutStatus status;
  status.vehicle_id = request.vehicle_id;
  status.request_id = request.request_id;
  status.state = ExecutionState::kRejected;
  status.error = reason;
  status.stamp_ns = now_ns();
  // Counted before it is written: whoever has received the reply finds it in the metrics.
  rejected_full_count_.fetch_add(1);
  if (options_.on_reply) options_.on_reply(status);
  outbox_.publish_path(path);
  outbox_.publish_status(status);
  // Written at once (synchronous publication); the instances must not stay for a vehicle that has
  // no session.
  outbox_.forget_vehicle(request.vehicle_id);
  // One line per second at most: a flood of new ids must not flood the log.
  const auto now = Clock::now();
  ++full_since_log_;
  if (now - last_full_log_ >= std::chrono::seconds(1)) {
    spdlog::warn("vehicle '{}' request {} rejected: {} ({} such rejection(s) since the last line)", request.vehicle_id,
                 request.request_id, reason, full_since_log_);
    last_full_log_ = now;
    full_since_log_ = 0;
  }
}

void VehicleRegistry::refresh_fleet(const Slot& slot, const std::string& vehicle_id) {
  std::optional<ExecutingPath> executing = slot.evicted ? std::nullopt : slot.session.executing();
  std::lock_guard<std::mutex> lock(fleet_mutex_);
  if (executing) {
    fleet_.update(std::move(*executing));
  } else {
    fleet_.remove(vehicle_id);
  }
}

void VehicleRegistry::add_fleet_objects(PlanningJob& job) {
  std::vector<FleetObstacle> others;
  {
    std::lock_guard<std::mutex> lock(fleet_mutex_);
    if (fleet_.size() == 0) return;
    others = fleet_.obstacles_for(job.request.vehicle_id, job.request.ego_pose, options_.fleet_radius_m);
  }
  // Within the request limit: the request was validated with its own objects.
  for (FleetObstacle& other : others) {
    if (job.request.objects.size() >= planner_.limits().max_objects) break;
    job.request.objects.push_back(std::move(other.object));
  }
}

std::optional<PlanningJob> VehicleRegistry::settle(Slot& slot, std::unique_lock<std::mutex>& lock,
                                                   SessionEffects effects, const std::string& vehicle_id) {
  refresh_fleet(slot, vehicle_id);
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
    job->previous_world = std::move(effects.search->previous_world);
  }
  if (!effects.note.empty()) spdlog::debug("vehicle '{}': {}", vehicle_id, effects.note);
  if (!effects.path && !effects.status) return job;
  // Whatever is written now is newer than a `planning` status kept back: it must never follow.
  slot.held_planning.reset();

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
    // Counted before it is written: whoever has received the reply finds it in the metrics.
    const int outcome = outcome_class(effects.status->state);
    if (options_.on_reply && outcome >= 0 &&
        (effects.status->request_id != slot.replied_request_id || outcome != slot.replied_outcome)) {
      slot.replied_request_id = effects.status->request_id;
      slot.replied_outcome = outcome;
      options_.on_reply(*effects.status);
    }
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
                                                       const std::vector<RequestIssue>& conversion_issues,
                                                       bool hold_planning) {
  const std::string vehicle_id = request.vehicle_id;
  const std::uint64_t request_id = request.request_id;
  const auto now = options_.clock();
  const auto slot = find_or_admit(vehicle_id, now);
  if (!slot) {
    reject_full(request);
    return std::nullopt;
  }
  std::unique_lock<std::mutex> lock(slot->mutex);
  if (slot->evicted) return std::nullopt;  // not for the dispatcher's own slot; defensive
  slot->request_alive = true;
  SessionEffects effects = slot->session.on_request(std::move(request), conversion_issues, now);
  if (effects.status && effects.status->state == ExecutionState::kRejected) {
    spdlog::warn("vehicle '{}' request {}: {}", vehicle_id, request_id, effects.note);
    effects.note.clear();
  } else if (!effects.note.empty()) {
    spdlog::info("vehicle '{}' request {}: {}", vehicle_id, request_id, effects.note);
    effects.note.clear();
  }
  std::optional<PullOutStatus> held;
  if (hold_planning && effects.search && !effects.path && effects.status &&
      effects.status->state == ExecutionState::kPlanning) {
    held = std::move(effects.status);
    effects.status.reset();
  }
  std::optional<PlanningJob> job = settle(*slot, lock, std::move(effects), vehicle_id);
  if (held && job) {
    // Still under the slot's lock: settle wrote nothing, so it kept the lock.
    slot->held_planning = std::move(held);
    slot->held_sequence = job->sequence;
  }
  if (job) add_fleet_objects(*job);
  return job;
}

void VehicleRegistry::release_planning(const PlanningJob& job) {
  const auto slot = find(job.request.vehicle_id);
  if (!slot) return;
  std::unique_lock<std::mutex> lock(slot->mutex);
  if (slot->evicted || !slot->held_planning || slot->held_sequence != job.sequence) return;
  SessionEffects effects;
  effects.status = std::move(slot->held_planning);
  slot->held_planning.reset();
  settle(*slot, lock, std::move(effects), job.request.vehicle_id);
}

void VehicleRegistry::on_result(const PlanningJob& job, const PlanningResult& result) {
  const auto slot = find(job.request.vehicle_id);
  if (!slot) return;
  std::unique_lock<std::mutex> lock(slot->mutex);
  if (slot->evicted) return;
  SessionEffects effects = slot->session.on_result(job.sequence, result, options_.clock());
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
  if (slot->evicted) return;
  settle(*slot, lock, slot->session.on_search_failed(job.sequence, what, options_.clock()), job.request.vehicle_id);
}

void VehicleRegistry::on_progress(const ExecutionProgress& progress) {
  const auto slot = find(progress.vehicle_id);
  if (!slot) {
    spdlog::debug("progress of unknown vehicle '{}' ignored", progress.vehicle_id);
    return;
  }
  std::unique_lock<std::mutex> lock(slot->mutex);
  if (slot->evicted) return;
  slot->progress_alive = true;
  std::vector<FleetObstacle> fleet;
  {
    std::lock_guard<std::mutex> fleet_lock(fleet_mutex_);
    if (fleet_.size() > 0) fleet = fleet_.obstacles_for(progress.vehicle_id, progress.pose, options_.fleet_radius_m);
  }
  SessionEffects effects = slot->session.on_progress(progress, options_.clock(), fleet);
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
  const auto now = options_.clock();
  std::vector<std::pair<std::size_t, EvictionReason>> evict;  // index into slots
  for (std::size_t i = 0; i < slots.size(); ++i) {
    auto& [id, slot] = slots[i];
    std::unique_lock<std::mutex> lock(slot->mutex);
    if (slot->evicted) continue;
    SessionEffects effects = slot->session.on_time(now);
    if (effects.status)
      spdlog::warn("vehicle '{}' request {}: {}", id, effects.status->request_id, effects.status->stop_reason);
    if (!effects.empty()) {
      settle(*slot, lock, std::move(effects), id);
      continue;  // it just published: not now
    }
    if (evict.size() >= kMaxEvictionsPerSweep) continue;
    if (const auto why = eviction_reason(*slot, now, false)) {
      slot->evicted = true;
      evict.emplace_back(i, *why);
    }
  }
  if (evict.empty()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [i, why] : evict) {
      const auto it = vehicles_.find(slots[i].first);
      if (it != vehicles_.end() && it->second == slots[i].second) vehicles_.erase(it);
    }
  }
  for (const auto& [i, why] : evict) forget(*slots[i].second, slots[i].first, why, now);
}

std::optional<PlanningJob> VehicleRegistry::restore(const SessionSnapshot& snapshot,
                                                    std::shared_ptr<const PlannedWorld> world) {
  const std::string& vehicle_id = snapshot.status.vehicle_id;
  release(vehicle_id);  // a fresh session: nothing of an earlier one carries over
  const auto now = options_.clock();
  const auto slot = find_or_admit(vehicle_id, now);
  if (!slot) {
    spdlog::error("vehicle '{}' not restored: service.max_vehicles sessions are held and none is idle", vehicle_id);
    return std::nullopt;
  }
  std::unique_lock<std::mutex> lock(slot->mutex);
  if (slot->evicted) return std::nullopt;
  // Alive until its readers say otherwise: a vehicle that never comes back goes by the idle timeout.
  slot->request_alive = true;
  slot->progress_alive = true;
  SessionEffects effects = slot->session.restore(snapshot, world, now);
  spdlog::info("vehicle '{}' request {}: {}", vehicle_id, snapshot.status.request_id,
               effects.note.empty() ? std::string("restored in state ") + pullout::to_string(snapshot.status.state)
                                    : effects.note);
  effects.note.clear();
  return settle(*slot, lock, std::move(effects), vehicle_id);
}

bool VehicleRegistry::release(const std::string& vehicle_id) {
  std::shared_ptr<Slot> slot;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = vehicles_.find(vehicle_id);
    if (it == vehicles_.end()) return false;
    slot = it->second;
    vehicles_.erase(it);
  }
  std::lock_guard<std::mutex> lock(slot->mutex);
  slot->evicted = true;
  if (slot->cancel) slot->cancel->store(true);
  return true;
}

void VehicleRegistry::on_instance_gone(const std::string& vehicle_id, VehicleInput input) {
  const auto slot = find(vehicle_id);
  if (!slot) return;
  std::lock_guard<std::mutex> lock(slot->mutex);
  (input == VehicleInput::kRequest ? slot->request_alive : slot->progress_alive) = false;
}

void VehicleRegistry::cancel_all() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, slot] : vehicles_) {
    std::lock_guard<std::mutex> vehicle_lock(slot->mutex);
    if (slot->cancel) slot->cancel->store(true);
  }
}

}  // namespace pullout::service
