#include "service/dds_edge.hpp"

#include <exception>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include <fastdds/rtps/builtin/data/ParticipantProxyData.h>
#include <fastdds/rtps/builtin/data/ReaderProxyData.h>
#include <fastdds/rtps/builtin/data/WriterProxyData.h>
#include <fastdds/rtps/common/InstanceHandle.h>
#include <spdlog/spdlog.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/dds/topic/qos/TopicQos.hpp>

#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/idl/security.hpp"
#include "pullout/model/names.hpp"
#include "service/builtin_profiles.hpp"

namespace pullout::service {
namespace dds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;

namespace {

constexpr bool same_names(const char* a, const char* b) {
  for (; *a != '\0' || *b != '\0'; ++a, ++b) {
    if (*a != *b) return false;
  }
  return true;
}
constexpr bool same_security_files() {
  for (std::size_t i = 0; i < kSecurityFileNames.size(); ++i) {
    if (!same_names(kSecurityFileNames[i], idl::kSecurityFiles[i])) return false;
  }
  return kSecurityFileNames.size() == std::size(idl::kSecurityFiles);
}
static_assert(same_security_files(), "config.hpp's kSecurityFileNames must list pullout/idl/security.hpp's files");

// Fewer instances than this in a reader or writer history means a fleet larger than that cannot
// be served (Fast DDS's default is 10).
constexpr int kMinExpectedInstances = 64;

dds::Topic* create_topic(dds::DomainParticipant& participant, const char* name, dds::TopicDataType* type_ptr) {
  dds::TypeSupport type(type_ptr);  // takes ownership
  if (type.register_type(&participant) != ReturnCode_t::RETCODE_OK) {
    throw DdsSetupError(std::string("cannot register type ") + type.get_type_name());
  }
  dds::Topic* topic = participant.create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) throw DdsSetupError(std::string("cannot create topic ") + name);
  return topic;
}

const char* reliability_name(dds::ReliabilityQosPolicyKind k) {
  return k == dds::RELIABLE_RELIABILITY_QOS ? "RELIABLE" : "BEST_EFFORT";
}

const char* durability_name(dds::DurabilityQosPolicyKind k) {
  switch (k) {
    case dds::VOLATILE_DURABILITY_QOS:
      return "VOLATILE";
    case dds::TRANSIENT_LOCAL_DURABILITY_QOS:
      return "TRANSIENT_LOCAL";
    case dds::TRANSIENT_DURABILITY_QOS:
      return "TRANSIENT";
    case dds::PERSISTENT_DURABILITY_QOS:
      return "PERSISTENT";
  }
  return "?";
}

// Warns when a profile's QoS differs from DESIGN.md's topics table. Not an error: an operator may
// tune a profile on purpose, but should hear about it.
template <typename Qos>
void check_endpoint_qos(const char* profile, const Qos& qos, dds::DurabilityQosPolicyKind durability) {
  if (qos.reliability().kind != dds::RELIABLE_RELIABILITY_QOS) {
    spdlog::warn("DDS profile {}: reliability is {}, the pullout topics need RELIABLE", profile,
                 reliability_name(qos.reliability().kind));
  }
  if (qos.durability().kind != durability) {
    spdlog::warn("DDS profile {}: durability is {}, expected {}", profile, durability_name(qos.durability().kind),
                 durability_name(durability));
  }
  if (qos.history().kind != dds::KEEP_LAST_HISTORY_QOS || qos.history().depth != 1) {
    spdlog::warn("DDS profile {}: history is not KEEP_LAST 1 (the latest sample per vehicle)", profile);
  }
  const int instances = qos.resource_limits().max_instances;
  if (instances > 0 && instances < kMinExpectedInstances) {
    spdlog::warn("DDS profile {}: resource_limits.max_instances = {} caps the number of vehicles served", profile,
                 instances);
  }
}

}  // namespace

// Fast DDS 2.9.1 keeps a writer's writer-side reader filters in a map that DataWriter::write (and
// unregister_instance) walks under the writer's lock, while a discovery thread adds a reader's
// entry (DISCOVERED_READER) or erases it (REMOVED_READER) after releasing that lock
// (DataWriterImpl::process_reader_filter_info / remove_reader_filter, called from
// StatefulWriter::matched_reader_add / matched_reader_remove "without locks taken"; upstream
// fixed the removal for 3.0 by taking the writer's lock there). A write during such a change walks
// a map being rebalanced and freed: the service crashed in ReaderFilterCollection::
// update_filter_info when hundreds of vehicles left (bench/RESULTS.md, Load).
//
// The gate keeps the service's writes out of those changes. The only code of ours that runs inside
// one is the filter factory: Fast DDS calls create_content_filter right before adding an entry and
// delete_content_filter right before erasing one, on the discovery thread, and after the change
// returns it calls the writer's on_publication_matched on the same thread (EDP pairing/unpairing),
// then, for a removal, the participant's on_subscriber_discovery. So the factory's hook holds the
// gate (after waiting for writes in progress), and those callbacks release it; writes wait while
// a discovery thread holds it. Several discovery threads may hold it at once (they never wait for
// each other: one may hold the PDP lock the other needs before its release).
//
// A change without a matched callback after it (a known reader whose QoS changed so that its
// filter is dropped or first added) releases at that thread's next callback; writes stop waiting
// for such a hold after kStaleHold, so a missed release delays writes, it never stops them.
class DdsEdge::FilterGate {
 public:
  static constexpr std::chrono::milliseconds kStaleHold{500};

  // On a discovery thread, from the filter factory: a filter map is about to change.
  void hold() {
    if (own_call_) return;  // our own writer deletion (destroy, forget_secure_vehicle)
    std::unique_lock<std::mutex> lock(mutex_);
    const auto self = std::this_thread::get_id();
    auto it = holds_.find(self);
    if (it != holds_.end()) {
      it->second = Clock::now();
      return;
    }
    ++pending_;
    changed_.wait(lock, [&] { return writing_ == 0; });
    --pending_;
    holds_.emplace(self, Clock::now());
  }

  // On a discovery thread, after Fast DDS's change: no-op when this thread holds nothing.
  void release() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (holds_.erase(std::this_thread::get_id()) != 0) changed_.notify_all();
  }

  // A write section (RAII): waits until no discovery thread holds the gate or wants to.
  class Write {
   public:
    explicit Write(FilterGate& gate) : gate_(gate) { gate_.enter(); }
    ~Write() { gate_.leave(); }
    Write(const Write&) = delete;
    Write& operator=(const Write&) = delete;

   private:
    FilterGate& gate_;
  };

  // Marks the calling thread as deleting writers (their filters are deleted without a change
  // that a discovery callback would end).
  class OwnCall {
   public:
    OwnCall() { own_call_ = true; }
    ~OwnCall() { own_call_ = false; }
    OwnCall(const OwnCall&) = delete;
    OwnCall& operator=(const OwnCall&) = delete;
  };

 private:
  using Clock = std::chrono::steady_clock;

  void enter() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      // Holds older than kStaleHold are not waited for (see above).
      Clock::time_point newest{};
      for (const auto& [thread, since] : holds_) newest = std::max(newest, since);
      const bool held = !holds_.empty() && Clock::now() - newest < kStaleHold;
      if (pending_ == 0 && !held) break;
      if (held) {
        changed_.wait_until(lock, newest + kStaleHold);
      } else {
        changed_.wait(lock);
      }
    }
    ++writing_;
  }

  void leave() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (--writing_ == 0) changed_.notify_all();
  }

  static thread_local bool own_call_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::thread::id, Clock::time_point> holds_;
  int pending_{0};
  int writing_{0};
};

thread_local bool DdsEdge::FilterGate::own_call_ = false;

// The filtering writers' listener: Fast DDS calls on_publication_matched on the discovery thread
// right after it added or removed a reader, and its filter (FilterGate).
class DdsEdge::MatchedListener final : public dds::DataWriterListener {
 public:
  explicit MatchedListener(FilterGate& gate) : gate_(gate) {}
  void on_publication_matched(dds::DataWriter* /*writer*/, const dds::PublicationMatchedStatus& /*info*/) override {
    gate_.release();
  }

 private:
  FilterGate& gate_;
};

// Remembers the partitions of every remote writer the participant discovers (with security, the
// access control plugin has checked them against the writer's permissions before the match).
//
// It also remembers the participants of other DDS vendors (by the vendor id of their discovery
// data): Fast DDS 2.9.1 cannot tell which instance their unregister or dispose names
// (instance_state_trusted).
//
// It also notes the partition of every remote path or status reader (a vehicle's: access control
// has checked that its permissions grant that partition), so that the dispatcher creates that
// vehicle's writers before its first reply (its client waits for them to match).
//
// In every mode it also watches for other pullout_service participants on the domain (their user
// data is kServiceUserData): two services both plan and publish for every vehicle, and the last
// writer wins. Each one that appears is logged as a warning, and counted (other_services).
class DdsEdge::Discovery final : public dds::DomainParticipantListener {
 public:
  // secure: the partitions of readers and writers matter only in secure mode. gate: released by
  // every discovery callback (FilterGate).
  Discovery(dds::GuardCondition& wake, bool secure, int domain_id, FilterGate& gate, bool replica,
            dds::GuardCondition& replica_wake)
      : wake_(wake),
        secure_(secure),
        domain_id_(domain_id),
        gate_(gate),
        replica_(replica),
        replica_wake_(replica_wake) {}

  void on_participant_discovery(dds::DomainParticipant* /*participant*/,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
    gate_.release();
    const auto& guid_prefix = info.info.m_guid.guidPrefix;
    std::lock_guard<std::mutex> lock(mutex_);
    if (info.status == Status::DISCOVERED_PARTICIPANT &&
        info.info.m_VendorId != eprosima::fastrtps::rtps::c_VendorId_eProsima) {
      remember_foreign(guid_prefix);
      return;
    }
    if (info.status == Status::REMOVED_PARTICIPANT || info.status == Status::DROPPED_PARTICIPANT) {
      if (const auto r = replicas_.find(guid_prefix); r != replicas_.end()) {
        spdlog::info("replica '{}' left DDS domain {} ({}; {} other replica(s) remain)", r->second, domain_id_,
                     info.status == Status::DROPPED_PARTICIPANT ? "its lease expired" : "it said goodbye",
                     replicas_.size() - 1);
        replicas_.erase(r);
        departed_.push_back(guid_prefix);
        replica_wake_.set_trigger_value(true);
        return;
      }
      const auto it = services_.find(guid_prefix);
      if (it == services_.end()) return;
      spdlog::info("the other pullout_service '{}' left DDS domain {} ({} other service(s) remain)", it->second,
                   domain_id_, services_.size() - 1);
      services_.erase(it);
      return;
    }
    const auto& data = info.info.m_userData.data_vec();
    const std::string user_data(data.begin(), data.end());
    if (user_data != kServiceUserData && user_data != kReplicaUserData) return;
    if (services_.count(guid_prefix) != 0 || replicas_.count(guid_prefix) != 0) return;
    const std::string name = info.info.m_participantName.to_string();
    std::ostringstream guid;
    guid << guid_prefix;
    if (replica_ && user_data == kReplicaUserData) {
      replicas_.emplace(guid_prefix, name);
      spdlog::info("replica '{}' (GUID prefix {}) joined DDS domain {} ({} other replica(s))", name, guid.str(),
                   domain_id_, replicas_.size());
      return;
    }
    services_.emplace(guid_prefix, name);
    spdlog::warn(
        "another pullout_service is on DDS domain {}: participant '{}' (GUID prefix {}). Both plan and publish for "
        "every vehicle and the last writer wins; stop one of them or give each its own domain "
        "(observability.on_duplicate_service)",
        domain_id_, name, guid.str());
  }

  // How many other pullout_service participants are on the domain now (replicas of a replica
  // not counted).
  std::size_t other_services() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return services_.size();
  }
  std::vector<ParticipantId> replicas() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<ParticipantId> out;
    out.reserve(replicas_.size());
    for (const auto& r : replicas_) out.push_back(r.first);
    return out;
  }
  std::vector<ParticipantId> take_departed() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(departed_, {});
  }

  void on_subscriber_discovery(dds::DomainParticipant* /*participant*/,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    using Status = eprosima::fastrtps::rtps::ReaderDiscoveryInfo;
    gate_.release();  // after a removal; before an addition this thread holds nothing
    if (!secure_ || info.status == Status::REMOVED_READER) return;
    const std::string topic = info.info.topicName().to_string();
    if (topic != kPathTopic && topic != kStatusTopic) return;
    const auto& names = info.info.m_qos.m_partition.names();
    if (names.size() != 1 || !idl::is_literal_partition_name(names.front())) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pending_readers_.size() >= kMaxPendingVehicles) return;
      pending_readers_.insert(names.front());
    }
    wake_.set_trigger_value(true);
  }

  // The vehicles whose readers were discovered since the last call.
  std::set<std::string> take_pending() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(pending_readers_, {});
  }

  void on_publisher_discovery(dds::DomainParticipant* /*participant*/,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    using Status = eprosima::fastrtps::rtps::WriterDiscoveryInfo;
    gate_.release();
    if (!secure_) return;  // only secure mode asks writer_partition_is
    const auto& guid = info.info.guid();
    std::lock_guard<std::mutex> lock(mutex_);
    if (info.status == Status::REMOVED_WRITER) {
      partitions_.erase(guid);
      return;
    }
    partitions_[guid] = info.info.m_qos.m_partition.names();
  }

  // Whether the writer with this handle belongs to a participant of another DDS vendor.
  bool foreign_writer(const eprosima::fastrtps::rtps::InstanceHandle_t& handle) const {
    const auto guid = eprosima::fastrtps::rtps::iHandle2GUID(handle);
    std::lock_guard<std::mutex> lock(mutex_);
    return foreign_.count(guid.guidPrefix) != 0;
  }

  // Whether the writer with this handle is known and its partitions are exactly {name}.
  bool writer_partition_is(const eprosima::fastrtps::rtps::InstanceHandle_t& handle, const std::string& name) const {
    const auto guid = eprosima::fastrtps::rtps::iHandle2GUID(handle);
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = partitions_.find(guid);
    return it != partitions_.end() && it->second.size() == 1 && it->second.front() == name;
  }

 private:
  // Kept after the participant leaves: a sample of its writers may still be waiting in a reader.
  // Bounded: the oldest are forgotten first. Called with mutex_ held.
  void remember_foreign(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
    if (!foreign_.insert(prefix).second) return;
    foreign_order_.push_back(prefix);
    if (foreign_order_.size() > kMaxForeignParticipants) {
      foreign_.erase(foreign_order_.front());
      foreign_order_.pop_front();
    }
  }

  // Bounds the set between two dispatcher wake-ups (only authenticated participants add to it).
  static constexpr std::size_t kMaxPendingVehicles = 65536;
  static constexpr std::size_t kMaxForeignParticipants = 65536;
  dds::GuardCondition& wake_;
  const bool secure_;
  const int domain_id_;
  FilterGate& gate_;
  const bool replica_;
  dds::GuardCondition& replica_wake_;
  mutable std::mutex mutex_;
  // Replica mode: the other replicas now (GUID prefix -> name), and those that left since the
  // dispatcher last asked.
  std::map<ParticipantId, std::string> replicas_;
  std::vector<ParticipantId> departed_;
  std::map<eprosima::fastrtps::rtps::GUID_t, std::vector<std::string>> partitions_;
  std::set<std::string> pending_readers_;
  // Other services: GUID prefix -> participant name.
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, std::string> services_;
  // Participants of other DDS vendors, oldest first forgotten.
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> foreign_;
  std::deque<eprosima::fastrtps::rtps::GuidPrefix_t> foreign_order_;
};

DdsEdge::DdsEdge(const DdsConfig& config, const ReplicaConfig& replica) {
  try {
    create_entities(config, replica);
  } catch (...) {
    destroy();
    throw;
  }
  check_qos();
}

DdsEdge::~DdsEdge() { destroy(); }

void DdsEdge::create_entities(const DdsConfig& config, const ReplicaConfig& replica) {
  auto* factory = dds::DomainParticipantFactory::get_instance();
  // Fast DDS only logs a missing or malformed XML file and then silently uses its defaults (all
  // interfaces, shared memory): that must stop the service instead.
  if (config.profiles_file.empty()) {
    const std::string xml(kBuiltinProfilesXml);
    if (factory->load_XML_profiles_string(xml.c_str(), xml.size()) != ReturnCode_t::RETCODE_OK) {
      throw DdsSetupError("cannot load the built-in DDS profiles");
    }
  } else if (factory->load_XML_profiles_file(config.profiles_file) != ReturnCode_t::RETCODE_OK) {
    throw DdsSetupError("cannot load DDS profiles file " + config.profiles_file);
  }
  const std::string profiles = describe_profiles(config);
  secure_ = !config.security_dir.empty();
  dds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(config.participant_profile, qos) != ReturnCode_t::RETCODE_OK) {
    throw DdsSetupError("no participant profile '" + config.participant_profile + "' in " + profiles);
  }
  // Marks this participant as a pullout service for the other services' Discovery; a name that
  // says where it runs, unless the profile gives one.
  replica_ = replica.enabled;
  const std::string_view mark = replica_ ? kReplicaUserData : kServiceUserData;
  qos.user_data().data_vec(std::vector<eprosima::fastrtps::rtps::octet>(mark.begin(), mark.end()));
  if (replica_) {
    // The other replicas take this one's vehicles over once its lease expires: a short lease,
    // announced four times per lease, makes that a fraction of a second after a SIGKILL.
    auto& discovery = qos.wire_protocol().builtin.discovery_config;
    const int ms = replica.lease_duration_ms;
    discovery.leaseDuration =
        eprosima::fastrtps::Duration_t(ms / 1000, static_cast<std::uint32_t>(ms % 1000) * 1'000'000);
    const int announce = ms / 4;
    discovery.leaseDuration_announcementperiod =
        eprosima::fastrtps::Duration_t(announce / 1000, static_cast<std::uint32_t>(announce % 1000) * 1'000'000);
  }
  // Other services name this one by its participant name when they see it on the domain: a name
  // left unset, Fast DDS's default or the one every shipped profile gives every participant
  // ("pullout", clients too) would name no process, so the service names itself by host and pid.
  const std::string profile_name = qos.name().to_string();
  if (profile_name.empty() || profile_name == "RTPSParticipant" || profile_name == "pullout") {
    char host[256] = {};
    if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
    qos.name(("pullout_service@" + std::string(host) + " pid " + std::to_string(getpid())).substr(0, 255));
  }
  if (secure_) {
    try {
      idl::add_security_properties(config.security_dir, qos);
    } catch (const std::invalid_argument& e) {
      throw DdsSetupError(std::string("dds.security_dir: ") + e.what());
    }
  }
  // The discovery callbacks are not masked by the StatusMask: none keeps every other status
  // (data available, matches) off the listener, on the dispatcher's wait set.
  filter_gate_ = std::make_unique<FilterGate>();
  matched_listener_ = std::make_unique<MatchedListener>(*filter_gate_);
  filter_factory_.set_change_hook([gate = filter_gate_.get()] { gate->hold(); });
  discovery_ =
      std::make_unique<Discovery>(discovery_wake_, secure_, config.domain_id, *filter_gate_, replica_, replica_wake_);
  participant_ = factory->create_participant(config.domain_id, qos, discovery_.get(), dds::StatusMask::none());
  if (participant_ == nullptr) {
    if (secure_) {
      throw DdsSetupError("cannot create the secure DDS participant with the credentials in " + config.security_dir +
                          " (profile '" + config.participant_profile + "' of " + profiles + ", domain " +
                          std::to_string(config.domain_id) + "): see the SECURITY errors of Fast DDS above");
    }
    throw DdsSetupError("cannot create the DDS participant from profile '" + config.participant_profile + "' of " +
                        profiles + " on domain " + std::to_string(config.domain_id));
  }

  request_topic_ = create_topic(*participant_, kRequestTopic, idl::make_guarded_type<msg::PullOutRequestPubSubType>());
  path_topic_ = create_topic(*participant_, kPathTopic, idl::make_guarded_type<msg::PullOutPathPubSubType>());
  status_topic_ = create_topic(*participant_, kStatusTopic, idl::make_guarded_type<msg::PullOutStatusPubSubType>());
  progress_topic_ =
      create_topic(*participant_, kProgressTopic, idl::make_guarded_type<msg::ExecutionProgressPubSubType>());

  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  dds::SubscriberQos subscriber_qos = dds::SUBSCRIBER_QOS_DEFAULT;
  if (secure_) subscriber_qos.partition().push_back("*");  // every vehicle's partition
  subscriber_ = participant_->create_subscriber(subscriber_qos);
  if (publisher_ == nullptr || subscriber_ == nullptr) throw DdsSetupError("cannot create the publisher/subscriber");

  const auto missing_profile = [&](const char* what, const char* profile) {
    return DdsSetupError(std::string("cannot create the ") + what + " from profile '" + profile + "' (is it in " +
                         profiles + "?)");
  };
  // Readers and writers are created without listeners: samples are taken on the dispatcher thread.
  const auto reader = [&](dds::Topic* topic, const char* what, const char* profile) {
    dds::DataReaderQos qos;
    if (subscriber_->get_datareader_qos_from_profile(profile, qos) != ReturnCode_t::RETCODE_OK) {
      throw missing_profile(what, profile);
    }
    // A Fast DDS 2.9.1 reader with a dynamic payload pool cannot take the empty payload of an
    // unregister or dispose, NACKs it for ever and holds back every later sample of that writer
    // (README, Interoperability): a profile that asks for one gets PREALLOCATED_WITH_REALLOC.
    auto& policy = qos.endpoint().history_memory_policy;
    if (policy == eprosima::fastrtps::rtps::DYNAMIC_RESERVE_MEMORY_MODE ||
        policy == eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE) {
      spdlog::warn(
          "DDS profile {}: a DYNAMIC* history memory policy stalls the reader on unregister and dispose samples "
          "(Fast DDS 2.9.1); using PREALLOCATED_WITH_REALLOC",
          profile);
      policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    }
    dds::DataReader* created = subscriber_->create_datareader(topic, qos, nullptr, dds::StatusMask::none());
    if (created == nullptr) throw missing_profile(what, profile);
    return created;
  };
  request_reader_ = reader(request_topic_, "request reader", kRequestReaderProfile);
  progress_reader_ = reader(progress_topic_, "progress reader", kProgressReaderProfile);
  if (replica_) {
    // What the replicas told their vehicles (TRANSIENT_LOCAL: a replica that starts late gets the
    // latest of every vehicle), to take a vehicle over with exactly that.
    replica_path_reader_ = reader(path_topic_, "replica path reader", idl::kPathReaderProfile);
    replica_status_reader_ = reader(status_topic_, "replica status reader", idl::kStatusReaderProfile);
  }
  // Writer-side filtering: the factory must be known before a reader is discovered.
  if (participant_->register_content_filter_factory(idl::kVehicleFilterClass, &filter_factory_) !=
      ReturnCode_t::RETCODE_OK) {
    throw DdsSetupError("cannot register the vehicle content filter factory");
  }
  const auto filtering_writer = [&](dds::Topic* topic, const char* what, const char* profile) {
    dds::DataWriterQos qos;
    if (publisher_->get_datawriter_qos_from_profile(profile, qos) != ReturnCode_t::RETCODE_OK) {
      throw missing_profile(what, profile);
    }
    qos.writer_resource_limits().reader_filters_allocation.maximum = idl::kMaxWriterReaderFilters;
    qos.writer_resource_limits().reader_filters_allocation.increment = 64;
    if (!qos.liveliness().lease_duration.is_infinite()) {
      // Fast DDS 2.9 turns writer-side filtering off for a writer with a finite liveliness lease.
      spdlog::warn(
          "DDS profile {}: a finite liveliness lease disables writer-side filtering: every vehicle "
          "receives every vehicle's samples",
          profile);
    }
    // The listener only ends filter changes (FilterGate); matches stay on the status condition.
    dds::DataWriter* writer =
        publisher_->create_datawriter(topic, qos, matched_listener_.get(), dds::StatusMask::publication_matched());
    if (writer == nullptr) throw missing_profile(what, profile);
    return writer;
  };
  path_writer_ = filtering_writer(path_topic_, "path writer", kPathWriterProfile);
  status_writer_ = filtering_writer(status_topic_, "status writer", kStatusWriterProfile);
}

void DdsEdge::check_qos() const {
  check_endpoint_qos(kRequestReaderProfile, request_reader_->get_qos(), dds::VOLATILE_DURABILITY_QOS);
  const auto progress = progress_reader_->get_qos();
  if (progress.reliability().kind != dds::RELIABLE_RELIABILITY_QOS) {
    spdlog::warn("DDS profile {}: reliability is {}, the pullout topics need RELIABLE", kProgressReaderProfile,
                 reliability_name(progress.reliability().kind));
  }
  check_endpoint_qos(kPathWriterProfile, path_writer_->get_qos(), dds::TRANSIENT_LOCAL_DURABILITY_QOS);
  check_endpoint_qos(kStatusWriterProfile, status_writer_->get_qos(), dds::TRANSIENT_LOCAL_DURABILITY_QOS);
}

void DdsEdge::destroy() noexcept {
  if (participant_ == nullptr) return;
  const FilterGate::OwnCall own_call;  // the writers' filters are deleted with them
  try {
    if (participant_->delete_contained_entities() != ReturnCode_t::RETCODE_OK) {
      spdlog::error("DDS shutdown: cannot delete the participant's entities");
    }
    if (dds::DomainParticipantFactory::get_instance()->delete_participant(participant_) != ReturnCode_t::RETCODE_OK) {
      spdlog::error("DDS shutdown: cannot delete the participant");
    }
  } catch (const std::exception& e) {
    spdlog::error("DDS shutdown: {}", e.what());
  }
  participant_ = nullptr;
  request_reader_ = progress_reader_ = nullptr;
  replica_path_reader_ = replica_status_reader_ = nullptr;
  path_writer_ = status_writer_ = nullptr;
  std::lock_guard<std::mutex> lock(vehicle_writers_mutex_);
  vehicle_writers_.clear();  // deleted with the participant's entities
}

std::size_t DdsEdge::other_services() const { return discovery_ ? discovery_->other_services() : 0; }

ParticipantId DdsEdge::self() const {
  return participant_ != nullptr ? participant_->guid().guidPrefix : ParticipantId{};
}

std::vector<ParticipantId> DdsEdge::replicas() const {
  return discovery_ ? discovery_->replicas() : std::vector<ParticipantId>{};
}

std::vector<ParticipantId> DdsEdge::take_departed_replicas() {
  replica_wake_.set_trigger_value(false);
  return discovery_ ? discovery_->take_departed() : std::vector<ParticipantId>{};
}

void DdsEdge::prepare_discovered_vehicles() {
  if (!secure_) return;
  discovery_wake_.set_trigger_value(false);
  for (const std::string& vehicle_id : discovery_->take_pending()) {
    if (writer_for(vehicle_id, true) != nullptr) spdlog::debug("vehicle '{}': writers ready", vehicle_id);
  }
}

bool DdsEdge::instance_state_trusted(const dds::SampleInfo& info) const {
  return info.valid_data || !discovery_->foreign_writer(info.publication_handle);
}

bool DdsEdge::sender_may_act_for(const dds::SampleInfo& info, const std::string& vehicle_id) const {
  if (!secure_) return true;
  return discovery_->writer_partition_is(info.publication_handle, vehicle_id);
}

dds::DataWriter* DdsEdge::writer_for(const std::string& vehicle_id, bool path) {
  if (!secure_) return path ? path_writer_ : status_writer_;
  std::lock_guard<std::mutex> lock(vehicle_writers_mutex_);
  auto it = vehicle_writers_.find(vehicle_id);
  if (it == vehicle_writers_.end()) {
    if (!idl::is_literal_partition_name(vehicle_id)) {
      spdlog::error("vehicle '{}': an id with * ? [ ] or \\ cannot name a DDS partition; not answered", vehicle_id);
      return nullptr;
    }
    dds::PublisherQos qos = dds::PUBLISHER_QOS_DEFAULT;
    qos.partition().push_back(vehicle_id.c_str());
    VehicleWriters writers;
    writers.publisher = participant_->create_publisher(qos);
    if (writers.publisher != nullptr) {
      writers.path = writers.publisher->create_datawriter_with_profile(
          path_topic_, kPathWriterProfile, matched_listener_.get(), dds::StatusMask::publication_matched());
      writers.status = writers.publisher->create_datawriter_with_profile(
          status_topic_, kStatusWriterProfile, matched_listener_.get(), dds::StatusMask::publication_matched());
    }
    if (writers.path == nullptr || writers.status == nullptr) {
      spdlog::error("vehicle '{}': cannot create its path/status writers in partition '{}' (permissions?)", vehicle_id,
                    vehicle_id);
      delete_vehicle_writers(writers);
      return nullptr;
    }
    it = vehicle_writers_.emplace(vehicle_id, writers).first;
  }
  return path ? it->second.path : it->second.status;
}

void DdsEdge::delete_vehicle_writers(VehicleWriters& writers) noexcept {
  if (writers.publisher == nullptr) return;
  if (writers.publisher->delete_contained_entities() != ReturnCode_t::RETCODE_OK ||
      participant_->delete_publisher(writers.publisher) != ReturnCode_t::RETCODE_OK) {
    spdlog::error("DDS: cannot delete a vehicle's publisher");
  }
  writers = VehicleWriters{};
}

void DdsEdge::forget_secure_vehicle(const std::string& vehicle_id) {
  // The path and status locks: no write of this vehicle is in progress on its writers.
  std::scoped_lock writes(path_mutex_, status_mutex_);
  std::lock_guard<std::mutex> lock(vehicle_writers_mutex_);
  const FilterGate::OwnCall own_call;  // the writers' filters are deleted with them
  const auto it = vehicle_writers_.find(vehicle_id);
  if (it == vehicle_writers_.end()) return;
  delete_vehicle_writers(it->second);
  vehicle_writers_.erase(it);
}

int DdsEdge::instance_capacity() const {
  int capacity = 0;
  const auto take = [&](int instances) {
    if (instances > 0 && (capacity == 0 || instances < capacity)) capacity = instances;
  };
  take(request_reader_->get_qos().resource_limits().max_instances);
  take(progress_reader_->get_qos().resource_limits().max_instances);
  take(path_writer_->get_qos().resource_limits().max_instances);
  take(status_writer_->get_qos().resource_limits().max_instances);
  return capacity;
}

bool DdsEdge::forget_vehicle(const std::string& vehicle_id) {
  if (secure_) {
    forget_secure_vehicle(vehicle_id);
    return true;
  }
  bool ok = true;
  {
    msg::PullOutPath key;
    key.vehicle_id(vehicle_id);
    std::lock_guard<std::mutex> lock(path_mutex_);
    const FilterGate::Write gate(*filter_gate_);
    const ReturnCode_t rc = path_writer_->unregister_instance(&key, dds::HANDLE_NIL);
    if (rc != ReturnCode_t::RETCODE_OK) {
      spdlog::error("unregister {} instance of vehicle '{}' failed (code {})", kPathTopic, vehicle_id, rc());
      ok = false;
    }
  }
  {
    msg::PullOutStatus key;
    key.vehicle_id(vehicle_id);
    std::lock_guard<std::mutex> lock(status_mutex_);
    const FilterGate::Write gate(*filter_gate_);
    const ReturnCode_t rc = status_writer_->unregister_instance(&key, dds::HANDLE_NIL);
    if (rc != ReturnCode_t::RETCODE_OK) {
      spdlog::error("unregister {} instance of vehicle '{}' failed (code {})", kStatusTopic, vehicle_id, rc());
      ok = false;
    }
  }
  return ok;
}

bool DdsEdge::publish_path(const PullOutPath& path) {
  msg::PullOutPath sample = idl::to_msg(path);
  bool ok = false;
  {
    std::lock_guard<std::mutex> lock(path_mutex_);
    try {
      dds::DataWriter* writer = writer_for(path.vehicle_id, true);
      const FilterGate::Write gate(*filter_gate_);
      ok = writer != nullptr && writer->write(&sample);
    } catch (const std::exception& e) {
      spdlog::error("write {}: {}", kPathTopic, e.what());
    }
  }
  if (!ok) {
    spdlog::error("write {} failed: vehicle '{}' request {} ({} segments)", kPathTopic, path.vehicle_id,
                  path.request_id, path.partial_paths.size());
  }
  return ok;
}

bool DdsEdge::publish_status(const PullOutStatus& status) {
  msg::PullOutStatus sample = idl::to_msg(status);
  bool ok = false;
  {
    std::lock_guard<std::mutex> lock(status_mutex_);
    try {
      dds::DataWriter* writer = writer_for(status.vehicle_id, false);
      const FilterGate::Write gate(*filter_gate_);
      ok = writer != nullptr && writer->write(&sample);
    } catch (const std::exception& e) {
      spdlog::error("write {}: {}", kStatusTopic, e.what());
    }
  }
  if (!ok) {
    spdlog::error("write {} failed: vehicle '{}' request {} state {}", kStatusTopic, status.vehicle_id,
                  status.request_id, to_string(status.state));
  }
  return ok;
}

}  // namespace pullout::service
