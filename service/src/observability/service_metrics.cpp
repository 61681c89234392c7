#include "observability/service_metrics.hpp"

#include <set>
#include <sstream>
#include <vector>

#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

#include "pullout/model/names.hpp"
#include "service/vehicle_registry.hpp"

namespace pullout::service {
namespace {

// [s] From 1 ms (a shift path on a straight road) to the 10-minute cap of a request's deadline.
const prometheus::Histogram::BucketBoundaries kPlanningBuckets{0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1,
                                                               0.2,   0.5,   1.0,   2.0,  5.0,  10.0, 60.0};

bool is_outcome(ExecutionState s) {
  return s == ExecutionState::kRejected || s == ExecutionState::kNoPath || has_path(s);
}

}  // namespace

std::string rejection_field_class(const std::string& line) {
  const auto colon = line.find(": ");
  if (colon == std::string::npos || colon == 0) return {};
  std::string field;
  int depth = 0;
  for (std::size_t i = 0; i < colon; ++i) {
    const char c = line[i];
    if (c == '[') {
      ++depth;
    } else if (c == ']') {
      if (depth > 0) --depth;
    } else if (depth == 0) {
      // Field names are identifiers and dots; anything else is not a field path.
      const bool ok =
          (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.';
      if (!ok) return {};
      field += c;
    }
  }
  return field;
}

ServiceMetrics::ServiceMetrics(const std::string& version) : registry_(std::make_shared<prometheus::Registry>()) {
  prometheus::BuildGauge()
      .Name("pullout_build_info")
      .Help("The pullout_service build (value 1)")
      .Register(*registry_)
      .Add({{"version", version}})
      .Set(1.0);
  requests_ = &prometheus::BuildCounter()
                   .Name("pullout_requests_total")
                   .Help("PullOutRequest samples taken from DDS")
                   .Register(*registry_)
                   .Add({});
  auto& searches = prometheus::BuildCounter()
                       .Name("pullout_searches_total")
                       .Help(
                           "Searches by where they ran: answered within service.quick_answer_ms on the dispatcher or a "
                           "planning thread (no planning status), or with the whole budget after the planning status")
                       .Register(*registry_);
  searches_[static_cast<int>(SearchPlace::kDispatcherQuick)] = &searches.Add({{"where", "dispatcher_quick"}});
  searches_[static_cast<int>(SearchPlace::kPlanningThreadQuick)] = &searches.Add({{"where", "planning_thread_quick"}});
  searches_[static_cast<int>(SearchPlace::kPlanningThread)] = &searches.Add({{"where", "planning_thread"}});
  auto& replies = prometheus::BuildCounter()
                      .Name("pullout_replies_total")
                      .Help("Answers published, one per request, by outcome")
                      .Register(*registry_);
  found_ = &replies.Add({{"outcome", "found"}});
  no_path_ = &replies.Add({{"outcome", "no_path"}});
  rejected_ = &replies.Add({{"outcome", "rejected"}});
  rejections_ = &prometheus::BuildCounter()
                     .Name("pullout_rejections_total")
                     .Help("Rejected requests by the field class named in the rejection (indices removed)")
                     .Register(*registry_);
  planning_ = &prometheus::BuildHistogram()
                   .Name("pullout_planning_seconds")
                   .Help("Search time of each found or no_path answer, by the planner of the path (none: no path)")
                   .Register(*registry_);
  vehicles_ =
      &prometheus::BuildGauge().Name("pullout_vehicles").Help("Vehicle sessions held").Register(*registry_).Add({});
  queue_depth_ = &prometheus::BuildGauge()
                      .Name("pullout_planning_queue_depth")
                      .Help("Searches waiting for a planning thread")
                      .Register(*registry_)
                      .Add({});
  other_services_ = &prometheus::BuildGauge()
                         .Name("pullout_other_services")
                         .Help("Other pullout_service participants on the same DDS domain now (should be 0)")
                         .Register(*registry_)
                         .Add({});
  auto& evictions = prometheus::BuildCounter()
                        .Name("pullout_evictions_total")
                        .Help("Vehicle sessions evicted, by reason")
                        .Register(*registry_);
  evicted_gone_ = &evictions.Add({{"reason", "gone"}});
  evicted_idle_ = &evictions.Add({{"reason", "idle"}});
  evicted_capacity_ = &evictions.Add({{"reason", "capacity"}});
  // Every search planner has its series from the start, so that rate() sees the first answer.
  for (const auto& [type, name] : detail::kPlannerNames) {
    if (type == PlannerType::kStop) continue;
    planning_by_planner_[static_cast<int>(type)] = &planning_->Add({{"planner", name}}, kPlanningBuckets);
  }
}

ServiceMetrics::~ServiceMetrics() = default;

void ServiceMetrics::on_request() { requests_->Increment(); }
void ServiceMetrics::on_search(SearchPlace place) { searches_[static_cast<int>(place)]->Increment(); }

prometheus::Counter& ServiceMetrics::field_counter(const std::string& field_class) {
  // Caller holds mutex_.
  const auto it = field_counters_.find(field_class);
  if (it != field_counters_.end()) return *it->second;
  const std::string label = field_counters_.size() < kMaxFieldClasses ? field_class : "other";
  prometheus::Counter* counter = &rejections_->Add({{"field", label}});
  if (label == field_class) field_counters_.emplace(field_class, counter);
  return *counter;
}

void ServiceMetrics::on_reply(const PullOutStatus& status) {
  if (!is_outcome(status.state)) return;
  if (status.state == ExecutionState::kRejected) {
    rejected_->Increment();
    std::set<std::string> fields;
    std::istringstream lines(status.error);
    for (std::string line; std::getline(lines, line);) {
      const std::string f = rejection_field_class(line);
      fields.insert(f.empty() ? std::string("unknown") : f);
    }
    if (fields.empty()) fields.insert("unknown");
    std::lock_guard<std::mutex> lock(mutex_);
    for (const std::string& f : fields) field_counter(f).Increment();
    return;
  }
  (status.state == ExecutionState::kNoPath ? no_path_ : found_)->Increment();
  const PlannerType planner = status.state == ExecutionState::kNoPath ? PlannerType::kNone : status.planner_type;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = planning_by_planner_.find(static_cast<int>(planner));
  if (it == planning_by_planner_.end()) it = planning_by_planner_.find(static_cast<int>(PlannerType::kNone));
  it->second->Observe(status.planning_time_ms / 1000.0);
}

void ServiceMetrics::on_eviction(EvictionReason reason) {
  switch (reason) {
    case EvictionReason::kGone:
      evicted_gone_->Increment();
      return;
    case EvictionReason::kIdle:
      evicted_idle_->Increment();
      return;
    case EvictionReason::kCapacity:
      evicted_capacity_->Increment();
      return;
  }
}

void ServiceMetrics::set_vehicles(std::size_t n) { vehicles_->Set(static_cast<double>(n)); }
void ServiceMetrics::set_queue_depth(std::size_t n) { queue_depth_->Set(static_cast<double>(n)); }
void ServiceMetrics::set_other_services(std::size_t n) { other_services_->Set(static_cast<double>(n)); }

}  // namespace pullout::service
