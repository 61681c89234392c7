#include "fleet_monitor.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/idl/topics.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"
#include "service/builtin_profiles.hpp"

namespace pullout::cli {

namespace dds = eprosima::fastdds::dds;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;

namespace {

constexpr auto kWaitSlice = std::chrono::milliseconds(200);
constexpr int kMaxDomainId = 232;
constexpr const char* kParticipantName = "pullout_view";

}  // namespace

class FleetMonitor::Impl {
 public:
  explicit Impl(FleetMonitorOptions options) : options_(std::move(options)) {
    if (options_.domain_id < 0 || options_.domain_id > kMaxDomainId) {
      throw std::invalid_argument("domain id " + std::to_string(options_.domain_id) + " is outside 0..232");
    }
    try {
      create();
    } catch (...) {
      destroy();
      throw;
    }
    thread_ = std::thread([this] { run(); });
  }

  ~Impl() {
    stop_.store(true);
    stop_condition_.set_trigger_value(true);
    if (thread_.joinable()) thread_.join();
    destroy();
  }

  FleetSnapshot snapshot() const {
    std::lock_guard<std::mutex> lock(mutex_);
    FleetSnapshot out;
    out.version = version_;
    out.service_matched = service_matched_;
    out.vehicles.reserve(vehicles_.size());
    for (const auto& [id, view] : vehicles_) out.vehicles.push_back(view);
    return out;
  }

  std::uint64_t wait_for_change(std::uint64_t seen, Duration timeout) const {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return version_ > seen; });
    return version_;
  }

 private:
  void create() {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    std::string where = "the built-in loopback profiles";
    if (options_.profiles_file.empty()) {
      const std::string xml(service::kBuiltinProfilesXml);
      if (factory->load_XML_profiles_string(xml.c_str(), xml.size()) != ReturnCode::RETCODE_OK) {
        throw FleetMonitorError("cannot load the built-in DDS profiles");
      }
    } else {
      where = options_.profiles_file;
      // Fast DDS only logs a broken file: check the result ourselves.
      if (factory->load_XML_profiles_file(options_.profiles_file) != ReturnCode::RETCODE_OK) {
        throw FleetMonitorError("DDS profiles file '" + options_.profiles_file + "' could not be loaded");
      }
    }
    dds::DomainParticipantQos qos;
    if (factory->get_participant_qos_from_profile(options_.participant_profile, qos) != ReturnCode::RETCODE_OK) {
      throw FleetMonitorError("no participant profile '" + options_.participant_profile + "' in " + where);
    }
    qos.name(kParticipantName);
    participant_ = factory->create_participant(options_.domain_id, qos, nullptr, dds::StatusMask::none());
    if (participant_ == nullptr) {
      throw FleetMonitorError("cannot create a DDS participant on domain " + std::to_string(options_.domain_id));
    }
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (subscriber_ == nullptr) throw FleetMonitorError("cannot create the DDS subscriber");

    const auto reader = [&](const char* topic_name, dds::TopicDataType* type, const char* profile) {
      dds::TypeSupport support(type);  // takes ownership
      if (support.register_type(participant_) != ReturnCode::RETCODE_OK) {
        throw FleetMonitorError(std::string("cannot register DDS type ") + support.get_type_name());
      }
      dds::Topic* topic = participant_->create_topic(topic_name, support.get_type_name(), dds::TOPIC_QOS_DEFAULT);
      if (topic == nullptr) throw FleetMonitorError(std::string("cannot create topic ") + topic_name);
      dds::DataReaderQos reader_qos;
      if (subscriber_->get_datareader_qos_from_profile(profile, reader_qos) != ReturnCode::RETCODE_OK) {
        throw FleetMonitorError(std::string("no reader profile '") + profile + "' in " + where);
      }
      // As the service: a DYNAMIC* payload pool stalls a Fast DDS 2.9.1 reader on the key-only
      // sample of an unregister (config/dds/loopback.xml).
      auto& policy = reader_qos.endpoint().history_memory_policy;
      if (policy == eprosima::fastrtps::rtps::DYNAMIC_RESERVE_MEMORY_MODE ||
          policy == eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE) {
        policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
      }
      dds::DataReader* created = subscriber_->create_datareader(topic, reader_qos, nullptr, dds::StatusMask::none());
      if (created == nullptr) throw FleetMonitorError(std::string("cannot create the reader of ") + topic_name);
      created->get_statuscondition().set_enabled_statuses(dds::StatusMask::data_available());
      wait_set_.attach_condition(created->get_statuscondition());
      return created;
    };
    request_reader_ =
        reader(idl::kRequestTopic, idl::make_guarded_type<msg::PullOutRequestPubSubType>(), idl::kRequestReaderProfile);
    path_reader_ =
        reader(idl::kPathTopic, idl::make_guarded_type<msg::PullOutPathPubSubType>(), idl::kPathReaderProfile);
    status_reader_ =
        reader(idl::kStatusTopic, idl::make_guarded_type<msg::PullOutStatusPubSubType>(), idl::kStatusReaderProfile);
    progress_reader_ = reader(idl::kProgressTopic, idl::make_guarded_type<msg::ExecutionProgressPubSubType>(),
                              idl::kProgressReaderProfile);
    wait_set_.attach_condition(stop_condition_);
  }

  void destroy() noexcept {
    if (participant_ == nullptr) return;
    for (dds::DataReader* r : {request_reader_, path_reader_, status_reader_, progress_reader_}) {
      if (r != nullptr) wait_set_.detach_condition(r->get_statuscondition());
    }
    wait_set_.detach_condition(stop_condition_);
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    participant_ = nullptr;
  }

  void run() {
    while (!stop_.load()) {
      dds::ConditionSeq active;
      wait_set_.wait(active, eprosima::fastrtps::Duration_t(
                                 0, static_cast<std::uint32_t>(std::chrono::nanoseconds(kWaitSlice).count())));
      if (stop_.load()) break;
      bool changed = false;
      changed |= take<msg::PullOutRequest>(request_reader_, [](const msg::PullOutRequest& m, VehicleView& v) {
        std::vector<RequestIssue> issues;
        PullOutRequest request = idl::from_msg(m, issues);
        // A request the service rejects for its encoding is not drawn (its lanes may be garbage).
        if (issues.empty()) v.request = std::make_shared<const PullOutRequest>(std::move(request));
      });
      changed |= take<msg::PullOutPath>(path_reader_, [](const msg::PullOutPath& m, VehicleView& v) {
        v.path = std::make_shared<const PullOutPath>(idl::from_msg(m));
      });
      changed |= take<msg::PullOutStatus>(status_reader_, [](const msg::PullOutStatus& m, VehicleView& v) {
        v.status = std::make_shared<const PullOutStatus>(idl::from_msg(m));
      });
      changed |= take<msg::ExecutionProgress>(progress_reader_, [](const msg::ExecutionProgress& m, VehicleView& v) {
        std::vector<RequestIssue> issues;
        ExecutionProgress progress = idl::from_msg(m, issues);
        if (issues.empty()) v.progress = std::make_shared<const ExecutionProgress>(std::move(progress));
      });
      dds::SubscriptionMatchedStatus path_matched;
      dds::SubscriptionMatchedStatus status_matched;
      path_reader_->get_subscription_matched_status(path_matched);
      status_reader_->get_subscription_matched_status(status_matched);
      const bool matched = path_matched.current_count > 0 && status_matched.current_count > 0;
      std::lock_guard<std::mutex> lock(mutex_);
      if (matched != service_matched_) {
        service_matched_ = matched;
        changed = true;
      }
      if (changed) {
        ++version_;
        changed_.notify_all();
      }
    }
  }

  // Takes every sample of `reader` and applies the valid ones to their vehicle's view. Returns
  // whether any was applied.
  template <typename Message, typename Apply>
  bool take(dds::DataReader* reader, Apply apply) {
    bool any = false;
    Message message;
    dds::SampleInfo info;
    while (reader->take_next_sample(&message, &info) == ReturnCode::RETCODE_OK) {
      if (!info.valid_data) continue;  // unregister / dispose: the vehicle's last samples stay shown
      std::lock_guard<std::mutex> lock(mutex_);
      VehicleView& view = vehicle(message.vehicle_id());
      apply(message, view);
      const auto& t = info.source_timestamp;
      const auto written =
          std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
              std::chrono::seconds(t.seconds()) + std::chrono::nanoseconds(t.nanosec())));
      view.last_update = std::max(view.last_update, written);
      any = true;
    }
    return any;
  }

  // The view of `id`, created when new; forgets the least recently updated vehicle when full.
  // Called with mutex_ held.
  VehicleView& vehicle(const std::string& id) {
    auto it = vehicles_.find(id);
    if (it != vehicles_.end()) return it->second;
    if (!vehicles_.empty() && vehicles_.size() >= options_.max_vehicles) {
      const auto oldest = std::min_element(vehicles_.begin(), vehicles_.end(), [](const auto& a, const auto& b) {
        return a.second.last_update < b.second.last_update;
      });
      vehicles_.erase(oldest);
    }
    VehicleView& view = vehicles_[id];
    view.vehicle_id = id;
    return view;
  }

  FleetMonitorOptions options_;
  dds::DomainParticipant* participant_{nullptr};
  dds::Subscriber* subscriber_{nullptr};
  dds::DataReader* request_reader_{nullptr};
  dds::DataReader* path_reader_{nullptr};
  dds::DataReader* status_reader_{nullptr};
  dds::DataReader* progress_reader_{nullptr};
  dds::WaitSet wait_set_;
  dds::GuardCondition stop_condition_;
  std::atomic<bool> stop_{false};
  std::thread thread_;

  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::map<std::string, VehicleView> vehicles_;
  std::uint64_t version_{0};
  bool service_matched_{false};
};

FleetMonitor::FleetMonitor(FleetMonitorOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
FleetMonitor::~FleetMonitor() = default;

FleetSnapshot FleetMonitor::snapshot() const { return impl_->snapshot(); }

std::uint64_t FleetMonitor::wait_for_change(std::uint64_t seen, Duration timeout) const {
  return impl_->wait_for_change(seen, timeout);
}

}  // namespace pullout::cli
