#include "pullout/idl/vehicle_filter.hpp"

#include <algorithm>
#include <cstring>
#include <unordered_set>

namespace pullout::idl {

namespace dds = eprosima::fastdds::dds;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;

namespace {
// RTPS representation identifiers (first two bytes of the payload, big-endian).
constexpr unsigned char kCdrBigEndian = 0x00;
constexpr unsigned char kCdrLittleEndian = 0x01;
constexpr std::size_t kHeaderBytes = 4;
}  // namespace

namespace {
enum class PayloadId { kFound, kUnknownEncoding, kMalformed };

// The vehicle id at the start of a serialized sample (see the header).
PayloadId payload_vehicle_id(const unsigned char* data, std::size_t size, std::string_view& id) {
  if (data == nullptr || size < kHeaderBytes + 4) return PayloadId::kMalformed;
  if (data[0] != 0x00 || (data[1] != kCdrBigEndian && data[1] != kCdrLittleEndian)) {
    return PayloadId::kUnknownEncoding;
  }
  const unsigned char* p = data + kHeaderBytes;
  std::uint32_t length = 0;
  if (data[1] == kCdrLittleEndian) {
    length = std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
  } else {
    length = std::uint32_t{p[3]} | std::uint32_t{p[2]} << 8 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[0]} << 24;
  }
  const std::size_t available = size - kHeaderBytes - 4;
  if (length > available) return PayloadId::kMalformed;
  const char* chars = reinterpret_cast<const char*>(p + 4);
  // The length counts the terminating NUL; tolerate a writer that omits it (length 0 for "").
  std::size_t n = length;
  if (n > 0 && chars[n - 1] == '\0') --n;
  id = std::string_view(chars, n);
  return PayloadId::kFound;
}
}  // namespace

bool payload_has_vehicle_id(const unsigned char* data, std::size_t size, std::string_view vehicle_id) {
  std::string_view id;
  switch (payload_vehicle_id(data, size, id)) {
    case PayloadId::kUnknownEncoding:
      return true;
    case PayloadId::kMalformed:
      return false;
    case PayloadId::kFound:
      break;
  }
  return id == vehicle_id;
}

std::size_t vehicle_set_entry_bytes(std::string_view vehicle_id) {
  return std::to_string(vehicle_id.size()).size() + 1 + vehicle_id.size();
}

std::vector<std::string> encode_vehicle_set(const std::vector<std::string>& ids) {
  std::string all;
  for (const auto& id : ids) {
    all += std::to_string(id.size());
    all += ':';
    all += id;
  }
  std::vector<std::string> parameters;
  for (std::size_t at = 0; at < all.size(); at += kVehicleSetParameterBytes) {
    parameters.push_back(all.substr(at, kVehicleSetParameterBytes));
  }
  return parameters;
}

bool decode_vehicle_set(const std::vector<std::string_view>& parameters, std::vector<std::string>& ids) {
  ids.clear();
  if (parameters.size() > kMaxVehicleSetParameters) return false;
  std::string all;
  for (const auto& parameter : parameters) {
    if (parameter.size() > kVehicleSetParameterBytes) return false;
    all += parameter;
  }
  std::size_t at = 0;
  while (at < all.size()) {
    const std::size_t colon = all.find(':', at);
    // Up to 3 digits: a vehicle id has at most kMaxVehicleIdBytes (255) bytes.
    if (colon == std::string::npos || colon == at || colon - at > 3) return false;
    std::size_t length = 0;
    for (std::size_t i = at; i < colon; ++i) {
      if (all[i] < '0' || all[i] > '9') return false;
      length = length * 10 + static_cast<std::size_t>(all[i] - '0');
    }
    if (length == 0 || length > all.size() - colon - 1) return false;
    ids.push_back(all.substr(colon + 1, length));
    at = colon + 1 + length;
  }
  return true;
}

// One vehicle, a set of vehicles, or (parameters that made no filter on an update) everything.
class VehicleIdFilterFactory::Filter final : public dds::IContentFilter {
 public:
  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo& /*sample_info*/,
                const GUID_t& /*reader_guid*/) const override {
    std::string_view id;
    switch (payload_vehicle_id(payload.data, payload.length, id)) {
      case PayloadId::kUnknownEncoding:
        return true;
      case PayloadId::kMalformed:
        return false;
      case PayloadId::kFound:
        break;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (pass_all_) return true;
    // std::unordered_set<std::string>::find needs a std::string before C++20.
    return ids_.count(std::string(id)) != 0;
  }

  // Sets the filter from an expression and its parameters; false (and the filter unchanged) when
  // they do not make one of ours.
  bool assign(std::string_view expression, const std::vector<std::string_view>& parameters) {
    std::vector<std::string> ids;
    if (expression == kVehicleFilterExpression) {
      if (parameters.size() != 1) return false;
      ids.emplace_back(parameters[0]);
    } else if (expression == kVehicleSetFilterExpression) {
      if (!decode_vehicle_set(parameters, ids)) return false;
    } else {
      return false;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    expression_ = std::string(expression);
    ids_ = std::unordered_set<std::string>(ids.begin(), ids.end());
    pass_all_ = false;
    return true;
  }

  void pass_all() {
    std::lock_guard<std::mutex> lock(mutex_);
    pass_all_ = true;
  }

  std::string expression() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return expression_;
  }

 private:
  mutable std::mutex mutex_;
  std::string expression_;
  std::unordered_set<std::string> ids_;
  bool pass_all_{false};
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
  std::vector<std::string_view> parameters;
  bool null_parameter = false;
  for (ParameterSeq::size_type i = 0; i < filter_parameters.length(); ++i) {
    if (filter_parameters[i] == nullptr) {
      null_parameter = true;
      break;
    }
    parameters.emplace_back(filter_parameters[i]);
  }

  const bool new_entry = filter_instance == nullptr;
  // An update of one of our filters: in place, never failing (see the header).
  Filter* existing = nullptr;
  if (filter_instance != nullptr) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& f : filters_) {
      if (f.get() == filter_instance) existing = f.get();
    }
  }
  if (existing != nullptr) {
    // A null expression keeps the filter's own (ContentFilteredTopic::set_expression_parameters).
    const std::string expression =
        filter_expression != nullptr ? std::string(filter_expression) : existing->expression();
    if (null_parameter || !existing->assign(expression, parameters)) existing->pass_all();
    return ReturnCode::RETCODE_OK;
  }

  if (filter_expression == nullptr || null_parameter) return ReturnCode::RETCODE_BAD_PARAMETER;
  auto filter = std::make_unique<Filter>();
  if (!filter->assign(filter_expression, parameters)) return ReturnCode::RETCODE_BAD_PARAMETER;
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
