#include "pullout/client/client.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <mutex>
#include <set>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/StatusCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "dds_qos.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/idl/security.hpp"
#include "pullout/idl/vehicle_filter.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

namespace pullout {

ClientError::ClientError(const std::string& what) : std::runtime_error(what) {}

namespace {

namespace dds = eprosima::fastdds::dds;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
using SteadyClock = std::chrono::steady_clock;

constexpr int kMaxDomainId = 232;
// Replies kept for wait_for_path / wait_for_status. Paths can be several hundred KB each.
constexpr std::size_t kRecentPaths = 16;  // client.hpp promises the last 16
constexpr std::size_t kRecentStatuses = 32;
// Reader history depths: more than 1 so that replies arriving back to back are not overwritten
// before the client's thread takes them. Late joiners still get only the writer's last sample.
constexpr int kPathReaderDepth = 4;
constexpr int kStatusReaderDepth = 8;
// The client's thread wakes at least this often (a missed wake-up, the matched counts).
constexpr auto kDispatchPeriod = std::chrono::milliseconds(1000);
// Instances the shared endpoints of a ClientParticipant hold at least (one per vehicle on it).
constexpr std::int32_t kSharedMaxInstances = 4096;

// Room for every vehicle of the participant in a shared endpoint's QoS (a writer's or a reader's):
// a profile's max_instances below kSharedMaxInstances is raised to it, with its depth per instance.
template <class Qos>
void widen_for_fleet(Qos& qos) {
  auto& limits = qos.resource_limits();
  if (limits.max_instances > 0 && limits.max_instances < kSharedMaxInstances) {
    const int depth = std::max(1, qos.history().depth);
    limits.max_instances = kSharedMaxInstances;
    limits.max_samples_per_instance = depth;
    limits.max_samples = kSharedMaxInstances * depth;
  }
}

std::int64_t system_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void validate_options(const ClientOptions& options) {
  if (options.vehicle_id.empty()) throw std::invalid_argument("ClientOptions.vehicle_id: must not be empty");
  if (options.vehicle_id.size() > kMaxVehicleIdBytes) {
    throw std::invalid_argument("ClientOptions.vehicle_id: longer than " + std::to_string(kMaxVehicleIdBytes) +
                                " bytes");
  }
  if (options.vehicle_id.find('\0') != std::string::npos) {
    throw std::invalid_argument("ClientOptions.vehicle_id: contains a NUL character");
  }
  if (options.domain_id < 0 || options.domain_id > kMaxDomainId) {
    throw std::invalid_argument("ClientOptions.domain_id: " + std::to_string(options.domain_id) + " is outside 0.." +
                                std::to_string(kMaxDomainId));
  }
  if (!options.security_dir.empty() && !idl::is_literal_partition_name(options.vehicle_id)) {
    throw std::invalid_argument(
        "ClientOptions.vehicle_id: with security_dir, it names a DDS partition and may not "
        "contain * ? [ ] or \\");
  }
  if (options.resend_window.count() < 0) {
    throw std::invalid_argument("ClientOptions.resend_window: must not be negative");
  }
  if (options.resend_period.count() <= 0) {
    throw std::invalid_argument("ClientOptions.resend_period: must be positive");
  }
}

// A deadline that does not overflow for huge timeouts (Duration::max()).
SteadyClock::time_point deadline_after(Client::Duration timeout) {
  const auto now = SteadyClock::now();
  if (timeout <= Client::Duration::zero()) return now;
  if (timeout >= SteadyClock::time_point::max() - now) return SteadyClock::time_point::max();
  return now + std::chrono::duration_cast<SteadyClock::duration>(timeout);
}

template <typename T>
struct Received {
  std::uint64_t seq{0};  // order of reception, from 1
  std::shared_ptr<const T> value;
};

// A registered callback and its delivery state, guarded by Impl::callback_mutex_.
template <typename T>
struct CallbackSlot {
  std::function<void(const T&)> callback;
  std::uint64_t generation{0};          // incremented by every registration (the first is 1)
  std::uint64_t delivered_seq{0};       // last seq given to the current callback
  std::uint64_t running_generation{0};  // generation of the callback the dispatcher is in; 0: none
};

template <typename T>
void push_bounded(std::deque<Received<T>>& queue, Received<T> item, std::size_t bound) {
  queue.push_back(std::move(item));
  while (queue.size() > bound) queue.pop_front();
}

}  // namespace

namespace client_detail {

// What a ClientParticipant's shared endpoints hand to one Client (Client::Impl implements it).
// Called on the Hub's thread with no Hub lock but its routes lock held: keep it short.
class __attribute__((visibility("hidden"))) VehicleSink {
 public:
  virtual void push_path(std::shared_ptr<const PullOutPath> path) = 0;
  virtual void push_status(std::shared_ptr<const PullOutStatus> status) = 0;
  // The service's matches or the applied filter changed: look again.
  virtual void wake() = 0;

 protected:
  ~VehicleSink() = default;
};

// The shared endpoints' matches with the service.
struct Matches {
  std::int32_t request{0};
  std::int32_t progress{0};
  std::int32_t path{0};
  std::int32_t status{0};
  std::uint64_t request_epoch{0};  // incremented whenever the request writer matched a new reader
};

// One set of a vehicle's DDS endpoints: a ClientParticipant's shared set (Hub) or a Client's own.
struct __attribute__((visibility("hidden"))) Endpoints {
  dds::Publisher* publisher{nullptr};
  dds::Subscriber* subscriber{nullptr};
  dds::DataWriter* request_writer{nullptr};
  dds::DataWriter* progress_writer{nullptr};
  dds::ContentFilteredTopic* path_filter{nullptr};
  dds::ContentFilteredTopic* status_filter{nullptr};
  dds::DataReader* path_reader{nullptr};
  dds::DataReader* status_reader{nullptr};

  // Deletes what was created (each reader before its filter and subscriber, each writer before
  // its publisher) and forgets it.
  void destroy(dds::DomainParticipant& participant) noexcept {
    if (subscriber != nullptr) {
      if (path_reader != nullptr) subscriber->delete_datareader(path_reader);
      if (status_reader != nullptr) subscriber->delete_datareader(status_reader);
      participant.delete_subscriber(subscriber);
    }
    if (path_filter != nullptr) participant.delete_contentfilteredtopic(path_filter);
    if (status_filter != nullptr) participant.delete_contentfilteredtopic(status_filter);
    if (publisher != nullptr) {
      if (request_writer != nullptr) publisher->delete_datawriter(request_writer);
      if (progress_writer != nullptr) publisher->delete_datawriter(progress_writer);
      participant.delete_publisher(publisher);
    }
    *this = Endpoints{};
  }
};

class Hub;

// The DDS participant, its topics and the vehicle filter factory, shared by the Clients on it: one
// per single-vehicle Client, or one per ClientParticipant. Each Client holds a shared_ptr, so the
// participant is deleted after the last Client on it.
class __attribute__((visibility("hidden"))) SharedParticipant {
 public:
  // shared_endpoints: create the Hub (a ClientParticipant's one request writer, progress writer,
  // path and status readers for all its Clients).
  SharedParticipant(int domain_id, std::string profiles_file, const std::string& participant_profile,
                    const std::string& security_dir, bool shared_endpoints = false);
  ~SharedParticipant();
  SharedParticipant(const SharedParticipant&) = delete;
  SharedParticipant& operator=(const SharedParticipant&) = delete;

  int domain_id() const { return domain_id_; }
  const std::string& profiles_file() const { return profiles_file_; }
  dds::DomainParticipant* participant() const { return participant_; }
  dds::Topic* request_topic() const { return request_topic_; }
  dds::Topic* progress_topic() const { return progress_topic_; }
  dds::Topic* path_topic() const { return path_topic_; }
  dds::Topic* status_topic() const { return status_topic_; }
  // The shared endpoints; null when each Client has its own.
  Hub* hub() const { return hub_.get(); }

  // Registers a Client for vehicle_id; throws std::invalid_argument when one is already alive.
  // Returns a serial that makes the Client's content-filtered topic names unique.
  std::uint64_t claim(const std::string& vehicle_id);
  void release(const std::string& vehicle_id);
  std::size_t client_count() const;
  // Serialises the creation and deletion of Clients' entities on the participant.
  std::mutex& entities_mutex() { return entities_mutex_; }

 private:
  const int domain_id_;
  const std::string profiles_file_;
  // Registered with the participant: declared first (destroyed last).
  void create(const std::string& participant_profile, const std::string& security_dir, bool shared_endpoints);
  void destroy() noexcept;

  idl::VehicleIdFilterFactory filter_factory_;
  dds::DomainParticipant* participant_{nullptr};
  dds::Topic* request_topic_{nullptr};
  dds::Topic* progress_topic_{nullptr};
  dds::Topic* path_topic_{nullptr};
  dds::Topic* status_topic_{nullptr};
  std::unique_ptr<Hub> hub_;
  mutable std::mutex mutex_;
  std::set<std::string> vehicles_;
  std::uint64_t next_serial_{0};
  std::mutex entities_mutex_;
};

// A ClientParticipant's shared endpoints: one request and one progress writer (each Client writes
// its own instance, keyed by its vehicle id) and one path and one status reader whose content
// filter is the set of the participant's vehicles (idl::kVehicleSetFilterExpression), filtered at
// the service's writers. Its thread takes every reply and hands it to the Client of its vehicle
// (VehicleSink), and tracks the matches with the service. So the service's writers see one
// filtered reader per participant, not one per vehicle (bench/RESULTS.md, "Load").
//
// Membership: add() puts a vehicle in the set; the thread applies the set to both readers'
// filters (ContentFilteredTopic::set_expression_parameters: the readers are announced again and
// the service's writers update their filters in place), coalescing changes that come within
// kApplyInterval. A vehicle counts as connected only once its id is in the applied set
// (is_applied). A reply the service writes before it has the new set is filtered out there; the
// Client's re-send repairs that.
class __attribute__((visibility("hidden"))) Hub {
 public:
  static constexpr auto kApplyInterval = std::chrono::milliseconds(20);

  Hub(dds::DomainParticipant* participant, dds::Topic* request_topic, dds::Topic* progress_topic,
      dds::Topic* path_topic, dds::Topic* status_topic, const std::string& profiles_file);
  ~Hub();
  Hub(const Hub&) = delete;
  Hub& operator=(const Hub&) = delete;

  // Routes vehicle_id's replies to sink. False (nothing changed) when the set filter has no room
  // for it (idl::kVehicleSetCapacityBytes).
  bool add(const std::string& vehicle_id, VehicleSink* sink);
  // Stops routing to the vehicle's sink (no push after this returns), takes it out of the set,
  // and unregisters its request and progress instances (the service sees them disposed).
  void remove(const std::string& vehicle_id, bool wrote_request, bool wrote_progress);
  bool is_applied(const std::string& vehicle_id) const;
  Matches matches() const;
  bool write_request(msg::PullOutRequest* sample);
  bool write_progress(msg::ExecutionProgress* sample);
  std::size_t members() const;

 private:
  void create();
  void create_readers(const std::vector<std::string>& parameters);
  void destroy() noexcept;
  void run();
  void apply_set();
  void take_and_route();
  bool update_matches();

  dds::DomainParticipant* const participant_;
  dds::Topic* const request_topic_;
  dds::Topic* const progress_topic_;
  dds::Topic* const path_topic_;
  dds::Topic* const status_topic_;
  const std::string profiles_file_;
  Endpoints ep_;  // the shared ones

  // The set: members_ as wanted, applied_ as the readers' filters have it. Guarded by set_mutex_.
  mutable std::mutex set_mutex_;
  std::set<std::string> members_;
  std::set<std::string> applied_;
  std::size_t encoded_bytes_{0};
  bool dirty_{false};
  std::chrono::steady_clock::time_point last_change_{};  // of members_

  mutable std::mutex routes_mutex_;
  std::unordered_map<std::string, VehicleSink*> routes_;

  mutable std::mutex matches_mutex_;
  Matches matches_;

  // The generated type support keeps per-type scratch buffers: one write per writer at a time.
  std::mutex request_write_mutex_;
  std::mutex progress_write_mutex_;

  dds::GuardCondition wake_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace client_detail

// Hidden explicitly: a nested class inherits the default visibility of the exported Client.
class __attribute__((visibility("hidden"))) Client::Impl final : public client_detail::VehicleSink {
 public:
  // shared: the participant to create the client's endpoints on; null: a participant of its own.
  Impl(std::shared_ptr<client_detail::SharedParticipant> shared, ClientOptions options);
  ~Impl();

  std::uint64_t send(PullOutRequest request);
  void report_progress(ExecutionProgress progress);
  void on_path(PathCallback callback);
  void on_status(StatusCallback callback);
  std::optional<PullOutPath> wait_for_path(std::uint64_t request_id, Duration timeout) const;
  std::optional<PullOutStatus> wait_for_status(std::uint64_t request_id, const StatusPredicate& predicate,
                                               Duration timeout) const;
  std::optional<PullOutPath> latest_path() const;
  std::optional<PullOutStatus> latest_status() const;
  std::uint64_t current_request_id() const;
  std::optional<std::uint32_t> current_segment() const;
  bool wait_for_services(std::size_t count, Duration timeout) const;
  ServiceState service_state() const;
  std::size_t matched_services() const;

  const ClientOptions& options() const { return options_; }

  // VehicleSink (shared endpoints): on the Hub's thread.
  void push_path(std::shared_ptr<const PullOutPath> path) override;
  void push_status(std::shared_ptr<const PullOutStatus> status) override;
  void wake() override { wake_dispatcher(); }

 private:
  void create_entities();
  void destroy_entities() noexcept;
  dds::DataWriterQos writer_qos(const char* profile) const;
  dds::DataReaderQos reader_qos(const char* profile, int depth) const;
  dds::DataReader* create_reply_reader(dds::Topic* topic, const char* profile, int depth,
                                       dds::ContentFilteredTopic** filter);

  void run();
  void dispatch_once();
  // Reads the matched counts; updates service_state_ and re-sends the pending request when a
  // service (re)appeared or its period elapsed. Returns when the next re-send is due.
  SteadyClock::time_point update_service_and_resend();
  void resend_pending(std::uint64_t id);
  // Under state_mutex_: whether request_id may still be re-sent (answered = false, current, and
  // within its window), and whether a wait for it should give up (service lost, no re-send).
  bool resend_pending_locked(std::uint64_t request_id, SteadyClock::time_point now) const;
  bool give_up_locked(std::uint64_t request_id, SteadyClock::time_point now) const;
  // When a wait for request_id must look again: its deadline, or earlier the end of the request's
  // resend window (give_up_locked may become true then with no sample arriving).
  SteadyClock::time_point recheck_locked(std::uint64_t request_id, SteadyClock::time_point deadline) const;
  bool stale_locked(const Received<PullOutStatus>& item) const;
  // Own endpoints: answered by its path or a status past planning. Shared endpoints: by both,
  // since a Client that just joined the set may get one of the two filtered out at the service
  // (its path and status readers' new set reach the service's two writers one after the other);
  // the re-send has the service publish both again.
  void update_answered_locked() {
    pending_.answered =
        hub_ != nullptr ? pending_.path_seen && pending_.status_seen : pending_.path_seen || pending_.status_seen;
  }
  template <typename T>
  void replace_callback(CallbackSlot<T>& slot, std::function<void(const T&)> callback);
  template <typename T>
  bool deliver(CallbackSlot<T>& slot, const Received<T>& item, std::uint64_t generation, const char* what);
  std::vector<std::shared_ptr<const PullOutPath>> take_paths();
  std::vector<std::shared_ptr<const PullOutStatus>> take_statuses();
  bool write_request(msg::PullOutRequest* sample);
  bool on_dispatcher_thread() const { return std::this_thread::get_id() == dispatcher_.get_id(); }
  void wake_dispatcher() { wake_.set_trigger_value(true); }

  ClientOptions options_;

  // --- DDS entities: created in the constructor, deleted in the destructor (the participant and
  // topics with the last Client holding shared_). ---
  std::shared_ptr<client_detail::SharedParticipant> shared_;
  bool claimed_{false};  // shared_ has this vehicle registered
  std::uint64_t serial_{0};
  dds::DomainParticipant* participant_{nullptr};
  client_detail::Endpoints ep_;  // its own (none when hub_ carries it)
  // The participant's shared endpoints carry this client (instead of the endpoints above); null
  // when it has its own.
  client_detail::Hub* hub_{nullptr};
  std::atomic<bool> wrote_request_{false};
  std::atomic<bool> wrote_progress_{false};
  std::uint64_t request_epoch_{0};  // the Hub's request_epoch last seen (dispatcher thread only)

  // Replies the Hub handed over, not yet taken by the client's thread.
  std::mutex inbox_mutex_;
  std::vector<std::shared_ptr<const PullOutPath>> inbox_paths_;
  std::vector<std::shared_ptr<const PullOutStatus>> inbox_statuses_;

  // --- received state, guarded by state_mutex_ ---
  mutable std::mutex state_mutex_;
  mutable std::condition_variable state_cv_;
  std::deque<Received<PullOutPath>> recent_paths_;
  std::deque<Received<PullOutStatus>> recent_statuses_;
  std::uint64_t path_seq_{0};
  std::uint64_t status_seq_{0};
  std::uint64_t last_request_id_{0};
  std::uint64_t current_request_id_{0};
  bool sent_any_{false};
  // The request being re-sent until answered: the current request, as written.
  struct Pending {
    std::uint64_t id{0};
    std::shared_ptr<const msg::PullOutRequest> sample;
    SteadyClock::time_point sent_at{};     // first write (send())
    SteadyClock::time_point last_write{};  // latest write
    bool path_seen{false};                 // its path was received
    bool status_seen{false};               // a status for it, past planning, was received
    bool answered{false};                  // update_answered_locked
  } pending_;
  ServiceState service_state_{ServiceState::kNotFound};
  std::int32_t request_matches_{0};  // the request writer's current match count
  // Statuses with seq <= this were received before the latest loss of the service.
  std::uint64_t stale_status_seq_{0};

  // Serialises request writes (the type support's scratch buffers; a re-send never overtakes a
  // newer send()). Lock order: write_mutex_, then state_mutex_.
  std::mutex write_mutex_;

  // --- callbacks, guarded by callback_mutex_ (never held while a callback runs). Lock order:
  // callback_mutex_, then state_mutex_. callback_cv_ signals the end of a callback. ---
  std::mutex callback_mutex_;
  std::condition_variable callback_cv_;
  CallbackSlot<PullOutPath> path_slot_;
  CallbackSlot<PullOutStatus> status_slot_;

  dds::GuardCondition wake_;
  std::atomic<bool> stop_{false};
  std::thread dispatcher_;
};

// ------------------------------------------------------------------------------------------------
// The shared participant

namespace client_detail {

SharedParticipant::SharedParticipant(int domain_id, std::string profiles_file, const std::string& participant_profile,
                                     const std::string& security_dir, bool shared_endpoints)
    : domain_id_(domain_id), profiles_file_(std::move(profiles_file)) {
  try {
    create(participant_profile, security_dir, shared_endpoints);
  } catch (...) {
    destroy();
    throw;
  }
}

SharedParticipant::~SharedParticipant() { destroy(); }

void SharedParticipant::destroy() noexcept {
  hub_.reset();
  if (participant_ == nullptr) return;
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  participant_ = nullptr;
}

void SharedParticipant::create(const std::string& participant_profile, const std::string& security_dir,
                               bool shared_endpoints) {
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipantQos participant_qos;
  if (profiles_file_.empty()) {
    participant_qos = client_detail::loopback_participant_qos();
  } else {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(profiles_file_, ec)) {
      throw ClientError("DDS profiles file '" + profiles_file_ + "' does not exist or is not a file");
    }
    // Fast DDS only logs a broken file: check the result ourselves.
    if (factory->load_XML_profiles_file(profiles_file_) != ReturnCode::RETCODE_OK) {
      throw ClientError("DDS profiles file '" + profiles_file_ + "' could not be loaded (invalid XML?)");
    }
    if (factory->get_participant_qos_from_profile(participant_profile, participant_qos) != ReturnCode::RETCODE_OK) {
      throw ClientError("participant profile '" + participant_profile + "' not found in '" + profiles_file_ + "'");
    }
  }
  const bool secure = !security_dir.empty();
  if (secure) {
    // A credential missing from the directory is a bad option (the caller's to fix), not a DDS
    // failure: std::invalid_argument, as for a bad domain id (the CLI's exit status 2, not 3).
    try {
      idl::add_security_properties(security_dir, participant_qos);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("ClientOptions.security_dir: ") + e.what());
    }
  }
  participant_ = factory->create_participant(static_cast<dds::DomainId_t>(domain_id_), participant_qos);
  if (participant_ == nullptr) {
    throw ClientError(
        "cannot create a DDS participant on domain " + std::to_string(domain_id_) +
        (secure ? " with the credentials in " + security_dir + " (the reason is in Fast DDS's log, category SECURITY)"
                : std::string()));
  }
  if (participant_->register_content_filter_factory(idl::kVehicleFilterClass, &filter_factory_) !=
      ReturnCode::RETCODE_OK) {
    throw ClientError("cannot register the vehicle content filter");
  }

  // TypeSupport takes ownership of the type object it is given.
  const auto register_type = [this](dds::TopicDataType* type) {
    dds::TypeSupport support(type);
    if (support.register_type(participant_) != ReturnCode::RETCODE_OK) {
      throw ClientError(std::string("cannot register DDS type ") + support.get_type_name());
    }
    return support.get_type_name();
  };
  const auto create_topic = [this](const char* name, const std::string& type_name) {
    dds::Topic* topic = participant_->create_topic(name, type_name, dds::TOPIC_QOS_DEFAULT);
    if (topic == nullptr) throw ClientError(std::string("cannot create topic ") + name);
    return topic;
  };
  // Guarded: a malformed reply fails to deserialize (and is dropped) instead of throwing out of
  // take_next_sample on the client's thread.
  request_topic_ = create_topic(client_detail::kRequestTopic,
                                register_type(idl::make_guarded_type<msg::PullOutRequestPubSubType>()));
  progress_topic_ = create_topic(client_detail::kProgressTopic,
                                 register_type(idl::make_guarded_type<msg::ExecutionProgressPubSubType>()));
  path_topic_ =
      create_topic(client_detail::kPathTopic, register_type(idl::make_guarded_type<msg::PullOutPathPubSubType>()));
  status_topic_ =
      create_topic(client_detail::kStatusTopic, register_type(idl::make_guarded_type<msg::PullOutStatusPubSubType>()));
  if (shared_endpoints) {
    hub_ = std::make_unique<Hub>(participant_, request_topic_, progress_topic_, path_topic_, status_topic_,
                                 profiles_file_);
  }
}

std::uint64_t SharedParticipant::claim(const std::string& vehicle_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!vehicles_.insert(vehicle_id).second) {
    throw std::invalid_argument("ClientOptions.vehicle_id: the participant already has a client for vehicle '" +
                                vehicle_id + "'");
  }
  return ++next_serial_;
}

void SharedParticipant::release(const std::string& vehicle_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  vehicles_.erase(vehicle_id);
}

std::size_t SharedParticipant::client_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return vehicles_.size();
}

// ------------------------------------------------------------------------------------------------
// The shared endpoints of a ClientParticipant

Hub::Hub(dds::DomainParticipant* participant, dds::Topic* request_topic, dds::Topic* progress_topic,
         dds::Topic* path_topic, dds::Topic* status_topic, const std::string& profiles_file)
    : participant_(participant),
      request_topic_(request_topic),
      progress_topic_(progress_topic),
      path_topic_(path_topic),
      status_topic_(status_topic),
      profiles_file_(profiles_file) {
  try {
    create();
    thread_ = std::thread([this] { run(); });
  } catch (...) {
    destroy();
    throw;
  }
}

Hub::~Hub() {
  stop_.store(true);
  wake_.set_trigger_value(true);
  if (thread_.joinable()) thread_.join();
  destroy();
}

void Hub::create() {
  ep_.publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  ep_.subscriber = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (ep_.publisher == nullptr || ep_.subscriber == nullptr)
    throw ClientError("cannot create a DDS publisher/subscriber");
  // The QoS of the per-Client endpoints (profile, else built in), with room for every vehicle's
  // instance: Fast DDS's default max_instances is 10.
  const auto writer_qos = [&](const char* profile) {
    dds::DataWriterQos qos = command_writer_qos();
    if (!profiles_file_.empty()) {
      dds::DataWriterQos from_profile;
      if (ep_.publisher->get_datawriter_qos_from_profile(profile, from_profile) == ReturnCode::RETCODE_OK) {
        qos = from_profile;
      }
    }
    widen_for_fleet(qos);
    return qos;
  };
  ep_.request_writer = ep_.publisher->create_datawriter(request_topic_, writer_qos(kRequestWriterProfile));
  if (ep_.request_writer == nullptr) throw ClientError("cannot create the shared pullout/request writer");
  ep_.progress_writer = ep_.publisher->create_datawriter(progress_topic_, writer_qos(kProgressWriterProfile));
  if (ep_.progress_writer == nullptr) throw ClientError("cannot create the shared pullout/progress writer");
  ep_.request_writer->get_statuscondition().set_enabled_statuses(dds::StatusMask::publication_matched());
  ep_.progress_writer->get_statuscondition().set_enabled_statuses(dds::StatusMask::publication_matched());
}

// The readers are created with the first set, once Clients stopped coming for kApplyInterval: the
// service's transient-local history (each vehicle's latest path and status) reaches a reader when
// it matches, filtered by the set it has then, so the Clients constructed together with the
// participant get their vehicle's latest path and status as single-vehicle Clients do.
void Hub::create_readers(const std::vector<std::string>& parameters) {
  const auto reader_qos = [&](const char* profile, int depth) {
    dds::DataReaderQos qos = reply_reader_qos(depth);
    if (!profiles_file_.empty()) {
      dds::DataReaderQos from_profile;
      if (ep_.subscriber->get_datareader_qos_from_profile(profile, from_profile) == ReturnCode::RETCODE_OK) {
        qos = from_profile;
      }
    }
    widen_for_fleet(qos);
    return qos;
  };
  const auto filtered_reader = [&](dds::Topic* topic, const char* profile, int depth,
                                   dds::ContentFilteredTopic** filter) {
    const std::string name = topic->get_name();
    *filter = participant_->create_contentfilteredtopic(name + "/vehicles", topic, idl::kVehicleSetFilterExpression,
                                                        parameters, idl::kVehicleFilterClass);
    if (*filter == nullptr) throw ClientError("cannot create the vehicle set filter on " + name);
    dds::DataReader* reader = ep_.subscriber->create_datareader(*filter, reader_qos(profile, depth));
    if (reader == nullptr) throw ClientError("cannot create the shared " + name + " reader");
    reader->get_statuscondition().set_enabled_statuses(dds::StatusMask::data_available()
                                                       << dds::StatusMask::subscription_matched());
    return reader;
  };
  ep_.path_reader = filtered_reader(path_topic_, kPathReaderProfile, kPathReaderDepth, &ep_.path_filter);
  ep_.status_reader = filtered_reader(status_topic_, kStatusReaderProfile, kStatusReaderDepth, &ep_.status_filter);
}

void Hub::destroy() noexcept { ep_.destroy(*participant_); }

bool Hub::add(const std::string& vehicle_id, VehicleSink* sink) {
  {
    std::lock_guard<std::mutex> lock(set_mutex_);
    const std::size_t bytes = idl::vehicle_set_entry_bytes(vehicle_id);
    if (encoded_bytes_ + bytes > idl::kVehicleSetCapacityBytes) return false;
    // SharedParticipant::claim already refused a second Client of this vehicle.
    members_.insert(vehicle_id);
    encoded_bytes_ += bytes;
    dirty_ = true;
    last_change_ = SteadyClock::now();
  }
  {
    std::lock_guard<std::mutex> lock(routes_mutex_);
    routes_[vehicle_id] = sink;
  }
  wake_.set_trigger_value(true);
  return true;
}

void Hub::remove(const std::string& vehicle_id, bool wrote_request, bool wrote_progress) {
  {
    std::lock_guard<std::mutex> lock(routes_mutex_);
    routes_.erase(vehicle_id);
  }
  {
    std::lock_guard<std::mutex> lock(set_mutex_);
    if (members_.erase(vehicle_id) != 0) encoded_bytes_ -= idl::vehicle_set_entry_bytes(vehicle_id);
    dirty_ = true;
    last_change_ = SteadyClock::now();
  }
  wake_.set_trigger_value(true);
  // As a Client's own writers being deleted: the service sees the vehicle's instances go (with
  // the writers' default autodispose_unregistered_instances, disposed) and may evict it.
  if (wrote_request) {
    msg::PullOutRequest key;
    key.vehicle_id(vehicle_id);
    std::lock_guard<std::mutex> lock(request_write_mutex_);
    ep_.request_writer->unregister_instance(&key, dds::HANDLE_NIL);
  }
  if (wrote_progress) {
    msg::ExecutionProgress key;
    key.vehicle_id(vehicle_id);
    std::lock_guard<std::mutex> lock(progress_write_mutex_);
    ep_.progress_writer->unregister_instance(&key, dds::HANDLE_NIL);
  }
}

bool Hub::is_applied(const std::string& vehicle_id) const {
  std::lock_guard<std::mutex> lock(set_mutex_);
  return applied_.count(vehicle_id) != 0;
}

Matches Hub::matches() const {
  std::lock_guard<std::mutex> lock(matches_mutex_);
  return matches_;
}

std::size_t Hub::members() const {
  std::lock_guard<std::mutex> lock(set_mutex_);
  return members_.size();
}

bool Hub::write_request(msg::PullOutRequest* sample) {
  std::lock_guard<std::mutex> lock(request_write_mutex_);
  return ep_.request_writer->write(sample);
}

bool Hub::write_progress(msg::ExecutionProgress* sample) {
  std::lock_guard<std::mutex> lock(progress_write_mutex_);
  return ep_.progress_writer->write(sample);
}

void Hub::run() {
  dds::WaitSet waitset;
  waitset.attach_condition(ep_.request_writer->get_statuscondition());
  waitset.attach_condition(ep_.progress_writer->get_statuscondition());
  waitset.attach_condition(wake_);
  dds::ConditionSeq active;
  SteadyClock::time_point last_apply{};
  while (!stop_.load()) {
    auto wait = std::chrono::duration_cast<std::chrono::nanoseconds>(kDispatchPeriod);
    bool dirty = false;
    SteadyClock::time_point last_change{};
    {
      std::lock_guard<std::mutex> lock(set_mutex_);
      dirty = dirty_;
      last_change = last_change_;
    }
    if (dirty) {
      // The first set once Clients stopped coming (create_readers), later ones at most every
      // kApplyInterval.
      const auto due = ep_.path_reader == nullptr ? last_change + kApplyInterval : last_apply + kApplyInterval;
      const auto now = SteadyClock::now();
      if (due <= now) {
        const bool first = ep_.path_reader == nullptr;
        apply_set();
        last_apply = now;
        if (first && ep_.path_reader != nullptr) {
          waitset.attach_condition(ep_.path_reader->get_statuscondition());
          waitset.attach_condition(ep_.status_reader->get_statuscondition());
        }
      } else {
        wait = std::chrono::duration_cast<std::chrono::nanoseconds>(due - now);
      }
    }
    take_and_route();
    if (update_matches()) {
      std::lock_guard<std::mutex> lock(routes_mutex_);
      for (const auto& [id, sink] : routes_) sink->wake();
    }
    waitset.wait(active, eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(wait.count() / 1000000000),
                                                        static_cast<std::uint32_t>(wait.count() % 1000000000)));
    wake_.set_trigger_value(false);
  }
  waitset.detach_condition(wake_);
  waitset.detach_condition(ep_.progress_writer->get_statuscondition());
  waitset.detach_condition(ep_.request_writer->get_statuscondition());
  if (ep_.path_reader != nullptr) {
    waitset.detach_condition(ep_.status_reader->get_statuscondition());
    waitset.detach_condition(ep_.path_reader->get_statuscondition());
  }
}

void Hub::apply_set() {
  std::vector<std::string> ids;
  {
    std::lock_guard<std::mutex> lock(set_mutex_);
    ids.assign(members_.begin(), members_.end());
    dirty_ = false;
  }
  const std::vector<std::string> parameters = idl::encode_vehicle_set(ids);
  bool path_ok = false;
  bool status_ok = false;
  if (ep_.path_reader == nullptr) {
    try {
      create_readers(parameters);
      path_ok = status_ok = true;
    } catch (const ClientError& e) {
      EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, e.what());
      // Whatever was created goes; the next round tries again.
      if (ep_.path_reader != nullptr) ep_.subscriber->delete_datareader(ep_.path_reader);
      if (ep_.status_reader != nullptr) ep_.subscriber->delete_datareader(ep_.status_reader);
      if (ep_.path_filter != nullptr) participant_->delete_contentfilteredtopic(ep_.path_filter);
      if (ep_.status_filter != nullptr) participant_->delete_contentfilteredtopic(ep_.status_filter);
      ep_.path_reader = ep_.status_reader = nullptr;
      ep_.path_filter = ep_.status_filter = nullptr;
    }
  } else {
    path_ok = ep_.path_filter->set_expression_parameters(parameters) == ReturnCode::RETCODE_OK;
    status_ok = ep_.status_filter->set_expression_parameters(parameters) == ReturnCode::RETCODE_OK;
  }
  if (!path_ok || !status_ok) {
    // Cannot happen within kVehicleSetCapacityBytes; try again at the next round.
    EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "cannot set the vehicle set filter of " << ids.size() << " vehicles");
    std::lock_guard<std::mutex> lock(set_mutex_);
    dirty_ = true;
    return;
  }
  {
    std::lock_guard<std::mutex> lock(set_mutex_);
    applied_ = std::set<std::string>(ids.begin(), ids.end());
  }
  std::lock_guard<std::mutex> lock(routes_mutex_);
  for (const auto& [id, sink] : routes_) sink->wake();
}

void Hub::take_and_route() {
  if (ep_.path_reader == nullptr) return;
  const auto route = [this](const std::string& vehicle_id, auto&& push) {
    std::lock_guard<std::mutex> lock(routes_mutex_);
    auto it = routes_.find(vehicle_id);
    if (it != routes_.end()) push(it->second);
  };
  msg::PullOutPath path_sample;
  dds::SampleInfo info;
  while (ep_.path_reader->take_next_sample(&path_sample, &info) == ReturnCode::RETCODE_OK) {
    if (!info.valid_data) continue;  // instance disposed / writer gone: nothing to deliver
    try {
      auto path = std::make_shared<const PullOutPath>(idl::from_msg(path_sample));
      route(path->vehicle_id, [&](VehicleSink* sink) { sink->push_path(path); });
    } catch (const std::exception& e) {
      EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "dropped a path sample that could not be converted: " << e.what());
    }
  }
  msg::PullOutStatus status_sample;
  while (ep_.status_reader->take_next_sample(&status_sample, &info) == ReturnCode::RETCODE_OK) {
    if (!info.valid_data) continue;
    try {
      auto status = std::make_shared<const PullOutStatus>(idl::from_msg(status_sample));
      route(status->vehicle_id, [&](VehicleSink* sink) { sink->push_status(status); });
    } catch (const std::exception& e) {
      EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "dropped a status sample that could not be converted: " << e.what());
    }
  }
}

bool Hub::update_matches() {
  dds::PublicationMatchedStatus request_matched;
  dds::PublicationMatchedStatus progress_matched;
  dds::SubscriptionMatchedStatus path_matched;
  dds::SubscriptionMatchedStatus status_matched;
  // This thread alone reads them (reading resets the change counts and the wait set trigger).
  ep_.request_writer->get_publication_matched_status(request_matched);
  ep_.progress_writer->get_publication_matched_status(progress_matched);
  if (ep_.path_reader != nullptr) {
    ep_.path_reader->get_subscription_matched_status(path_matched);
    ep_.status_reader->get_subscription_matched_status(status_matched);
  }
  std::lock_guard<std::mutex> lock(matches_mutex_);
  const Matches before = matches_;
  matches_.request = request_matched.current_count;
  matches_.progress = progress_matched.current_count;
  matches_.path = path_matched.current_count;
  matches_.status = status_matched.current_count;
  if (request_matched.total_count_change > 0) ++matches_.request_epoch;
  return before.request != matches_.request || before.progress != matches_.progress || before.path != matches_.path ||
         before.status != matches_.status || before.request_epoch != matches_.request_epoch;
}

}  // namespace client_detail

// ------------------------------------------------------------------------------------------------
// Construction and destruction

Client::Impl::Impl(std::shared_ptr<client_detail::SharedParticipant> shared, ClientOptions options)
    : options_(std::move(options)) {
  if (shared) {
    if (!options_.security_dir.empty()) {
      throw std::invalid_argument(
          "ClientOptions.security_dir: not supported on a shared ClientParticipant (credentials belong to a "
          "participant)");
    }
    // The participant's: client.hpp says these fields are ignored on a shared participant.
    options_.domain_id = shared->domain_id();
    options_.profiles_file = shared->profiles_file();
  }
  validate_options(options_);
  if (!shared) {
    shared = std::make_shared<client_detail::SharedParticipant>(options_.domain_id, options_.profiles_file,
                                                                options_.participant_profile, options_.security_dir);
  }
  serial_ = shared->claim(options_.vehicle_id);  // throws for a vehicle already on it
  claimed_ = true;
  shared_ = std::move(shared);
  participant_ = shared_->participant();
  try {
    create_entities();
    dispatcher_ = std::thread([this] { run(); });
  } catch (...) {
    destroy_entities();
    throw;
  }
}

Client::Impl::~Impl() {
  stop_.store(true);
  wake_dispatcher();
  if (dispatcher_.joinable()) dispatcher_.join();
  state_cv_.notify_all();
  destroy_entities();
}

void Client::Impl::create_entities() {
  // On a ClientParticipant's shared endpoints when its set filter has room; else endpoints of its
  // own (as a single-vehicle Client).
  if (client_detail::Hub* hub = shared_->hub(); hub != nullptr && hub->add(options_.vehicle_id, this)) {
    hub_ = hub;
    return;
  }
  std::lock_guard<std::mutex> lock(shared_->entities_mutex());
  const bool secure = !options_.security_dir.empty();
  dds::Topic* request_topic = shared_->request_topic();
  dds::Topic* progress_topic = shared_->progress_topic();
  dds::Topic* path_topic = shared_->path_topic();
  dds::Topic* status_topic = shared_->status_topic();

  // With security, this vehicle's partition (the only one its permissions grant).
  dds::PublisherQos publisher_qos = dds::PUBLISHER_QOS_DEFAULT;
  dds::SubscriberQos subscriber_qos = dds::SUBSCRIBER_QOS_DEFAULT;
  if (secure) {
    publisher_qos.partition().push_back(options_.vehicle_id.c_str());
    subscriber_qos.partition().push_back(options_.vehicle_id.c_str());
  }
  ep_.publisher = participant_->create_publisher(publisher_qos);
  ep_.subscriber = participant_->create_subscriber(subscriber_qos);
  if (ep_.publisher == nullptr || ep_.subscriber == nullptr)
    throw ClientError("cannot create a DDS publisher/subscriber");

  ep_.request_writer =
      ep_.publisher->create_datawriter(request_topic, writer_qos(client_detail::kRequestWriterProfile));
  if (ep_.request_writer == nullptr) throw ClientError("cannot create the pullout/request writer");
  ep_.progress_writer =
      ep_.publisher->create_datawriter(progress_topic, writer_qos(client_detail::kProgressWriterProfile));
  if (ep_.progress_writer == nullptr) throw ClientError("cannot create the pullout/progress writer");
  ep_.path_reader =
      create_reply_reader(path_topic, client_detail::kPathReaderProfile, kPathReaderDepth, &ep_.path_filter);
  ep_.status_reader =
      create_reply_reader(status_topic, client_detail::kStatusReaderProfile, kStatusReaderDepth, &ep_.status_filter);
  ep_.path_reader->get_statuscondition().set_enabled_statuses(dds::StatusMask::data_available()
                                                              << dds::StatusMask::subscription_matched());
  ep_.status_reader->get_statuscondition().set_enabled_statuses(dds::StatusMask::data_available()
                                                                << dds::StatusMask::subscription_matched());
  ep_.request_writer->get_statuscondition().set_enabled_statuses(dds::StatusMask::publication_matched());
  ep_.progress_writer->get_statuscondition().set_enabled_statuses(dds::StatusMask::publication_matched());
}

dds::DataReader* Client::Impl::create_reply_reader(dds::Topic* topic, const char* profile, int depth,
                                                   dds::ContentFilteredTopic** filter) {
  const std::string topic_name = topic->get_name();
  // The name only has to be unique within the participant (serial_: one per client on it).
  dds::ContentFilteredTopic* filtered = participant_->create_contentfilteredtopic(
      topic_name + "/vehicle_" + std::to_string(serial_), topic, idl::kVehicleFilterExpression, {options_.vehicle_id},
      idl::kVehicleFilterClass);
  if (filtered == nullptr) throw ClientError("cannot create the vehicle filter on " + topic_name);
  *filter = filtered;
  dds::DataReader* reader = ep_.subscriber->create_datareader(filtered, reader_qos(profile, depth));
  if (reader == nullptr) throw ClientError("cannot create the " + topic_name + " reader");
  return reader;
}

dds::DataWriterQos Client::Impl::writer_qos(const char* profile) const {
  dds::DataWriterQos qos = client_detail::command_writer_qos();
  if (!options_.profiles_file.empty()) {
    dds::DataWriterQos from_profile;
    if (ep_.publisher->get_datawriter_qos_from_profile(profile, from_profile) == ReturnCode::RETCODE_OK) {
      qos = from_profile;
    }
  }
  return qos;
}

dds::DataReaderQos Client::Impl::reader_qos(const char* profile, int depth) const {
  dds::DataReaderQos qos = client_detail::reply_reader_qos(depth);
  if (!options_.profiles_file.empty()) {
    dds::DataReaderQos from_profile;
    if (ep_.subscriber->get_datareader_qos_from_profile(profile, from_profile) == ReturnCode::RETCODE_OK) {
      qos = from_profile;
    }
  }
  return qos;
}

void Client::Impl::destroy_entities() noexcept {
  if (!shared_) return;
  if (hub_ != nullptr) {
    hub_->remove(options_.vehicle_id, wrote_request_.load(), wrote_progress_.load());
    hub_ = nullptr;
  }
  {
    // Only this client's entities: the other clients on the participant keep theirs. Readers
    // before their content-filtered topics.
    std::lock_guard<std::mutex> lock(shared_->entities_mutex());
    if (participant_ != nullptr) ep_.destroy(*participant_);
  }
  if (claimed_) shared_->release(options_.vehicle_id);
  claimed_ = false;
  participant_ = nullptr;
  shared_.reset();  // the participant goes with its last client
}

// ------------------------------------------------------------------------------------------------
// Writing

std::uint64_t Client::Impl::send(PullOutRequest request) {
  // The vehicle's own profile or dimensions, unless this request names another.
  if (request.vehicle_profile.empty() && !request.vehicle) {
    request.vehicle_profile = options_.vehicle_profile;
    request.vehicle = options_.vehicle;
  }
  std::uint64_t id = 0;
  std::uint64_t previous = 0;
  const std::int64_t now = system_now_ns();
  std::lock_guard<std::mutex> write_lock(write_mutex_);
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    // Strictly increasing, and above any id a previous run issued before now (clock seeded).
    id = std::max(last_request_id_ + 1, static_cast<std::uint64_t>(std::max<std::int64_t>(now, 1)));
    last_request_id_ = id;
    previous = current_request_id_;
    // Current before the write, so that a reply racing the write's return is recognised.
    current_request_id_ = id;
    sent_any_ = true;
  }
  request.vehicle_id = options_.vehicle_id;
  request.request_id = id;
  request.stamp_ns = now;
  auto sample = std::make_shared<msg::PullOutRequest>(idl::to_msg(request));
  if (!write_request(sample.get())) {
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (current_request_id_ == id) current_request_id_ = previous;
    throw ClientError("cannot write request " + std::to_string(id) +
                      " (DDS write failed: sample too large for the type or transport, or writer error)");
  }
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    const auto written = SteadyClock::now();
    // A reply that raced the write's return may already have answered it.
    Pending pending{id, std::move(sample), written, written};
    for (const auto& item : recent_paths_) pending.path_seen = pending.path_seen || item.value->request_id == id;
    for (const auto& item : recent_statuses_) {
      pending.status_seen =
          pending.status_seen || (item.value->request_id == id && item.value->state != ExecutionState::kPlanning);
    }
    pending_ = std::move(pending);
    update_answered_locked();
  }
  wake_dispatcher();  // schedules the first re-send
  return id;
}

void Client::Impl::resend_pending(std::uint64_t id) {
  std::lock_guard<std::mutex> write_lock(write_mutex_);
  std::shared_ptr<const msg::PullOutRequest> sample;
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    // Checked under write_mutex_: a send() that replaced it meanwhile has already written.
    if (!resend_pending_locked(id, SteadyClock::now())) return;
    sample = pending_.sample;
    pending_.last_write = SteadyClock::now();
  }
  // write() takes a non-const pointer but does not modify the sample.
  if (!write_request(const_cast<msg::PullOutRequest*>(sample.get()))) {
    EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "re-sending request " << id << " failed (DDS write)");
  }
}

bool Client::Impl::resend_pending_locked(std::uint64_t request_id, SteadyClock::time_point now) const {
  return pending_.id != 0 && pending_.id == request_id && pending_.id == current_request_id_ && !pending_.answered &&
         now < pending_.sent_at + options_.resend_window;
}

bool Client::Impl::give_up_locked(std::uint64_t request_id, SteadyClock::time_point now) const {
  return service_state_ == ServiceState::kLost && !resend_pending_locked(request_id, now);
}

SteadyClock::time_point Client::Impl::recheck_locked(std::uint64_t request_id, SteadyClock::time_point deadline) const {
  if (pending_.id != request_id || pending_.answered) return deadline;
  const auto window_end = pending_.sent_at + options_.resend_window;
  return SteadyClock::now() < window_end ? std::min(deadline, window_end) : deadline;
}

bool Client::Impl::stale_locked(const Received<PullOutStatus>& item) const {
  return item.seq <= stale_status_seq_ && item.value->state == ExecutionState::kPlanning;
}

SteadyClock::time_point Client::Impl::update_service_and_resend() {
  client_detail::Matches m;
  bool matched_new_reader = false;
  bool in_filter = true;
  if (hub_ != nullptr) {
    m = hub_->matches();
    matched_new_reader = m.request_epoch != request_epoch_;
    request_epoch_ = m.request_epoch;
    in_filter = hub_->is_applied(options_.vehicle_id);
  } else {
    dds::PublicationMatchedStatus request_matched;
    dds::PublicationMatchedStatus progress_matched;
    dds::SubscriptionMatchedStatus path_matched;
    dds::SubscriptionMatchedStatus status_matched;
    // Reading a status also resets its trigger in the wait set.
    ep_.request_writer->get_publication_matched_status(request_matched);
    ep_.progress_writer->get_publication_matched_status(progress_matched);
    ep_.path_reader->get_subscription_matched_status(path_matched);
    ep_.status_reader->get_subscription_matched_status(status_matched);
    m.request = request_matched.current_count;
    m.progress = progress_matched.current_count;
    m.path = path_matched.current_count;
    m.status = status_matched.current_count;
    matched_new_reader = request_matched.total_count_change > 0;
  }
  const bool connected = m.request > 0 && m.progress > 0 && m.path > 0 && m.status > 0 && in_filter;
  const auto now = SteadyClock::now();
  std::uint64_t resend_id = 0;
  SteadyClock::time_point next = now + kDispatchPeriod;
  bool changed = false;
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    // A new reader of requests (a service that came back, or a second one): the volatile topic
    // gives it nothing that was written before, so the pending request goes again now.
    const bool new_reader = m.request > request_matches_ || matched_new_reader;
    changed = m.request != request_matches_;  // wait_for_services counts them
    request_matches_ = m.request;
    if (connected && service_state_ != ServiceState::kConnected) {
      service_state_ = ServiceState::kConnected;
      changed = true;
    } else if (!connected && service_state_ == ServiceState::kConnected) {
      service_state_ = ServiceState::kLost;
      stale_status_seq_ = status_seq_;
      changed = true;
    }
    if (resend_pending_locked(pending_.id, now)) {
      const auto due = pending_.last_write + options_.resend_period;
      if ((new_reader && m.request > 0) || (due <= now && m.request > 0)) {
        resend_id = pending_.id;
        next = std::min(next, now + options_.resend_period);
      } else {
        next = std::min(next, std::max(due, now + std::chrono::milliseconds(1)));
      }
    }
  }
  if (changed) state_cv_.notify_all();
  if (resend_id != 0) resend_pending(resend_id);
  return next;
}

void Client::Impl::report_progress(ExecutionProgress progress) {
  progress.vehicle_id = options_.vehicle_id;
  if (progress.request_id == 0) {
    progress.request_id = current_request_id();
    if (progress.request_id == 0) throw std::logic_error("report_progress: no current request to report on");
  }
  if (progress.stamp_ns == 0) progress.stamp_ns = system_now_ns();
  msg::ExecutionProgress sample = idl::to_msg(progress);
  wrote_progress_.store(true);  // before the write: a destroyed client unregisters the instance
  const bool written = hub_ != nullptr ? hub_->write_progress(&sample) : ep_.progress_writer->write(&sample);
  if (!written) throw ClientError("cannot write progress for request " + std::to_string(progress.request_id));
}

bool Client::Impl::write_request(msg::PullOutRequest* sample) {
  if (hub_ == nullptr) return ep_.request_writer->write(sample);
  wrote_request_.store(true);  // before the write: a destroyed client unregisters the instance
  return hub_->write_request(sample);
}

void Client::Impl::push_path(std::shared_ptr<const PullOutPath> path) {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    inbox_paths_.push_back(std::move(path));
  }
  wake_dispatcher();
}

void Client::Impl::push_status(std::shared_ptr<const PullOutStatus> status) {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    inbox_statuses_.push_back(std::move(status));
  }
  wake_dispatcher();
}

// ------------------------------------------------------------------------------------------------
// Callbacks and the client's thread

template <typename T>
void Client::Impl::replace_callback(CallbackSlot<T>& slot, std::function<void(const T&)> callback) {
  std::function<void(const T&)> previous;  // destroyed after the lock is released
  {
    std::unique_lock<std::mutex> lock(callback_mutex_);
    previous = std::move(slot.callback);
    slot.callback = std::move(callback);
    ++slot.generation;
    slot.delivered_seq = 0;
    // From another thread: return only once a running previous callback has returned. From a
    // callback (the dispatcher), that callback is the one running: it takes effect next delivery.
    // (A later callback that has started meanwhile is not waited for.)
    const std::uint64_t mine = slot.generation;
    if (!on_dispatcher_thread()) {
      callback_cv_.wait(lock, [&] { return slot.running_generation == 0 || slot.running_generation >= mine; });
    }
  }
  wake_dispatcher();  // replays the latest sample to the new callback
}

void Client::Impl::on_path(PathCallback callback) { replace_callback(path_slot_, std::move(callback)); }

void Client::Impl::on_status(StatusCallback callback) { replace_callback(status_slot_, std::move(callback)); }

void Client::Impl::run() {
  dds::WaitSet waitset;
  // With shared endpoints, the Hub wakes this thread (replies, matches).
  const bool own = hub_ == nullptr;
  if (own) {
    waitset.attach_condition(ep_.path_reader->get_statuscondition());
    waitset.attach_condition(ep_.status_reader->get_statuscondition());
    waitset.attach_condition(ep_.request_writer->get_statuscondition());
    waitset.attach_condition(ep_.progress_writer->get_statuscondition());
  }
  waitset.attach_condition(wake_);
  dds::ConditionSeq active;
  SteadyClock::time_point next = SteadyClock::now();
  while (!stop_.load()) {
    // Until the next re-send is due; the bound only limits how long a missed wake-up could delay.
    const auto wait =
        std::clamp<SteadyClock::duration>(next - SteadyClock::now(), std::chrono::milliseconds(1), kDispatchPeriod);
    const auto wait_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
    waitset.wait(active, eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(wait_ns / 1000000000),
                                                        static_cast<std::uint32_t>(wait_ns % 1000000000)));
    wake_.set_trigger_value(false);
    if (stop_.load()) break;
    dispatch_once();
    next = update_service_and_resend();
  }
  waitset.detach_condition(wake_);
  if (own) {
    waitset.detach_condition(ep_.progress_writer->get_statuscondition());
    waitset.detach_condition(ep_.request_writer->get_statuscondition());
    waitset.detach_condition(ep_.status_reader->get_statuscondition());
    waitset.detach_condition(ep_.path_reader->get_statuscondition());
  }
}

std::vector<std::shared_ptr<const PullOutPath>> Client::Impl::take_paths() {
  std::vector<std::shared_ptr<const PullOutPath>> out;
  if (hub_ != nullptr) {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    out.swap(inbox_paths_);
    return out;
  }
  msg::PullOutPath sample;
  dds::SampleInfo info;
  while (ep_.path_reader->take_next_sample(&sample, &info) == ReturnCode::RETCODE_OK) {
    if (!info.valid_data) continue;  // instance disposed / writer gone: nothing to deliver
    try {
      auto path = std::make_shared<PullOutPath>(idl::from_msg(sample));
      // The content filter already dropped other vehicles; this covers encodings it passes.
      if (path->vehicle_id == options_.vehicle_id) out.push_back(std::move(path));
    } catch (const std::exception& e) {
      EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "dropped a path sample that could not be converted: " << e.what());
    }
  }
  return out;
}

std::vector<std::shared_ptr<const PullOutStatus>> Client::Impl::take_statuses() {
  std::vector<std::shared_ptr<const PullOutStatus>> out;
  if (hub_ != nullptr) {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    out.swap(inbox_statuses_);
    return out;
  }
  msg::PullOutStatus sample;
  dds::SampleInfo info;
  while (ep_.status_reader->take_next_sample(&sample, &info) == ReturnCode::RETCODE_OK) {
    if (!info.valid_data) continue;
    try {
      auto status = std::make_shared<PullOutStatus>(idl::from_msg(sample));
      if (status->vehicle_id == options_.vehicle_id) out.push_back(std::move(status));
    } catch (const std::exception& e) {
      EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "dropped a status sample that could not be converted: " << e.what());
    }
  }
  return out;
}

// Invokes the slot's callback with item, unless it was already given to it. Returns false when a
// callback was registered since `generation` was read: the rest of the batch is left to the next
// round, which replays the latest sample to the new callback.
template <typename T>
bool Client::Impl::deliver(CallbackSlot<T>& slot, const Received<T>& item, std::uint64_t generation, const char* what) {
  std::function<void(const T&)> callback;
  {
    std::lock_guard<std::mutex> lock(callback_mutex_);
    if (slot.generation != generation) return false;
    if (!slot.callback || item.seq <= slot.delivered_seq) return true;
    slot.delivered_seq = item.seq;
    callback = slot.callback;  // a copy: the callback may replace itself
    slot.running_generation = generation;
  }
  try {
    callback(*item.value);
  } catch (const std::exception& e) {
    EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "the " << what << " callback threw: " << e.what());
  } catch (...) {
    EPROSIMA_LOG_ERROR(PULLOUT_CLIENT, "the " << what << " callback threw a non-standard exception");
  }
  callback = nullptr;  // the copy goes before running_generation is cleared
  {
    std::lock_guard<std::mutex> lock(callback_mutex_);
    slot.running_generation = 0;
  }
  callback_cv_.notify_all();
  return true;
}

void Client::Impl::dispatch_once() {
  auto paths = take_paths();
  auto statuses = take_statuses();

  std::vector<Received<PullOutPath>> path_out;
  std::vector<Received<PullOutStatus>> status_out;
  std::uint64_t path_generation = 0;
  std::uint64_t status_generation = 0;
  {
    // Both locks, so that a registration sees each sample either as gathered for delivery here
    // (with the generation read here) or as still to replay.
    std::lock_guard<std::mutex> callbacks(callback_mutex_);
    std::lock_guard<std::mutex> lock(state_mutex_);
    path_generation = path_slot_.generation;
    status_generation = status_slot_.generation;
    // Replay of the latest sample to a newly registered callback.
    if (path_slot_.callback && !recent_paths_.empty() && recent_paths_.back().seq > path_slot_.delivered_seq) {
      path_out.push_back(recent_paths_.back());
    }
    if (status_slot_.callback && !recent_statuses_.empty() &&
        recent_statuses_.back().seq > status_slot_.delivered_seq) {
      status_out.push_back(recent_statuses_.back());
    }
    for (auto& path : paths) {
      // Before the first send(), follow the request the service last answered (restart case).
      if (!sent_any_) current_request_id_ = path->request_id;
      if (path->request_id == pending_.id) pending_.path_seen = true;
      Received<PullOutPath> item{++path_seq_, std::move(path)};
      if (path_slot_.callback) path_out.push_back(item);
      push_bounded(recent_paths_, std::move(item), kRecentPaths);
    }
    for (auto& status : statuses) {
      if (status->request_id == pending_.id && status->state != ExecutionState::kPlanning) pending_.status_seen = true;
      Received<PullOutStatus> item{++status_seq_, std::move(status)};
      if (status_slot_.callback) status_out.push_back(item);
      push_bounded(recent_statuses_, std::move(item), kRecentStatuses);
    }
    update_answered_locked();
  }
  if (!paths.empty() || !statuses.empty()) state_cv_.notify_all();

  // No lock is held while a callback runs. Paths first: a status announcing execution refers to a
  // path the callback has seen.
  for (const auto& item : path_out) {
    if (!deliver(path_slot_, item, path_generation, "path")) break;
  }
  for (const auto& item : status_out) {
    if (!deliver(status_slot_, item, status_generation, "status")) break;
  }
}

// ------------------------------------------------------------------------------------------------
// Queries and waits

std::optional<PullOutPath> Client::Impl::wait_for_path(std::uint64_t request_id, Duration timeout) const {
  const auto deadline = deadline_after(timeout);
  std::unique_lock<std::mutex> lock(state_mutex_);
  while (true) {
    for (auto it = recent_paths_.rbegin(); it != recent_paths_.rend(); ++it) {
      if (it->value->request_id == request_id) return *it->value;
    }
    const auto now = SteadyClock::now();
    if (stop_.load() || now >= deadline || give_up_locked(request_id, now)) return std::nullopt;
    // The dispatcher notifies on every reply and service change.
    state_cv_.wait_until(lock, recheck_locked(request_id, deadline));
  }
}

std::optional<PullOutStatus> Client::Impl::wait_for_status(std::uint64_t request_id, const StatusPredicate& predicate,
                                                           Duration timeout) const {
  const auto deadline = deadline_after(timeout);
  const auto accepts = [&](const PullOutStatus& s) {
    return s.request_id == request_id && (!predicate || predicate(s));
  };
  std::unique_lock<std::mutex> lock(state_mutex_);
  // The latest status already received for this request (unless stale).
  for (auto it = recent_statuses_.rbegin(); it != recent_statuses_.rend(); ++it) {
    if (it->value->request_id != request_id) continue;
    if (!stale_locked(*it) && accepts(*it->value)) return *it->value;
    break;
  }
  std::uint64_t seen = status_seq_;
  while (true) {
    const auto now = SteadyClock::now();
    if (stop_.load() || now >= deadline || give_up_locked(request_id, now)) return std::nullopt;
    state_cv_.wait_until(lock, recheck_locked(request_id, deadline));
    for (const auto& item : recent_statuses_) {
      if (item.seq > seen && !stale_locked(item) && accepts(*item.value)) return *item.value;
    }
    seen = status_seq_;
  }
}

std::optional<PullOutPath> Client::Impl::latest_path() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (recent_paths_.empty()) return std::nullopt;
  return *recent_paths_.back().value;
}

std::optional<PullOutStatus> Client::Impl::latest_status() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (recent_statuses_.empty() || stale_locked(recent_statuses_.back())) return std::nullopt;
  return *recent_statuses_.back().value;
}

std::size_t Client::Impl::matched_services() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return static_cast<std::size_t>(std::max(request_matches_, 0));
}

ServiceState Client::Impl::service_state() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return service_state_;
}

std::uint64_t Client::Impl::current_request_id() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return current_request_id_;
}

std::optional<std::uint32_t> Client::Impl::current_segment() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (current_request_id_ == 0) return std::nullopt;
  for (auto it = recent_statuses_.rbegin(); it != recent_statuses_.rend(); ++it) {
    const PullOutStatus& status = *it->value;
    if (status.request_id != current_request_id_) continue;
    if (has_path(status.state)) {
      return status.current_path_idx;
    }
    return std::nullopt;
  }
  return std::nullopt;
}

bool Client::Impl::wait_for_services(std::size_t count, Duration timeout) const {
  // The client's thread tracks the matched counts (update_service_and_resend) and notifies.
  const auto deadline = deadline_after(timeout);
  std::unique_lock<std::mutex> lock(state_mutex_);
  const auto ready = [&] {
    return service_state_ == ServiceState::kConnected &&
           static_cast<std::size_t>(std::max(request_matches_, 0)) >= count;
  };
  return state_cv_.wait_until(lock, deadline, [&] { return stop_.load() || ready(); }) && ready();
}

// ------------------------------------------------------------------------------------------------
// Client: forwards to Impl

Client::Client(ClientOptions options) : impl_(std::make_unique<Impl>(nullptr, std::move(options))) {}
Client::Client(ClientParticipant& participant, ClientOptions options)
    : impl_(std::make_unique<Impl>(participant.shared_, std::move(options))) {}
Client::~Client() = default;

std::uint64_t Client::send(PullOutRequest request) { return impl_->send(std::move(request)); }
void Client::report_progress(ExecutionProgress progress) { impl_->report_progress(std::move(progress)); }
void Client::on_path(PathCallback callback) { impl_->on_path(std::move(callback)); }
void Client::on_status(StatusCallback callback) { impl_->on_status(std::move(callback)); }
std::optional<PullOutPath> Client::wait_for_path(std::uint64_t request_id, Duration timeout) const {
  return impl_->wait_for_path(request_id, timeout);
}
std::optional<PullOutStatus> Client::wait_for_status(std::uint64_t request_id, const StatusPredicate& predicate,
                                                     Duration timeout) const {
  return impl_->wait_for_status(request_id, predicate, timeout);
}
std::optional<PullOutPath> Client::latest_path() const { return impl_->latest_path(); }
std::optional<PullOutStatus> Client::latest_status() const { return impl_->latest_status(); }
std::uint64_t Client::current_request_id() const { return impl_->current_request_id(); }
std::optional<std::uint32_t> Client::current_segment() const { return impl_->current_segment(); }
bool Client::wait_for_service(Duration timeout) const { return impl_->wait_for_services(1, timeout); }
bool Client::wait_for_services(std::size_t count, Duration timeout) const {
  return impl_->wait_for_services(count, timeout);
}
ServiceState Client::service_state() const { return impl_->service_state(); }
std::size_t Client::matched_services() const { return impl_->matched_services(); }
const std::string& Client::vehicle_id() const { return impl_->options().vehicle_id; }
int Client::domain_id() const { return impl_->options().domain_id; }

// ------------------------------------------------------------------------------------------------
// ClientParticipant

ClientParticipant::ClientParticipant(ClientParticipantOptions options) {
  if (options.domain_id < 0 || options.domain_id > kMaxDomainId) {
    throw std::invalid_argument("ClientParticipantOptions.domain_id: " + std::to_string(options.domain_id) +
                                " is outside 0.." + std::to_string(kMaxDomainId));
  }
  shared_ = std::make_shared<client_detail::SharedParticipant>(options.domain_id, std::move(options.profiles_file),
                                                               options.participant_profile, std::string(),
                                                               options.shared_endpoints);
}

ClientParticipant::~ClientParticipant() = default;

int ClientParticipant::domain_id() const { return shared_->domain_id(); }
std::size_t ClientParticipant::client_count() const { return shared_->client_count(); }

}  // namespace pullout
