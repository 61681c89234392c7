#include "service/dds_edge.hpp"

#include <exception>

#include <spdlog/spdlog.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/dds/topic/qos/TopicQos.hpp>

#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/model/names.hpp"

namespace pullout::service {
namespace dds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;

namespace {

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

DdsEdge::DdsEdge(const DdsConfig& config) {
  try {
    create_entities(config);
  } catch (...) {
    destroy();
    throw;
  }
  check_qos();
}

DdsEdge::~DdsEdge() { destroy(); }

void DdsEdge::create_entities(const DdsConfig& config) {
  auto* factory = dds::DomainParticipantFactory::get_instance();
  // Fast DDS only logs a missing or malformed XML file and then silently uses its defaults (all
  // interfaces, shared memory): that must stop the service instead.
  if (factory->load_XML_profiles_file(config.profiles_file) != ReturnCode_t::RETCODE_OK) {
    throw DdsSetupError("cannot load DDS profiles file " + config.profiles_file);
  }
  participant_ = factory->create_participant_with_profile(config.domain_id, config.participant_profile);
  if (participant_ == nullptr) {
    throw DdsSetupError("cannot create the DDS participant from profile '" + config.participant_profile + "' of " +
                        config.profiles_file + " on domain " + std::to_string(config.domain_id));
  }

  request_topic_ = create_topic(*participant_, kRequestTopic, idl::make_guarded_type<msg::PullOutRequestPubSubType>());
  path_topic_ = create_topic(*participant_, kPathTopic, idl::make_guarded_type<msg::PullOutPathPubSubType>());
  status_topic_ = create_topic(*participant_, kStatusTopic, idl::make_guarded_type<msg::PullOutStatusPubSubType>());
  progress_topic_ =
      create_topic(*participant_, kProgressTopic, idl::make_guarded_type<msg::ExecutionProgressPubSubType>());

  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) throw DdsSetupError("cannot create the publisher/subscriber");

  const auto missing_profile = [&](const char* what, const char* profile) {
    return DdsSetupError(std::string("cannot create the ") + what + " from profile '" + profile + "' (is it in " +
                         config.profiles_file + "?)");
  };
  // Readers and writers are created without listeners: samples are taken on the dispatcher thread.
  request_reader_ = subscriber_->create_datareader_with_profile(request_topic_, kRequestReaderProfile, nullptr,
                                                                dds::StatusMask::none());
  if (request_reader_ == nullptr) throw missing_profile("request reader", kRequestReaderProfile);
  progress_reader_ = subscriber_->create_datareader_with_profile(progress_topic_, kProgressReaderProfile, nullptr,
                                                                 dds::StatusMask::none());
  if (progress_reader_ == nullptr) throw missing_profile("progress reader", kProgressReaderProfile);
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
    dds::DataWriter* writer = publisher_->create_datawriter(topic, qos, nullptr, dds::StatusMask::none());
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
  path_writer_ = status_writer_ = nullptr;
}

bool DdsEdge::publish_path(const PullOutPath& path) {
  msg::PullOutPath sample = idl::to_msg(path);
  bool ok = false;
  {
    std::lock_guard<std::mutex> lock(path_mutex_);
    try {
      ok = path_writer_->write(&sample);
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
      ok = status_writer_->write(&sample);
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
