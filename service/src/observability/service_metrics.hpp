// The service's Prometheus metrics (prometheus-cpp). Lives in service/ only: the core knows nothing
// of it. Every method is thread-safe and cheap (atomic updates); a scrape reads the registry.
//
//   pullout_build_info{version}                        gauge, 1
//   pullout_requests_total                             counter: request samples taken
//   pullout_replies_total{outcome}                     counter: answers published, one per request:
//                                                      found, no_path, rejected
//   pullout_rejections_total{field}                    counter: per rejected answer, once per field
//                                                      class named in it (indices removed:
//                                                      "lanes[2].left_bound[5].x" -> lanes.left_bound.x)
//   pullout_planning_seconds{planner}                  histogram: search time of each found or no_path
//                                                      answer, by the planner that found the path
//                                                      (none: no path)
//   pullout_vehicles                                   gauge: vehicle sessions held
//   pullout_planning_queue_depth                       gauge: searches waiting for a planning thread
//   pullout_evictions_total{reason}                    counter: sessions evicted: gone, idle, capacity
//   pullout_other_services                             gauge: other pullout_service participants
//                                                      seen on the domain right now
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "pullout/model/types.hpp"

namespace prometheus {
class Registry;
class Counter;
class Gauge;
class Histogram;
template <typename T>
class Family;
}  // namespace prometheus

namespace pullout::service {

enum class EvictionReason;

// The field class of a rejection line "<field>: <problem>": the field with its indices removed.
// Empty when the line names no field.
std::string rejection_field_class(const std::string& line);

// Where a search ran: answered within service.quick_answer_ms on the dispatcher or on a planning
// thread (no `planning` status), or on a planning thread with the whole budget after `planning`.
enum class SearchPlace { kDispatcherQuick = 0, kPlanningThreadQuick = 1, kPlanningThread = 2 };

class ServiceMetrics {
 public:
  // `version`: the build_info label.
  explicit ServiceMetrics(const std::string& version);
  ~ServiceMetrics();
  ServiceMetrics(const ServiceMetrics&) = delete;
  ServiceMetrics& operator=(const ServiceMetrics&) = delete;

  std::shared_ptr<prometheus::Registry> registry() const { return registry_; }

  void on_request();
  // An answer the service published for a request (its first status with a final outcome).
  void on_reply(const PullOutStatus& status);
  void on_eviction(EvictionReason reason);
  void set_vehicles(std::size_t n);
  void set_queue_depth(std::size_t n);
  void set_other_services(std::size_t n);
  // Where a search ran, and whether it was answered within service.quick_answer_ms.
  void on_search(SearchPlace place);

  // Distinct rejection field classes kept as labels; the rest count as "other" (a label per
  // distinct value is a time series for ever).
  static constexpr std::size_t kMaxFieldClasses = 64;

 private:
  prometheus::Counter& field_counter(const std::string& field_class);

  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Counter* requests_{nullptr};
  std::array<prometheus::Counter*, 3> searches_{};  // by SearchPlace
  prometheus::Counter* found_{nullptr};
  prometheus::Counter* no_path_{nullptr};
  prometheus::Counter* rejected_{nullptr};
  prometheus::Family<prometheus::Counter>* rejections_{nullptr};
  prometheus::Family<prometheus::Histogram>* planning_{nullptr};
  prometheus::Gauge* vehicles_{nullptr};
  prometheus::Gauge* queue_depth_{nullptr};
  prometheus::Gauge* other_services_{nullptr};
  prometheus::Counter* evicted_gone_{nullptr};
  prometheus::Counter* evicted_idle_{nullptr};
  prometheus::Counter* evicted_capacity_{nullptr};
  std::mutex mutex_;  // guards field_counters_ and planning_by_planner_
  std::unordered_map<std::string, prometheus::Counter*> field_counters_;
  std::unordered_map<int, prometheus::Histogram*> planning_by_planner_;
};

}  // namespace pullout::service
