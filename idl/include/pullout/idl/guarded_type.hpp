// Type support for the pullout topics that never lets an exception escape into Fast DDS.
//
// The code fastddsgen 2.3.0 generates catches only fastcdr's NotEnoughMemoryException. A sample
// whose sequence length field is huge makes deserialize() throw std::bad_alloc or
// std::length_error instead, and a key (vehicle_id) longer than 255 bytes makes getKey() throw;
// both would terminate the process from a Fast DDS thread. GuardedType turns every exception into
// the "failed" return value, so Fast DDS drops the sample (reader) or write() returns false
// (writer).
//
// Usage: eprosima::fastdds::dds::TypeSupport type(make_guarded_type<msg::PullOutRequestPubSubType>());
#pragma once

#include <memory>

#include <fastdds/dds/topic/TopicDataType.hpp>

#include "pullout/msg/pulloutPubSubTypes.h"

namespace pullout::idl {

template <typename Generated>
class GuardedType : public Generated {
 public:
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    try {
      return Generated::serialize(data, payload);
    } catch (...) {
      return false;
    }
  }

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      return Generated::deserialize(payload, data);
    } catch (...) {
      return false;
    }
  }

  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool force_md5) override {
    try {
      return Generated::getKey(data, handle, force_md5);
    } catch (...) {
      return false;
    }
  }
};

// A heap-allocated guarded type, for TypeSupport's owning pointer constructor (TypeSupport takes
// ownership of the pointer it is given).
template <typename Generated>
eprosima::fastdds::dds::TopicDataType* make_guarded_type() {
  return std::make_unique<GuardedType<Generated>>().release();
}

}  // namespace pullout::idl
