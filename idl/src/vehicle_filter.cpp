#include "pullout/idl/vehicle_filter.hpp"

#include <algorithm>
#include <cstring>

namespace pullout::idl {

namespace dds = eprosima::fastdds::dds;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;

namespace {
// RTPS representation identifiers (first two bytes of the payload, big-endian).
constexpr unsigned char kCdrBigEndian = 0x00;
constexpr unsigned char kCdrLittleEndian = 0x01;
constexpr std::size_t kHeaderBytes = 4;
}  // namespace

bool payload_has_vehicle_id(const unsigned char* data, std::size_t size, std::string_view vehicle_id) {
  if (data == nullptr || size < kHeaderBytes + 4) return false;
  if (data[0] != 0x00 || (data[1] != kCdrBigEndian && data[1] != kCdrLittleEndian)) return true;
  const unsigned char* p = data + kHeaderBytes;
  std::uint32_t length = 0;
  if (data[1] == kCdrLittleEndian) {
    length = std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
  } else {
    length = std::uint32_t{p[3]} | std::uint32_t{p[2]} << 8 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[0]} << 24;
  }
  const std::size_t available = size - kHeaderBytes - 4;
  if (length > available) return false;
  const char* chars = reinterpret_cast<const char*>(p + 4);
  // The length counts the terminating NUL; tolerate a writer that omits it (length 0 for "").
  std::size_t n = length;
  if (n > 0 && chars[n - 1] == '\0') --n;
  return n == vehicle_id.size() && std::memcmp(chars, vehicle_id.data(), n) == 0;
}

class VehicleIdFilterFactory::Filter final : public dds::IContentFilter {
 public:
  explicit Filter(std::string vehicle_id) : vehicle_id_(std::move(vehicle_id)) {}

  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo& /*sample_info*/,
                const GUID_t& /*reader_guid*/) const override {
    return payload_has_vehicle_id(payload.data, payload.length, vehicle_id_);
  }

 private:
  const std::string vehicle_id_;
};

VehicleIdFilterFactory::VehicleIdFilterFactory() = default;
VehicleIdFilterFactory::~VehicleIdFilterFactory() = default;

ReturnCode VehicleIdFilterFactory::create_content_filter(const char* filter_class_name, const char* /*type_name*/,
                                                         const dds::TopicDataType* /*data_type*/,
                                                         const char* filter_expression,
                                                         const ParameterSeq& filter_parameters,
                                                         dds::IContentFilter*& filter_instance) {
  if (filter_class_name == nullptr || std::strcmp(filter_class_name, kVehicleFilterClass) != 0) {
    return ReturnCode::RETCODE_BAD_PARAMETER;
  }
  // A null expression asks to update the parameters of an existing filter: the client never does.
  if (filter_expression == nullptr) return ReturnCode::RETCODE_UNSUPPORTED;
  if (std::strcmp(filter_expression, kVehicleFilterExpression) != 0 || filter_parameters.length() != 1 ||
      filter_parameters[0] == nullptr) {
    return ReturnCode::RETCODE_BAD_PARAMETER;
  }
  const bool new_entry = filter_instance == nullptr;
  auto filter = std::make_unique<Filter>(filter_parameters[0]);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    filter_instance = filter.get();
    filters_.push_back(std::move(filter));
  }
  if (new_entry && change_hook_) change_hook_();
  return ReturnCode::RETCODE_OK;
}

ReturnCode VehicleIdFilterFactory::delete_content_filter(const char* /*filter_class_name*/,
                                                         dds::IContentFilter* filter_instance) {
  // The hook first: a writer may be evaluating this filter until the hook returns.
  if (change_hook_) change_hook_();
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = std::find_if(filters_.begin(), filters_.end(),
                         [&](const std::unique_ptr<Filter>& f) { return f.get() == filter_instance; });
  if (it == filters_.end()) return ReturnCode::RETCODE_BAD_PARAMETER;
  filters_.erase(it);
  return ReturnCode::RETCODE_OK;
}

}  // namespace pullout::idl
