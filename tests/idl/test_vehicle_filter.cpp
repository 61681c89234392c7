// The vehicle content filter: it reads vehicle_id straight from serialized samples, so
// check it on samples serialized by the generated types, and on malformed payloads.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <fastdds/dds/core/LoanableSequence.hpp>

#include "pullout/idl/vehicle_filter.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

namespace pullout::idl {
namespace {

using eprosima::fastrtps::rtps::SerializedPayload_t;

template <typename PubSubType, typename Msg>
std::vector<unsigned char> serialize(Msg& sample) {
  PubSubType type;
  SerializedPayload_t payload(type.getSerializedSizeProvider(&sample)());
  EXPECT_TRUE(type.serialize(&sample, &payload));
  return {payload.data, payload.data + payload.length};
}

bool matches(const std::vector<unsigned char>& bytes, const std::string& id) {
  return payload_has_vehicle_id(bytes.data(), bytes.size(), id);
}

TEST(VehicleFilter, MatchesGeneratedPathAndStatusSamples) {
  msg::PullOutPath path;
  path.vehicle_id("vehicle-10");
  path.request_id(42);
  path.partial_paths().resize(3);
  const auto path_bytes = serialize<msg::PullOutPathPubSubType>(path);
  EXPECT_TRUE(matches(path_bytes, "vehicle-10"));
  EXPECT_FALSE(matches(path_bytes, "vehicle-1"));    // a prefix is not a match
  EXPECT_FALSE(matches(path_bytes, "vehicle-100"));  // nor an extension
  EXPECT_FALSE(matches(path_bytes, ""));

  msg::PullOutStatus status;
  status.vehicle_id("bus/7 'quoted' \"x\"");
  const auto status_bytes = serialize<msg::PullOutStatusPubSubType>(status);
  EXPECT_TRUE(matches(status_bytes, "bus/7 'quoted' \"x\""));
}

TEST(VehicleFilter, EmptyVehicleId) {
  msg::PullOutStatus status;
  const auto bytes = serialize<msg::PullOutStatusPubSubType>(status);
  EXPECT_TRUE(matches(bytes, ""));
  EXPECT_FALSE(matches(bytes, "a"));
}

TEST(VehicleFilter, BothByteOrders) {
  // Encapsulation CDR_BE / CDR_LE, then length 3 ("ab\0").
  const std::vector<unsigned char> be{0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x03, 'a', 'b', 0x00};
  const std::vector<unsigned char> le{0x00, 0x01, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 'a', 'b', 0x00};
  EXPECT_TRUE(matches(be, "ab"));
  EXPECT_TRUE(matches(le, "ab"));
  EXPECT_FALSE(matches(le, "ba"));
}

TEST(VehicleFilter, MalformedPayloadsDoNotMatchAndDoNotOverread) {
  EXPECT_FALSE(payload_has_vehicle_id(nullptr, 0, "ab"));
  const std::vector<unsigned char> short_header{0x00, 0x01, 0x00};
  EXPECT_FALSE(matches(short_header, ""));
  // Length says 200 bytes but only 3 follow.
  const std::vector<unsigned char> truncated{0x00, 0x01, 0x00, 0x00, 0xC8, 0x00, 0x00, 0x00, 'a', 'b', 0x00};
  EXPECT_FALSE(matches(truncated, "ab"));
  // Huge length (would overflow a naive bounds check).
  const std::vector<unsigned char> huge{0x00, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xFF, 'a'};
  EXPECT_FALSE(matches(huge, "a"));
}

TEST(VehicleFilter, UnknownEncapsulationPasses) {
  // PL_CDR_LE (0x0003) or XCDR2: the filter cannot tell, the reception check decides.
  const std::vector<unsigned char> pl_cdr{0x00, 0x03, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 'x', 'y', 0x00};
  EXPECT_TRUE(matches(pl_cdr, "ab"));
}

TEST(VehicleFilterFactory, AcceptsOnlyItsExpression) {
  VehicleIdFilterFactory factory;
  eprosima::fastdds::dds::IContentFilter* filter = nullptr;
  eprosima::fastdds::dds::LoanableSequence<const char*> params;
  params.length(1);
  params[0] = "v1";
  using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
  EXPECT_EQ(factory.create_content_filter("DDSSQL", "t", nullptr, kVehicleFilterExpression, params, filter),
            ReturnCode::RETCODE_BAD_PARAMETER);
  EXPECT_EQ(factory.create_content_filter(kVehicleFilterClass, "t", nullptr, "x > 1", params, filter),
            ReturnCode::RETCODE_BAD_PARAMETER);
  ASSERT_EQ(factory.create_content_filter(kVehicleFilterClass, "t", nullptr, kVehicleFilterExpression, params, filter),
            ReturnCode::RETCODE_OK);
  ASSERT_NE(filter, nullptr);

  msg::PullOutStatus status;
  status.vehicle_id("v1");
  auto bytes = serialize<msg::PullOutStatusPubSubType>(status);
  SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(bytes.size());
  EXPECT_TRUE(filter->evaluate(payload, {}, eprosima::fastrtps::rtps::GUID_t{}));
  status.vehicle_id("v2");
  bytes = serialize<msg::PullOutStatusPubSubType>(status);
  std::copy(bytes.begin(), bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(bytes.size());
  EXPECT_FALSE(filter->evaluate(payload, {}, eprosima::fastrtps::rtps::GUID_t{}));

  EXPECT_EQ(factory.delete_content_filter(kVehicleFilterClass, filter), ReturnCode::RETCODE_OK);
  EXPECT_EQ(factory.delete_content_filter(kVehicleFilterClass, filter), ReturnCode::RETCODE_BAD_PARAMETER);
}

}  // namespace
}  // namespace pullout::idl
