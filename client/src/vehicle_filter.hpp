// A content filter that keeps the samples of one vehicle, so that a client's readers never store
// (nor count against their resource limits) the replies of other vehicles.
//
// Fast DDS's built-in SQL filter needs type objects, which pullout's generated types do not have
// (fastdds_notes.md), so this custom filter class reads the key straight from the serialized
// sample: every pullout reply type starts with `@key string vehicle_id`, i.e. (XCDR1, final) a
// 4-byte encapsulation header, a uint32 length including the terminating NUL, then the bytes.
// A payload in any other encapsulation passes the filter (the client checks the converted
// sample's vehicle_id again on reception).
//
// The filter runs on Fast DDS receive threads: evaluate() is const and reads only the vehicle id
// fixed at creation. Internal to the client library.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>

namespace pullout::client_detail {

inline constexpr const char* kVehicleFilterClass = "PULLOUT_VEHICLE_ID";
inline constexpr const char* kVehicleFilterExpression = "vehicle_id = %0";

// Whether a serialized sample (data[0..size), starting with the encapsulation header) whose first
// member is a string carries `vehicle_id` there. True when the encapsulation is not plain CDR
// (cannot tell); false when the payload is too short or malformed.
bool payload_has_vehicle_id(const unsigned char* data, std::size_t size, std::string_view vehicle_id);

class VehicleIdFilterFactory final : public eprosima::fastdds::dds::IContentFilterFactory {
 public:
  VehicleIdFilterFactory();
  ~VehicleIdFilterFactory();
  VehicleIdFilterFactory(const VehicleIdFilterFactory&) = delete;
  VehicleIdFilterFactory& operator=(const VehicleIdFilterFactory&) = delete;

  // Accepts exactly kVehicleFilterExpression with one parameter (the vehicle id, unquoted).
  ReturnCode_t create_content_filter(const char* filter_class_name, const char* type_name,
                                     const eprosima::fastdds::dds::TopicDataType* data_type,
                                     const char* filter_expression, const ParameterSeq& filter_parameters,
                                     eprosima::fastdds::dds::IContentFilter*& filter_instance) override;
  ReturnCode_t delete_content_filter(const char* filter_class_name,
                                     eprosima::fastdds::dds::IContentFilter* filter_instance) override;

 private:
  class Filter;
  std::mutex mutex_;
  std::vector<std::unique_ptr<Filter>> filters_;
};

}  // namespace pullout::client_detail
