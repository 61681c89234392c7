// QoS of the client's DDS entities: the built-in loopback-only defaults, and the profile names an
// XML profiles file may override them with. Internal to the client library.
#pragma once

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "pullout/idl/topics.hpp"

namespace pullout::client_detail {

// Topic names, and the profile names looked up in a user profiles file (config/dds/*.xml).
using idl::kPathReaderProfile;
using idl::kPathTopic;
using idl::kProgressTopic;
using idl::kProgressWriterProfile;
using idl::kRequestTopic;
using idl::kRequestWriterProfile;
using idl::kStatusReaderProfile;
using idl::kStatusTopic;

// Loopback only: built-in transports (UDP on every interface, shared memory) off, one UDPv4
// transport whitelisted to 127.0.0.1 with 4 MiB socket buffers (large paths, see
// fastdds_notes.md), participant lease 2 s announced every 0.5 s (as config/dds/loopback.xml).
// Independent of FASTRTPS_DEFAULT_PROFILES_FILE.
eprosima::fastdds::dds::DomainParticipantQos loopback_participant_qos();

// pullout/request and pullout/progress: reliable, volatile, keep last 1 (per vehicle).
eprosima::fastdds::dds::DataWriterQos command_writer_qos();

// pullout/path and pullout/status readers: reliable, transient local (late joiners get the
// vehicle's latest sample), keep last `depth`.
eprosima::fastdds::dds::DataReaderQos reply_reader_qos(int depth);

}  // namespace pullout::client_detail
