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
// XML has no element for it), so each vehicle's samples are sent to that vehicle's readers only.
//
// Construction loads the XML and creates everything, or throws DdsSetupError naming the step that
// failed (after deleting whatever was created). Destruction deletes every entity and the
// participant, which also removes the participant's shared-memory files.
#pragma once

#include <mutex>
#include <stdexcept>
#include <string>

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
}  // namespace eprosima::fastdds::dds

namespace pullout::service {

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
  // `config.profiles_file` must name a readable Fast DDS XML file (load_config resolves it).
  explicit DdsEdge(const DdsConfig& config);
  ~DdsEdge() override;
  DdsEdge(const DdsEdge&) = delete;
  DdsEdge& operator=(const DdsEdge&) = delete;

  bool publish_path(const PullOutPath& path) override;
  bool publish_status(const PullOutStatus& status) override;

  // For the dispatcher thread only (take samples, wait on their status conditions).
  eprosima::fastdds::dds::DataReader& request_reader() { return *request_reader_; }
  eprosima::fastdds::dds::DataReader& progress_reader() { return *progress_reader_; }

 private:
  void create_entities(const DdsConfig& config);
  void check_qos() const;
  void destroy() noexcept;

  // Registered with the participant: declared first, destroyed after it.
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
  eprosima::fastdds::dds::DataWriter* path_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* status_writer_{nullptr};
  // The generated type support keeps per-type scratch buffers (key serialisation), so writes of
  // one type from several threads are serialised here.
  std::mutex path_mutex_;
  std::mutex status_mutex_;
};

}  // namespace pullout::service
