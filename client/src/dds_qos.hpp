// QoS of the client's DDS entities: the built-in loopback-only defaults, and the profile names an
// XML profiles file may override them with. Internal to the client library.
#pragma once

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

namespace pullout::client_detail {

inline constexpr const char* kRequestTopic = "pullout/request";
inline constexpr const char* kPathTopic = "pullout/path";
inline constexpr const char* kStatusTopic = "pullout/status";
inline constexpr const char* kProgressTopic = "pullout/progress";

// Profile names looked up in a user profiles file (shared with config/dds/*.xml).
inline constexpr const char* kRequestWriterProfile = "pullout_request_writer";
inline constexpr const char* kProgressWriterProfile = "pullout_progress_writer";
inline constexpr const char* kPathReaderProfile = "pullout_path_reader";
inline constexpr const char* kStatusReaderProfile = "pullout_status_reader";

// Loopback only: built-in transports (UDP on every interface, shared memory) off, one UDPv4
// transport whitelisted to 127.0.0.1 with 4 MiB socket buffers (large paths, see
// fastdds_notes.md). Independent of FASTRTPS_DEFAULT_PROFILES_FILE.
eprosima::fastdds::dds::DomainParticipantQos loopback_participant_qos();

// pullout/request and pullout/progress: reliable, volatile, keep last 1 (per vehicle).
eprosima::fastdds::dds::DataWriterQos command_writer_qos();

// pullout/path and pullout/status readers: reliable, transient local (late joiners get the
// vehicle's latest sample), keep last `depth`.
eprosima::fastdds::dds::DataReaderQos reply_reader_qos(int depth);

}  // namespace pullout::client_detail
