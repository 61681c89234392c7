#include "dds_qos.hpp"

#include <memory>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

namespace pullout::client_detail {

namespace dds = eprosima::fastdds::dds;

namespace {
constexpr std::uint32_t kSocketBufferBytes = 4u * 1024u * 1024u;
}  // namespace

dds::DomainParticipantQos loopback_participant_qos() {
  // Start from the specification defaults, not get_default_participant_qos(): the latter may come
  // from an XML file named by the environment, and these defaults must stay loopback-only.
  dds::DomainParticipantQos qos;
  qos.name("pullout_client");
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.emplace_back("127.0.0.1");
  // The kernel caps these silently at net.core.{r,w}mem_max; a smaller buffer only costs latency.
  udp->sendBufferSize = kSocketBufferBytes;
  udp->receiveBufferSize = kSocketBufferBytes;
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.push_back(udp);
  // As config/dds/loopback.xml: the service notices a dead client within about 2 s.
  qos.wire_protocol().builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(2, 0);
  qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod =
      eprosima::fastrtps::Duration_t(0, 500000000);
  return qos;
}

dds::DataWriterQos command_writer_qos() {
  dds::DataWriterQos qos;
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = 1;
  // Repair a lost fragment of a large request quickly instead of after the default 3 s.
  qos.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 200000000);
  // The types are unbounded: allocate samples as they come instead of preallocating the generated
  // maximum size per history slot.
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
  return qos;
}

dds::DataReaderQos reply_reader_qos(int depth) {
  dds::DataReaderQos qos;
  // Readers default to best effort in Fast DDS: set reliability explicitly.
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = depth;
  // Not DYNAMIC*: a Fast DDS 2.9.1 reader with a dynamic payload pool never accepts the key-only
  // sample of an unregister (the service unregisters an evicted vehicle's path and status) and
  // then holds back every later sample of that writer (config/dds/loopback.xml).
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  return qos;
}

}  // namespace pullout::client_detail
