#include "service/pullout_service.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <exception>
#include <iterator>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>
#include <fastdds/dds/core/condition/StatusCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "pullout/idl/convert.hpp"
#include "pullout/model/names.hpp"
#include "pullout/model/types.hpp"
#include "pullout/version.hpp"

namespace pullout::service {
namespace dds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;

namespace {

// The dispatcher also wakes this often without any event, so that a missed wake-up (which should
// not happen) costs at most this much latency rather than a stuck vehicle.
// It is also the period of the sessions' on_time (the odometry watchdog).
const eprosima::fastrtps::Duration_t kDispatcherWakePeriod{0, 250'000'000};
constexpr auto kSessionTimePeriod = std::chrono::milliseconds(250);
constexpr auto kProgressWarnInterval = std::chrono::seconds(5);

const char* outcome_name(PlanningResult::Outcome o) {
  switch (o) {
    case PlanningResult::Outcome::kFound:
      return "found";
    case PlanningResult::Outcome::kNoPath:
      return "no path";
    case PlanningResult::Outcome::kRejected:
      return "rejected";
  }
  return "?";
}

// [ms] A request that waited longer than this in the reader is handed to a planning thread, not
// tried on the dispatcher (quick_answer_on_dispatcher): the dispatcher is behind (a burst, or a
// machine short of CPU).
constexpr double kDispatcherMaxWaitMs = 5.0;

// [ms] How long ago Fast DDS received the sample (both stamps on this host's system clock); 0 when
// the stamp is missing or in the future.
double waited_in_reader_ms(const dds::SampleInfo& info) {
  const eprosima::fastrtps::rtps::Time_t& r = info.reception_timestamp;
  const double received_ms = static_cast<double>(r.seconds()) * 1e3 + static_cast<double>(r.nanosec()) / 1e6;
  const double now_ms =
      std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
  return received_ms > 0.0 && now_ms > received_ms ? now_ms - received_ms : 0.0;
}

// A job whose `planning` status is held back and that waited longer than this many quick budgets
// (service.quick_answer_ms) for a planning thread gets the status at once (a long queue).
constexpr double kHeldPlanningMaxWaitFactor = 10.0;

// [ms] CPU time of the calling thread.
double thread_cpu_ms() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) / 1e6;
}

RegistryOptions registry_options(const ServiceConfig& service, ServiceMetrics* metrics) {
  RegistryOptions o;
  o.session.progress_timeout_s = service.progress_timeout_s;
  o.session.fleet_clearance_m = service.fleet_clearance_m;
  o.session_idle_timeout_s = service.session_idle_timeout_s;
  o.max_vehicles = service.max_vehicles;
  if (metrics != nullptr) {
    o.on_reply = [metrics](const PullOutStatus& status) { metrics->on_reply(status); };
    o.on_evicted = [metrics](int reason) { metrics->on_eviction(static_cast<EvictionReason>(reason)); };
  }
  return o;
}

std::unique_ptr<ServiceMetrics> make_metrics(const Config& config) {
  if (!config.observability.metrics.enabled) return nullptr;
  return std::make_unique<ServiceMetrics>(kVersionString);
}

std::unique_ptr<HttpEndpoint> make_http(const Config& config, const ServiceMetrics* metrics, HealthState& health) {
  if (metrics == nullptr) return nullptr;
  const MetricsConfig& m = config.observability.metrics;
  auto http = std::make_unique<HttpEndpoint>(m.address, m.port, metrics->registry(), health);
  spdlog::info("metrics and health on http://{}:{} (/metrics, /healthz, /readyz)", m.address, http->port());
  return http;
}

std::unique_ptr<StateJournal> make_journal(const Config& config, Outbox& next) {
  if (config.service.state_dir.empty()) return nullptr;
  return std::make_unique<StateJournal>(config.service.state_dir, next);
}

}  // namespace

PulloutService::PulloutService(const Config& config, std::shared_ptr<const LaneletMap> map)
    : config_(config),
      metrics_(make_metrics(config)),
      http_(make_http(config, metrics_.get(), health_)),
      dds_(config.dds, config.service.replica),
      journal_(make_journal(config, dds_)),
      planner_(config.vehicle, config.start_planner, config.service.limits, std::move(map), config.vehicle_profiles),
      registry_(planner_, journal_ ? static_cast<Outbox&>(*journal_) : dds_,
                registry_options(config.service, metrics_.get())) {
  health_.config_loaded = true;  // load_config validated it
  health_.dds_ready = true;      // DdsEdge throws unless the participant and every endpoint exist
  // Every session holds one instance on the path and on the status writer, and a vehicle that is
  // served has one on each reader: a profile with fewer instances than sessions stops answering
  // new vehicles without a word once full.
  const int capacity = dds_.instance_capacity();
  if (capacity > 0 && config.service.max_vehicles > static_cast<std::size_t>(capacity)) {
    throw DdsSetupError("service.max_vehicles = " + std::to_string(config.service.max_vehicles) +
                        " exceeds resource_limits.max_instances = " + std::to_string(capacity) +
                        " of the DDS profiles in " + describe_profiles(config.dds) +
                        ": lower max_vehicles or raise max_instances");
  }
  if (config.service.replica.enabled) {
    shadows_ = std::make_unique<ReplicaShadows>(config.service.max_vehicles);
    health_.in_step = false;  // until sync_with_replicas
  }
  queue_ = std::make_unique<PlanningQueue>(config_.service.worker_threads, [this](PlanningJob& job) { run_job(job); });
  health_.workers_running = true;
}

PulloutService::~PulloutService() { stop(); }

void PulloutService::start() {
  if (dispatcher_.joinable() || stopping_) return;
  if (journal_) restore_from_journal();
  dispatcher_ = std::thread([this] { dispatch_loop(); });
}

void PulloutService::stop() {
  // Exactly one caller joins; concurrent callers wait in call_once until it has finished (two
  // threads joining one std::thread is undefined behaviour).
  std::call_once(stop_once_, [this] {
    health_.workers_running = false;  // /readyz says so while the threads stop
    stopping_ = true;
    shutdown_.set_trigger_value(true);
    if (dispatcher_.joinable()) dispatcher_.join();
    registry_.cancel_all();
    if (queue_) queue_->stop();
    http_.reset();
  });
}

void PulloutService::restore_from_journal() {
  const auto t0 = std::chrono::steady_clock::now();
  JournalLoad loaded = journal_->load(config_.service.session_idle_timeout_s);
  for (const std::string& problem : loaded.problems) spdlog::warn("state journal: {} (ignored)", problem);
  for (JournalEntry& e : loaded.entries) {
    SessionSnapshot snapshot;
    if (e.request) snapshot.request = std::move(*e.request);
    snapshot.path = std::move(e.path);
    snapshot.status = std::move(e.status);
    restore(snapshot, e.request ? e.request_issues : std::vector<RequestIssue>{{"request", "not in the journal"}});
  }
  spdlog::info("state journal {}: {} vehicle(s) restored, {} file(s) ignored in {:.1f} ms", config_.service.state_dir,
               loaded.entries.size(), loaded.problems.size(),
               std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
}

void PulloutService::restore(const SessionSnapshot& snapshot, const std::vector<RequestIssue>& request_issues) {
  std::shared_ptr<const PlannedWorld> world;
  std::vector<RequestIssue> issues = request_issues;
  if (issues.empty()) world = planner_.planned_world(snapshot.request, issues);
  if (!world && has_path(snapshot.status.state)) {
    spdlog::warn("vehicle '{}' request {}: no world for the safety check ({}: {}): the vehicle must send it again",
                 snapshot.status.vehicle_id, snapshot.status.request_id, issues.empty() ? "?" : issues.front().field,
                 issues.empty() ? "?" : issues.front().problem);
  }
  std::optional<PlanningJob> job = registry_.restore(snapshot, std::move(world));
  if (job) queue_->push(std::move(*job));
}

double PulloutService::effective_deadline_ms(double requested_ms) const {
  const double budget = requested_ms > 0.0 ? requested_ms : config_.service.default_deadline_ms;
  return std::min(budget, config_.service.limits.max_deadline_ms);
}

void PulloutService::dispatch_loop() {
  dds::WaitSet waitset;
  dds::StatusCondition& requests = dds_.request_reader().get_statuscondition();
  dds::StatusCondition& progress = dds_.progress_reader().get_statuscondition();
  requests.set_enabled_statuses(dds::StatusMask::data_available());
  progress.set_enabled_statuses(dds::StatusMask::data_available());
  waitset.attach_condition(requests);
  waitset.attach_condition(progress);
  waitset.attach_condition(shutdown_);
  if (dds_.secure()) waitset.attach_condition(dds_.discovery_condition());
  dds::StatusCondition* replica_paths = nullptr;
  dds::StatusCondition* replica_statuses = nullptr;
  if (shadows_) {
    replica_paths = &dds_.replica_path_reader()->get_statuscondition();
    replica_statuses = &dds_.replica_status_reader()->get_statuscondition();
    replica_paths->set_enabled_statuses(dds::StatusMask::data_available());
    replica_statuses->set_enabled_statuses(dds::StatusMask::data_available());
    waitset.attach_condition(*replica_paths);
    waitset.attach_condition(*replica_statuses);
    waitset.attach_condition(dds_.replica_condition());
  }
  spdlog::debug("dispatcher running");
  health_.beat();
  if (shadows_) sync_with_replicas();

  auto last_time_tick = std::chrono::steady_clock::now();
  while (!stopping_) {
    dds::ConditionSeq active;
    const auto rc = waitset.wait(active, kDispatcherWakePeriod);
    if (stopping_) break;
    if (rc != ReturnCode_t::RETCODE_OK && rc != ReturnCode_t::RETCODE_TIMEOUT) {
      spdlog::error("dispatcher: WaitSet::wait failed (code {})", rc());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    health_.beat();
    dds_.prepare_discovered_vehicles();
    // Both readers are drained on every wake-up: cheap when empty, and it cannot miss data.
    // Requests before the takeover: a request for a vehicle of a replica that just left is kept
    // for the takeover (its world), not planned afresh.
    if (shadows_) take_replica_samples();
    take_requests();
    if (shadows_) take_over_departed();
    take_progress();
    const auto now = std::chrono::steady_clock::now();
    if (now - last_time_tick >= kSessionTimePeriod) {
      last_time_tick = now;
      registry_.on_time();
      const std::size_t others = dds_.other_services();
      health_.other_services = static_cast<std::uint32_t>(others);
      if (metrics_) {
        metrics_->set_vehicles(registry_.size());
        metrics_->set_queue_depth(queue_->depth());
        metrics_->set_other_services(others);
      }
      // Bounded like the sessions: entries older than the interval say nothing any more.
      for (auto it = progress_warned_.begin(); it != progress_warned_.end();) {
        it = now - it->second >= kProgressWarnInterval ? progress_warned_.erase(it) : std::next(it);
      }
    }
  }

  // The conditions belong to the readers, which outlive this thread; detach before they go.
  waitset.detach_condition(requests);
  waitset.detach_condition(progress);
  waitset.detach_condition(shutdown_);
  if (dds_.secure()) waitset.detach_condition(dds_.discovery_condition());
  if (shadows_) {
    waitset.detach_condition(*replica_paths);
    waitset.detach_condition(*replica_statuses);
    waitset.detach_condition(dds_.replica_condition());
  }
  spdlog::debug("dispatcher stopped");
}

void PulloutService::take_requests() {
  msg::PullOutRequest sample;
  dds::SampleInfo info;
  dds::DataReader& reader = dds_.request_reader();
  while (!stopping_) {
    try {
      if (reader.take_next_sample(&sample, &info) != ReturnCode_t::RETCODE_OK) return;
      if (info.valid_data) {
        if (!sender_allowed(info, sample.vehicle_id(), "request")) continue;
        request_instances_[info.instance_handle] = sample.vehicle_id();
        if (shadows_ && !serving(sample.vehicle_id())) {
          // Another replica serves it, or served it and left (this one may take it over next):
          // kept for a takeover (decoded and validated then).
          std::vector<RequestIssue> issues;
          PullOutRequest request = idl::from_msg(sample, issues);
          if (issues.empty() && sample.vehicle_id().size() <= kMaxVehicleIdBytes) {
            shadows_->keep_request(request);
            spdlog::debug("vehicle '{}' request {}: kept for a takeover", request.vehicle_id, request.request_id);
          }
          continue;
        }
        handle_request(sample, waited_in_reader_ms(info));
      } else {
        instance_gone(request_instances_, info, VehicleInput::kRequest);
      }
    } catch (const std::exception& e) {
      // One bad sample (say an allocation failure on a huge one) must not take the service down.
      spdlog::error("request dropped: {}", e.what());
    }
  }
}

void PulloutService::take_progress() {
  msg::ExecutionProgress sample;
  dds::SampleInfo info;
  dds::DataReader& reader = dds_.progress_reader();
  while (!stopping_) {
    try {
      if (reader.take_next_sample(&sample, &info) != ReturnCode_t::RETCODE_OK) return;
      if (info.valid_data) {
        if (!sender_allowed(info, sample.vehicle_id(), "progress")) continue;
        progress_instances_[info.instance_handle] = sample.vehicle_id();
        if (shadows_ && !registry_.holds(sample.vehicle_id())) continue;  // another replica's vehicle
        handle_progress(sample);
      } else {
        instance_gone(progress_instances_, info, VehicleInput::kProgress);
      }
    } catch (const std::exception& e) {
      spdlog::error("progress sample dropped: {}", e.what());
    }
  }
}

bool PulloutService::serving(const std::string& vehicle_id) const {
  if (registry_.holds(vehicle_id)) return true;
  const ParticipantId self = dds_.self();
  const std::vector<ParticipantId> others = dds_.replicas();
  return !shadows_->owner_left(vehicle_id, self, others) && shadows_->serves(vehicle_id, self, others);
}

std::size_t PulloutService::take_replica_samples() {
  std::size_t taken = 0;
  const ParticipantId self = dds_.self();
  const auto writer_of = [](const dds::SampleInfo& info) {
    return eprosima::fastrtps::rtps::iHandle2GUID(info.publication_handle).guidPrefix;
  };
  // A vehicle another replica speaks for: shadowed; if this replica serves it too (two replicas
  // decided on different views of who is alive), the one with the smaller GUID prefix yields.
  const auto note_owner = [&](const std::string& vehicle_id, const ParticipantId& writer) -> ReplicaShadows::Shadow* {
    if (writer == self) {
      shadows_->erase(vehicle_id);  // this replica serves it
      return nullptr;
    }
    if (registry_.holds(vehicle_id)) {
      if (writer < self) return nullptr;  // the other one yields
      registry_.release(vehicle_id);
      spdlog::warn("vehicle '{}': another replica serves it too; this one yields", vehicle_id);
    }
    ReplicaShadows::Shadow* shadow = shadows_->at(vehicle_id);
    if (shadow != nullptr) shadow->owner = writer;
    return shadow;
  };
  {
    msg::PullOutPath sample;
    dds::SampleInfo info;
    while (!stopping_ && dds_.replica_path_reader()->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      ++taken;
      if (!info.valid_data) continue;
      if (ReplicaShadows::Shadow* s = note_owner(sample.vehicle_id(), writer_of(info))) s->path = idl::from_msg(sample);
    }
  }
  msg::PullOutStatus sample;
  dds::SampleInfo info;
  while (!stopping_ && dds_.replica_status_reader()->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
    ++taken;
    if (!info.valid_data) {
      // Disposed: the owner evicted the vehicle (not the owner dying: that is no writers).
      const auto it = replica_status_instances_.find(info.instance_handle);
      if (it == replica_status_instances_.end()) continue;
      if (info.instance_state == dds::NOT_ALIVE_DISPOSED_INSTANCE_STATE) shadows_->erase(it->second);
      if (info.instance_state != dds::NOT_ALIVE_NO_WRITERS_INSTANCE_STATE) replica_status_instances_.erase(it);
      continue;
    }
    replica_status_instances_[info.instance_handle] = sample.vehicle_id();
    if (ReplicaShadows::Shadow* s = note_owner(sample.vehicle_id(), writer_of(info))) s->status = idl::from_msg(sample);
  }
  return taken;
}

void PulloutService::sync_with_replicas() {
  // A replica that starts while others serve must know their vehicles before it answers a request:
  // a vehicle whose owner it has not heard of yet would otherwise be planned afresh here too (the
  // rendezvous winner for a vehicle without a known owner). Requests that arrive meanwhile wait in
  // the reader. Bounded: about one lease to discover the other replicas (they announce every
  // quarter of a lease), then at most three more for their writers to match and their history
  // (TRANSIENT_LOCAL paths and statuses) to arrive.
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const auto lease = std::chrono::milliseconds(config_.service.replica.lease_duration_ms);
  const auto poll = std::chrono::milliseconds(10);
  while (!stopping_ && Clock::now() - t0 < lease) {
    std::this_thread::sleep_for(poll);
    health_.beat();
  }
  const auto deadline = t0 + 4 * lease;
  const dds::DataReader* readers[] = {dds_.replica_path_reader(), dds_.replica_status_reader()};
  std::size_t others = 0;
  bool matched = false;
  while (!stopping_) {
    // Every other replica's path and status writer, and this one's own, matched by both readers.
    others = dds_.replicas().size();
    matched = true;
    for (const dds::DataReader* reader : readers) {
      dds::SubscriptionMatchedStatus status;
      reader->get_subscription_matched_status(status);
      matched = matched && static_cast<std::size_t>(status.current_count) >= others + 1;
    }
    if (matched || Clock::now() >= deadline) break;
    std::this_thread::sleep_for(poll);
    health_.beat();
  }
  // Their history (one path and one status per vehicle they serve) follows the match; Fast DDS
  // 2.9 has no wait_for_historical_data (unsupported), so it is taken until none has come for half
  // a lease.
  auto last_sample = Clock::now();
  while (!stopping_ && matched && Clock::now() < deadline && Clock::now() - last_sample < lease / 2) {
    if (take_replica_samples() > 0) last_sample = Clock::now();
    std::this_thread::sleep_for(poll);
    health_.beat();
  }
  const std::size_t vehicles = shadows_->size();
  health_.in_step = true;
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  if (matched) {
    spdlog::info("replica: in step with {} other replica(s) after {:.0f} ms ({} vehicle(s) served by them)", others, ms,
                 vehicles);
  } else {
    spdlog::warn("replica: serving after {:.0f} ms although the writers of the {} other replica(s) did not all match",
                 ms, others);
  }
}

void PulloutService::take_over_departed() {
  for (const ParticipantId& departed : dds_.take_departed_replicas()) {
    const auto t0 = std::chrono::steady_clock::now();
    const ParticipantId self = dds_.self();
    const std::vector<ParticipantId> others = dds_.replicas();
    std::size_t taken = 0;
    const std::vector<std::string> vehicles = shadows_->owned_by(departed);
    for (const std::string& vehicle_id : vehicles) {
      if (!shadows_->serves(vehicle_id, self, others)) continue;  // another replica wins it
      bool request_known = false;
      const std::optional<SessionSnapshot> snapshot = shadows_->snapshot(vehicle_id, request_known);
      shadows_->erase(vehicle_id);
      if (!snapshot) continue;
      restore(*snapshot, request_known ? std::vector<RequestIssue>{}
                                       : std::vector<RequestIssue>{{"request", "not seen by this replica"}});
      if (snapshot->request_is_later) {
        // As if the vehicle sent it now: a departed vehicle's path answers it, segment kept.
        std::optional<PlanningJob> job = registry_.on_request(snapshot->request, {});
        if (job) queue_->push(std::move(*job));
      }
      ++taken;
    }
    spdlog::info("took over {} of the {} vehicle(s) of the replica that left, in {:.1f} ms", taken, vehicles.size(),
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
}

bool PulloutService::sender_allowed(const dds::SampleInfo& info, const std::string& vehicle_id, const char* what) {
  if (dds_.sender_may_act_for(info, vehicle_id)) return true;
  // Refused samples are counted and logged at most once per kProgressWarnInterval: a hostile
  // sender must not flood the log.
  ++refused_samples_;
  const auto now = std::chrono::steady_clock::now();
  if (now - refused_logged_ >= kProgressWarnInterval) {
    refused_logged_ = now;
    spdlog::warn("{} for vehicle '{}' refused: its writer is not in that vehicle's partition ({} refused so far)", what,
                 vehicle_id.substr(0, kMaxVehicleIdBytes), refused_samples_);
  }
  return false;
}

void PulloutService::instance_gone(InstanceNames& names, const dds::SampleInfo& info, VehicleInput input) {
  if (info.instance_state == dds::ALIVE_INSTANCE_STATE) return;
  // An unregister or dispose from another DDS vendor may name the wrong instance (DdsEdge::
  // instance_state_trusted): such a vehicle is evicted when idle for the timeout, or for room.
  if (!dds_.instance_state_trusted(info)) {
    spdlog::debug("{} instance state from a writer of another DDS vendor ignored",
                  input == VehicleInput::kRequest ? kRequestTopic : kProgressTopic);
    return;
  }
  const auto it = names.find(info.instance_handle);
  if (it == names.end()) return;
  // With security, only the vehicle's own writers can end its instances (a dispose written by
  // another vehicle's writer must not make this one look gone).
  if (!dds_.sender_may_act_for(info, it->second)) return;
  spdlog::debug("vehicle '{}': its {} instance is no longer alive", it->second,
                input == VehicleInput::kRequest ? kRequestTopic : kProgressTopic);
  registry_.on_instance_gone(it->second, input);
  names.erase(it);
}

void PulloutService::handle_request(const msg::PullOutRequest& sample, double waited_ms) {
  if (metrics_) metrics_->on_request();
  if (sample.vehicle_id().size() > kMaxVehicleIdBytes) {
    spdlog::warn("request {} dropped: vehicle_id of {} bytes cannot be answered (at most {})", sample.request_id(),
                 sample.vehicle_id().size(), kMaxVehicleIdBytes);
    return;
  }
  if (journal_) journal_->on_request(sample);
  std::vector<RequestIssue> issues;
  PullOutRequest request = idl::from_msg(sample, issues);
  if (!issues.empty()) {
    registry_.on_request(std::move(request), issues);
    return;
  }
  if (!request.route_segments.empty()) {
    spdlog::info("vehicle '{}' request {}: received (route of {} segments, {} objects)", request.vehicle_id,
                 request.request_id, request.route_segments.size(), request.objects.size());
  } else if (request.route_lanelet_ids.empty()) {
    spdlog::info("vehicle '{}' request {}: received ({} lanes, {} objects)", request.vehicle_id, request.request_id,
                 request.lanes.size(), request.objects.size());
  } else {
    spdlog::info("vehicle '{}' request {}: received (route of {} lanelets, {} objects)", request.vehicle_id,
                 request.request_id, request.route_lanelet_ids.size(), request.objects.size());
  }
  // A search that ends within service.quick_answer_ms is answered without a `planning` status
  // first: that status would precede the answer by about a millisecond and costs a DDS write at
  // the service and a sample at the vehicle. The status is held back and written once the quick
  // attempt runs out (quick_attempt). Not in replica mode: there a vehicle's `planning` status
  // is what the other replicas see first.
  const bool quick = config_.service.quick_answer_ms > 0.0 && !shadows_;
  // The attempt on the dispatcher (quick_answer_on_dispatcher) saves the hand-off too, but only
  // while the dispatcher keeps up: a request that waited in the reader is behind others, and on a
  // machine short of CPU three threads get more of it than one (the scheduler is fair per thread).
  const bool here = quick && config_.service.quick_answer_on_dispatcher && waited_ms < kDispatcherMaxWaitMs;
  std::optional<PlanningJob> job = registry_.on_request(std::move(request), {}, quick);
  if (!job) return;  // rejected, or only the objects of the followed path updated
  if (here) {
    if (quick_attempt(*job)) {
      if (metrics_) metrics_->on_search(SearchPlace::kDispatcherQuick);
      return;
    }
    registry_.release_planning(*job);
  } else if (quick) {
    job->planning_held = true;
  }
  const std::string vehicle = job->request.vehicle_id;
  if (queue_->push(std::move(*job))) {
    spdlog::debug("vehicle '{}': a waiting request was replaced by a newer one", vehicle);
  }
}

void PulloutService::handle_progress(const msg::ExecutionProgress& sample) {
  std::vector<RequestIssue> issues;
  ExecutionProgress progress = idl::from_msg(sample, issues);
  if (!issues.empty()) {
    const auto now = std::chrono::steady_clock::now();
    auto [it, first] = progress_warned_.try_emplace(progress.vehicle_id, now);
    if (first || now - it->second >= kProgressWarnInterval) {
      it->second = now;
      spdlog::warn("vehicle '{}' progress ignored: {}: {}", progress.vehicle_id, issues.front().field,
                   issues.front().problem);
    }
    return;
  }
  registry_.on_progress(progress);
}

bool PulloutService::quick_attempt(PlanningJob& job) {
  const double budget_ms = effective_deadline_ms(job.request.deadline_ms);
  const double quick_ms = config_.service.quick_answer_ms;
  const bool whole_budget = budget_ms <= quick_ms;
  StopCondition stop = StopCondition::after_ms(whole_budget ? budget_ms : quick_ms).with_cancel(job.cancel.get());
  PlanningResult result;
  for (int attempt = 0;; ++attempt) {
    const double cpu_before_ms = thread_cpu_ms();
    try {
      result = planner_.plan(job.request, stop, job.previous_world.get());
    } catch (const std::exception&) {
      return false;  // searched again with the whole budget, which reports the failure
    }
    if (stopping_ || job.cancel->load()) return true;  // shutdown or superseded: nothing to publish
    if (whole_budget || result.stopped == StopReason::kNone) break;
    // Cut short by the quick budget (not the request's). When this thread ran for less than
    // half of it, the clock ran out while it waited for a CPU (a busy machine), not because the
    // search is long: once more, rather than the `planning` write and a whole search again. Else
    // the search runs again with the whole budget, from the start (a stopped search keeps nothing).
    if (attempt > 0 || thread_cpu_ms() - cpu_before_ms >= 0.5 * quick_ms) return false;
    stop = StopCondition::after_ms(quick_ms).with_cancel(job.cancel.get());
  }
  finish(job, result, 0.0);
  return true;
}

void PulloutService::run_job(PlanningJob& job) {
  const PullOutRequest& request = job.request;
  if (stopping_ || job.cancel->load()) return;  // superseded or shutting down before it started
  const double budget_ms = effective_deadline_ms(request.deadline_ms);
  const StopCondition stop = StopCondition::after_ms(budget_ms).with_cancel(job.cancel.get());
  const double waited_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - job.accepted_at).count();

  if (job.planning_held) {
    // Its `planning` status was held back for a quick answer. A job that waited for a planning
    // thread longer than kHeldPlanningMaxWaitFactor times that budget writes it at once: the
    // vehicle hears that its request is in work within about that time.
    if (waited_ms < kHeldPlanningMaxWaitFactor * config_.service.quick_answer_ms && quick_attempt(job)) {
      if (metrics_) metrics_->on_search(SearchPlace::kPlanningThreadQuick);
      return;
    }
    if (stopping_ || job.cancel->load()) return;
    registry_.release_planning(job);
  }
  if (metrics_) metrics_->on_search(SearchPlace::kPlanningThread);
  PlanningResult result;
  try {
    result = planner_.plan(request, stop, job.previous_world.get());
  } catch (const std::exception& e) {
    spdlog::error("vehicle '{}' request {}: planner failed: {}", request.vehicle_id, request.request_id, e.what());
    if (!stopping_) registry_.on_search_failed(job, e.what());
    return;
  }
  if (stopping_) return;  // a search cut short by shutdown is not a "no path"
  finish(job, result, waited_ms);
}

void PulloutService::finish(const PlanningJob& job, const PlanningResult& result, double waited_ms) {
  const PullOutRequest& request = job.request;
  registry_.on_result(job, result);
  if (result.outcome == PlanningResult::Outcome::kFound) {
    spdlog::info("vehicle '{}' request {}: {} path, {} segment(s), {:.1f} ms (+{:.1f} ms queued)", request.vehicle_id,
                 request.request_id, to_string(result.path.planner_type), result.path.partial_paths.size(),
                 result.planning_time_ms, waited_ms);
  } else {
    spdlog::info(
        "vehicle '{}' request {}: {}{}, {:.1f} ms: {}", request.vehicle_id, request.request_id,
        outcome_name(result.outcome),
        result.stopped == StopReason::kNone ? ""
        : result.timed_out                  ? " (deadline)"
                                            : " (cancelled)",
        result.planning_time_ms,
        result.outcome == PlanningResult::Outcome::kRejected ? format_issues(result.issues) : result.stop_reason);
    for (const PlannerAttempt& a : result.evaluation_table) {
      spdlog::debug("vehicle '{}' request {}:   {} margin {:.2f} m, backward {:.2f} m: {}", request.vehicle_id,
                    request.request_id, to_string(a.planner), a.margin_m, a.backward_distance_m, describe(a));
    }
  }
}

}  // namespace pullout::service
