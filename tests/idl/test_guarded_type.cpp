// GuardedType: the generated type support with every exception turned into "failed".
#include "pullout/idl/guarded_type.hpp"

#include <cstdint>
#include <exception>
#include <string>

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <gtest/gtest.h>

namespace pullout::idl {
namespace {

using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

TEST(GuardedType, OverlongKeyFailsInsteadOfThrowing) {
  // The generated code serialises the key into a fixed 4 + 255 + 1 byte buffer.
  msg::PullOutRequest request;
  request.vehicle_id(std::string(300, 'v'));
  InstanceHandle_t handle;
  msg::PullOutRequestPubSubType generated;
  EXPECT_ANY_THROW(generated.getKey(&request, &handle, false));
  GuardedType<msg::PullOutRequestPubSubType> guarded;
  EXPECT_FALSE(guarded.getKey(&request, &handle, false));

  request.vehicle_id("car-1");
  EXPECT_TRUE(guarded.getKey(&request, &handle, false));
}

TEST(GuardedType, TruncatedSampleFailsToDeserialize) {
  // A request whose lanes sequence claims 2^31 - 1 elements and then ends.
  SerializedPayload_t payload(1024);
  eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload.data), payload.max_size);
  eprosima::fastcdr::Cdr ser(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
  payload.encapsulation = ser.endianness() == eprosima::fastcdr::Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
  ser.serialize_encapsulation();
  ser << std::string("car-1") << std::uint64_t{1} << std::int32_t{0} << std::uint32_t{0};
  for (int i = 0; i < 15; ++i) ser << 0.0;  // ego pose, velocity, goal pose
  ser << std::uint32_t{0x7FFFFFFF};
  payload.length = static_cast<std::uint32_t>(ser.getSerializedDataLength());

  GuardedType<msg::PullOutRequestPubSubType> guarded;
  msg::PullOutRequest request;
  bool ok = true;
  EXPECT_NO_THROW(ok = guarded.deserialize(&payload, &request));
  EXPECT_FALSE(ok);
}

TEST(GuardedType, ClaimedSequenceLengthAllocatesNoMoreThanThePayload) {
  // An empty request up to its overrides, whose search_priority claims 2^24 planners and then
  // ends. fastddsgen's decoding of a sequence of enumerations resized the vector to the claimed
  // length before reading it, so 4 bytes could make the service allocate and zero up to 16 GB
  // (found by fuzz_request); the decoding must fail having allocated no more than it was sent.
  SerializedPayload_t payload(1024);
  eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload.data), payload.max_size);
  eprosima::fastcdr::Cdr ser(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
  payload.encapsulation = ser.endianness() == eprosima::fastcdr::Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
  ser.serialize_encapsulation();
  ser << std::string("car-1") << std::uint64_t{1} << std::int32_t{0} << std::uint32_t{0};
  for (int i = 0; i < 15; ++i) ser << 0.0;                          // ego pose, velocity, goal pose
  ser << std::uint32_t{0} << std::uint32_t{0} << std::uint32_t{0};  // lanes, route, objects
  for (int i = 0; i < 8; ++i) ser << 0.0;                           // grid resolution, origin
  ser << std::uint32_t{0} << std::uint32_t{0} << std::uint32_t{0};  // grid width, height, data
  ser << (std::uint32_t{1} << 24);                                  // overrides.search_priority
  payload.length = static_cast<std::uint32_t>(ser.getSerializedDataLength());

  GuardedType<msg::PullOutRequestPubSubType> guarded;
  msg::PullOutRequest request;
  bool ok = true;
  EXPECT_NO_THROW(ok = guarded.deserialize(&payload, &request));
  EXPECT_FALSE(ok);
  // 4 bytes per planner.
  EXPECT_LE(request.overrides().search_priority().capacity() * 4, payload.length);
}

TEST(GuardedType, RoundTrip) {
  GuardedType<msg::ExecutionProgressPubSubType> type;
  msg::ExecutionProgress in;
  in.vehicle_id("bus-3");
  in.request_id(17);
  in.velocity_mps(1.5);
  SerializedPayload_t payload(type.getSerializedSizeProvider(&in)());
  ASSERT_TRUE(type.serialize(&in, &payload));
  msg::ExecutionProgress out;
  ASSERT_TRUE(type.deserialize(&payload, &out));
  EXPECT_EQ(out.vehicle_id(), "bus-3");
  EXPECT_EQ(out.request_id(), 17u);
  EXPECT_EQ(out.velocity_mps(), 1.5);
}

}  // namespace
}  // namespace pullout::idl
