// The vehicle content filter: it reads vehicle_id straight from serialized samples, so
// check it on samples serialized by the generated types, and on malformed payloads.
#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
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

// Whether `filter` keeps a status sample of `id`.
bool keeps(const eprosima::fastdds::dds::IContentFilter* filter, const std::string& id) {
  msg::PullOutStatus status;
  status.vehicle_id(id);
  const auto bytes = serialize<msg::PullOutStatusPubSubType>(status);
  SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(bytes.size());
  return filter->evaluate(payload, {}, eprosima::fastrtps::rtps::GUID_t{});
}

struct Parameters {
  explicit Parameters(std::vector<std::string> values) : strings(std::move(values)) {
    seq.length(static_cast<eprosima::fastdds::dds::LoanableSequence<const char*>::size_type>(strings.size()));
    for (std::size_t i = 0; i < strings.size(); ++i) seq[static_cast<int>(i)] = strings[i].c_str();
  }
  std::vector<std::string> strings;
  eprosima::fastdds::dds::LoanableSequence<const char*> seq;
};

std::vector<std::string_view> views(const std::vector<std::string>& strings) {
  return {strings.begin(), strings.end()};
}

TEST(VehicleSet, EncodingRoundTripsIdsThatSpanParametersAndContainSeparators) {
  // Ids with ':' and digits in them, one of the maximum length (spans two 255-byte parameters).
  const std::vector<std::string> ids{"a", "12:3", std::string(255, 'x'), "v:9:", "veh-0001"};
  const auto parameters = encode_vehicle_set(ids);
  std::size_t expected_bytes = 0;
  for (const auto& id : ids) expected_bytes += vehicle_set_entry_bytes(id);
  std::size_t total = 0;
  for (const auto& p : parameters) {
    EXPECT_LE(p.size(), kVehicleSetParameterBytes);
    total += p.size();
  }
  EXPECT_EQ(total, expected_bytes);
  EXPECT_GE(parameters.size(), 2u);
  std::vector<std::string> decoded;
  ASSERT_TRUE(decode_vehicle_set(views(parameters), decoded));
  EXPECT_EQ(decoded, ids);
  EXPECT_TRUE(encode_vehicle_set({}).empty());
  ASSERT_TRUE(decode_vehicle_set({}, decoded));
  EXPECT_TRUE(decoded.empty());
}

TEST(VehicleSet, MalformedEncodingsAreRejected) {
  std::vector<std::string> ids;
  for (const char* bad : {"x", "3:ab", ":a", "0:", "1a:b", "1234:a", "2:ab3"}) {
    EXPECT_FALSE(decode_vehicle_set({bad}, ids)) << bad;
  }
  const std::vector<std::string> too_many(kMaxVehicleSetParameters + 1, "1:a");
  EXPECT_FALSE(decode_vehicle_set(views(too_many), ids));
}

TEST(VehicleSetFilter, KeepsTheSetsVehiclesAndIsUpdatedInPlace) {
  VehicleIdFilterFactory factory;
  int hooks = 0;
  factory.set_change_hook([&] { ++hooks; });
  eprosima::fastdds::dds::IContentFilter* filter = nullptr;
  using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
  Parameters first(encode_vehicle_set({"v1", "v2"}));
  ASSERT_EQ(
      factory.create_content_filter(kVehicleFilterClass, "t", nullptr, kVehicleSetFilterExpression, first.seq, filter),
      ReturnCode::RETCODE_OK);
  ASSERT_NE(filter, nullptr);
  EXPECT_EQ(hooks, 1);
  EXPECT_TRUE(keeps(filter, "v1"));
  EXPECT_TRUE(keeps(filter, "v2"));
  EXPECT_FALSE(keeps(filter, "v3"));

  // A writer's update (expression given) and a ContentFilteredTopic's (null expression): the same
  // filter object, no hook (no entry added or erased at a writer).
  auto* const original = filter;
  Parameters second(encode_vehicle_set({"v2", "v3"}));
  ASSERT_EQ(
      factory.create_content_filter(kVehicleFilterClass, "t", nullptr, kVehicleSetFilterExpression, second.seq, filter),
      ReturnCode::RETCODE_OK);
  EXPECT_EQ(filter, original);
  EXPECT_FALSE(keeps(filter, "v1"));
  EXPECT_TRUE(keeps(filter, "v3"));
  Parameters third(encode_vehicle_set({"v1"}));
  ASSERT_EQ(factory.create_content_filter(kVehicleFilterClass, "t", nullptr, nullptr, third.seq, filter),
            ReturnCode::RETCODE_OK);
  EXPECT_EQ(filter, original);
  EXPECT_TRUE(keeps(filter, "v1"));
  EXPECT_FALSE(keeps(filter, "v2"));
  Parameters none(std::vector<std::string>{});
  ASSERT_EQ(factory.create_content_filter(kVehicleFilterClass, "t", nullptr, nullptr, none.seq, filter),
            ReturnCode::RETCODE_OK);
  EXPECT_FALSE(keeps(filter, "v1"));
  EXPECT_EQ(hooks, 1);

  EXPECT_EQ(factory.delete_content_filter(kVehicleFilterClass, filter), ReturnCode::RETCODE_OK);
  EXPECT_EQ(hooks, 2);
  // Updates no longer leave a filter behind: the one delete freed the only one.
  EXPECT_EQ(factory.delete_content_filter(kVehicleFilterClass, original), ReturnCode::RETCODE_BAD_PARAMETER);
}

// Fast DDS 2.9.1 erases a writer's reader filter whose update fails (ReaderFilterCollection::
// process_reader_filter_info), without the delete call the service's FilterGate waits for: an
// update must never fail. Bad parameters make the filter pass everything (the client re-checks).
TEST(VehicleSetFilter, AnUpdateWithBadParametersNeverFailsAndPassesEverything) {
  VehicleIdFilterFactory factory;
  eprosima::fastdds::dds::IContentFilter* filter = nullptr;
  using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
  Parameters one({"v1"});
  ASSERT_EQ(factory.create_content_filter(kVehicleFilterClass, "t", nullptr, kVehicleFilterExpression, one.seq, filter),
            ReturnCode::RETCODE_OK);
  auto* const original = filter;
  Parameters bad({"not an encoding"});
  EXPECT_EQ(
      factory.create_content_filter(kVehicleFilterClass, "t", nullptr, kVehicleSetFilterExpression, bad.seq, filter),
      ReturnCode::RETCODE_OK);
  EXPECT_EQ(filter, original);
  EXPECT_TRUE(keeps(filter, "v1"));
  EXPECT_TRUE(keeps(filter, "v9"));
  // A later good update makes it a filter again.
  Parameters good(encode_vehicle_set({"v9"}));
  EXPECT_EQ(
      factory.create_content_filter(kVehicleFilterClass, "t", nullptr, kVehicleSetFilterExpression, good.seq, filter),
      ReturnCode::RETCODE_OK);
  EXPECT_FALSE(keeps(filter, "v1"));
  EXPECT_TRUE(keeps(filter, "v9"));
  // A bad first creation still fails (no entry is made for it).
  eprosima::fastdds::dds::IContentFilter* fresh = nullptr;
  EXPECT_EQ(
      factory.create_content_filter(kVehicleFilterClass, "t", nullptr, kVehicleSetFilterExpression, bad.seq, fresh),
      ReturnCode::RETCODE_BAD_PARAMETER);
  EXPECT_EQ(fresh, nullptr);
  EXPECT_EQ(factory.delete_content_filter(kVehicleFilterClass, filter), ReturnCode::RETCODE_OK);
}

}  // namespace
}  // namespace pullout::idl
