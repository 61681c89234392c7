// What the service's DDS edge does with a sample's bytes, without DDS, for the fuzz targets of
// the request and progress topics (fuzz_request.cpp, fuzz_progress.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "pullout/model/names.hpp"

namespace pullout::fuzz {

// What a reader does with a received sample: decode it with the guarded type support, compute its
// key, and drop a vehicle id longer than kMaxVehicleIdBytes (as the service does). False: dropped.
template <typename Type, typename Message>
bool receive(Type& type, const std::uint8_t* data, std::size_t size, Message& sample) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  if (!type.deserialize(&payload, &sample)) return false;
  eprosima::fastrtps::rtps::InstanceHandle_t handle;
  if (!type.getKey(&sample, &handle, false)) return false;
  return sample.vehicle_id().size() <= kMaxVehicleIdBytes;
}

// What a writer does with an outgoing sample: size it, serialize it, compute its key.
template <typename Type, typename Message>
void publish(Type& type, Message message) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&message)());
  type.serialize(&message, &payload);
  eprosima::fastrtps::rtps::InstanceHandle_t handle;
  type.getKey(&message, &handle, false);
}

}  // namespace pullout::fuzz
