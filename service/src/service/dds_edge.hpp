// The service's DDS entities: one participant, the four pullout topics, readers for requests and
// progress, writers for paths and statuses. QoS comes from the XML profiles file named in the
// config (config/dds/*.xml), by profile name:
//
//   participant  <dds.participant_profile>
//   readers      pullout_request_reader, pullout_progress_reader
//   writers      pullout_path_writer, pullout_status_writer
//
// The path and status writers filter at the writer: the vehicle content filter factory
// (pullout/idl/vehicle_filter.hpp) is registered on the participant, and each writer evaluates
// the filters of up to idl::kMaxWriterReaderFilters remote readers (set in code: Fast DDS 2.9's
// XML has no element for it), so each vehicle's samples are sent to that vehicle's readers only
// (a single-vehicle client's reader, or a ClientParticipant's reader whose filter is the set of its
// vehicles, updated in place by the factory when the client announces a new set).
// Fast DDS 2.9.1 changes those filters on a discovery thread without the writer's lock; a gate
// (FilterGate in dds_edge.cpp) keeps the writes out of such a change.
//
// Construction loads the XML and creates everything, or throws DdsSetupError naming the step that
// failed (after deleting whatever was created). Destruction deletes every entity and the
// participant, which also removes the participant's shared-memory files.
//
// Secure mode (config.security_dir set; pullout/idl/security.hpp): the participant authenticates
// with those credentials, the readers take every partition ("*"), and each vehicle's path and
// status are written by writers of their own in the partition named after the vehicle id
// (created on the vehicle's first reply, deleted by forget_vehicle). A sample is the vehicle's
// only if its writer is in that vehicle's partition (sender_may_act_for), which the vehicle's
// permissions document alone grants.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <fastdds/rtps/common/Guid.h>
#include <fastdds/dds/core/condition/GuardCondition.hpp>

#include "pullout/config/config.hpp"
#include "pullout/idl/topics.hpp"
#include "pullout/idl/vehicle_filter.hpp"
#include "service/outbox.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class Publisher;
class Subscriber;
class Topic;
class DataReader;
class DataWriter;
struct SampleInfo;
}  // namespace eprosima::fastdds::dds

namespace pullout::service {

// The participant user data that marks a pullout service (other services look for it), and a
// service in replica mode (service.replica.enabled).
inline constexpr std::string_view kServiceUserData = "pullout_service";
inline constexpr std::string_view kReplicaUserData = "pullout_service replica";

// A participant's GUID prefix: who a replica is on the domain.
using ParticipantId = eprosima::fastrtps::rtps::GuidPrefix_t;

class DdsSetupError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using idl::kPathTopic;
using idl::kPathWriterProfile;
using idl::kProgressReaderProfile;
using idl::kProgressTopic;
using idl::kRequestReaderProfile;
using idl::kRequestTopic;
using idl::kStatusTopic;
using idl::kStatusWriterProfile;

class DdsEdge final : public Outbox {
 public:
  // `config.profiles_file` must name a readable Fast DDS XML file (load_config resolves it), or be
  // empty: the built-in profiles (builtin_profiles.hpp).
  // `replica`: service.replica; enabled, the participant is marked as a replica, announces the
  // replica lease, and the edge reads the path and status topics too (replica_*_reader).
  explicit DdsEdge(const DdsConfig& config, const ReplicaConfig& replica = {});
  ~DdsEdge() override;
  DdsEdge(const DdsEdge&) = delete;
  DdsEdge& operator=(const DdsEdge&) = delete;

  bool publish_path(const PullOutPath& path) override;
  bool publish_status(const PullOutStatus& status) override;
  // Unregisters the vehicle's path and status instances (with the writers' default
  // autodispose_unregistered_instances, readers see them disposed): the writers free the
  // instances, so that max_instances bounds the vehicles served at once, not over a lifetime.
  // Secure mode: deletes the vehicle's own writers instead (its readers see the instances with
  // no writer). Thread-safe.
  bool forget_vehicle(const std::string& vehicle_id) override;

  // How many other pullout_service participants are on the domain now that are duplicates (both
  // serving every vehicle): every other service when this one is not a replica, the services
  // that are not replicas when it is. Each one that appears is logged as a warning. Thread-safe.
  std::size_t other_services() const;
  // Replica mode: this participant, and the other replicas on the domain now. Thread-safe.
  ParticipantId self() const;
  std::vector<ParticipantId> replicas() const;
  // Replica mode: the replicas that left since the last call (dispatcher thread); their leaving
  // triggers replica_condition().
  std::vector<ParticipantId> take_departed_replicas();
  eprosima::fastdds::dds::GuardCondition& replica_condition() { return replica_wake_; }
  bool replica() const { return replica_; }

  // The smallest resource_limits.max_instances of the four endpoints (0: unlimited): the most
  // vehicles the service can hold sessions for.
  int instance_capacity() const;

  // Whether DDS Security is on (per-vehicle partitions).
  bool secure() const { return secure_; }
  // Whether the writer of a sample (its SampleInfo) may speak for `vehicle_id`: always without
  // security; with security only a writer whose partitions are exactly {vehicle_id}. A sample
  // from a writer not (yet) discovered is refused. Thread-safe.
  bool sender_may_act_for(const eprosima::fastdds::dds::SampleInfo& info, const std::string& vehicle_id) const;
  // Whether the instance of a sample (its SampleInfo) is the one its writer meant. Not for the
  // key-only sample (unregister, dispose) of a writer of another DDS vendor: Fast DDS 2.9.1 drops
  // the serialized key such a writer sends (or reads up to 16 bytes of it as a key hash) and then
  // takes the instance of the last sample the reader deserialized, another vehicle's. Writers of
  // Fast DDS send the key hash, which is right. Thread-safe.
  bool instance_state_trusted(const eprosima::fastdds::dds::SampleInfo& info) const;
  // Secure mode: triggered when a vehicle's reader is discovered; the dispatcher then calls
  // prepare_discovered_vehicles (which creates that vehicle's writers and resets the trigger).
  eprosima::fastdds::dds::GuardCondition& discovery_condition() { return discovery_wake_; }
  void prepare_discovered_vehicles();

  // For the dispatcher thread only (take samples, wait on their status conditions).
  eprosima::fastdds::dds::DataReader& request_reader() { return *request_reader_; }
  eprosima::fastdds::dds::DataReader& progress_reader() { return *progress_reader_; }
  // Replica mode only (null otherwise): every vehicle's path and status, as the replicas publish them.
  eprosima::fastdds::dds::DataReader* replica_path_reader() { return replica_path_reader_; }
  eprosima::fastdds::dds::DataReader* replica_status_reader() { return replica_status_reader_; }

 private:
  class Discovery;        // the participant listener: discovered writers' partitions, other vendors' participants
  class FilterGate;       // keeps the writes out of Fast DDS's changes to the writers' reader filters
  class MatchedListener;  // the filtering writers' listener: ends such a change (FilterGate::release)
  // One vehicle's writers in secure mode, in a publisher whose partition is the vehicle id.
  struct VehicleWriters {
    eprosima::fastdds::dds::Publisher* publisher{nullptr};
    eprosima::fastdds::dds::DataWriter* path{nullptr};
    eprosima::fastdds::dds::DataWriter* status{nullptr};
  };

  void create_entities(const DdsConfig& config, const ReplicaConfig& replica);
  void check_qos() const;
  void destroy() noexcept;
  // The writer for this vehicle's paths (`path` true) or statuses; null when it cannot be created.
  eprosima::fastdds::dds::DataWriter* writer_for(const std::string& vehicle_id, bool path);
  void delete_vehicle_writers(VehicleWriters& writers) noexcept;
  void forget_secure_vehicle(const std::string& vehicle_id);

  // Registered with the participant: declared first, destroyed after it (with the gate and the
  // writers' listener, which the factory and the writers call).
  std::unique_ptr<FilterGate> filter_gate_;
  std::unique_ptr<MatchedListener> matched_listener_;
  idl::VehicleIdFilterFactory filter_factory_;
  eprosima::fastdds::dds::DomainParticipant* participant_{nullptr};
  eprosima::fastdds::dds::Publisher* publisher_{nullptr};
  eprosima::fastdds::dds::Subscriber* subscriber_{nullptr};
  eprosima::fastdds::dds::Topic* request_topic_{nullptr};
  eprosima::fastdds::dds::Topic* path_topic_{nullptr};
  eprosima::fastdds::dds::Topic* status_topic_{nullptr};
  eprosima::fastdds::dds::Topic* progress_topic_{nullptr};
  eprosima::fastdds::dds::DataReader* request_reader_{nullptr};
  eprosima::fastdds::dds::DataReader* progress_reader_{nullptr};
  eprosima::fastdds::dds::DataReader* replica_path_reader_{nullptr};
  eprosima::fastdds::dds::DataReader* replica_status_reader_{nullptr};
  eprosima::fastdds::dds::DataWriter* path_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* status_writer_{nullptr};
  // The generated type support keeps per-type scratch buffers (key serialisation), so writes of
  // one type from several threads are serialised here.
  std::mutex path_mutex_;
  std::mutex status_mutex_;

  bool secure_{false};
  bool replica_{false};
  eprosima::fastdds::dds::GuardCondition discovery_wake_;
  eprosima::fastdds::dds::GuardCondition replica_wake_;
  std::unique_ptr<Discovery> discovery_;
  std::mutex vehicle_writers_mutex_;  // guards vehicle_writers_
  std::unordered_map<std::string, VehicleWriters> vehicle_writers_;
};

}  // namespace pullout::service
