// The vehicle content filter: keeps the samples of one vehicle, or of a set of vehicles. Shared by
// both DDS edges.
//
// The client reads pullout/path and pullout/status through a ContentFilteredTopic of this filter
// class: a single-vehicle Client with expression kVehicleFilterExpression (parameter: its vehicle
// id), a ClientParticipant with one reader per topic for all its Clients, expression
// kVehicleSetFilterExpression (parameters: encode_vehicle_set() of its vehicles' ids, changed in
// place as Clients come and go). The service registers
// the same factory on its participant, so that Fast DDS evaluates each remote reader's filter at
// the service's writers (writer-side filtering, Fast DDS >= 2.6): a vehicle's path and status are
// sent to that vehicle's reader only, and every other reader gets a small GAP instead of the
// sample. Without the factory at the writer, the filter runs in the reader, after the bytes
// crossed the wire (every reply to every vehicle: N^2 traffic for a fleet of N).
//
// Fast DDS's built-in SQL filter needs type objects, which pullout's generated types do not have
// (fastdds_notes.md), so this custom filter class reads the key straight from the serialized
// sample: every pullout reply type starts with `@key string vehicle_id`, i.e. (XCDR1, final) a
// 4-byte encapsulation header, a uint32 length including the terminating NUL, then the bytes.
// A payload in any other encapsulation passes the filter (the client checks the converted
// sample's vehicle_id again on reception).
//
// The filter runs on Fast DDS receive and writer threads while a discovery thread may update its
// parameters (a remote reader's set changed): evaluate() takes the filter's own lock. Not part of
// the client's public headers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>

namespace pullout::idl {

inline constexpr const char* kVehicleFilterClass = "PULLOUT_VEHICLE_ID";
inline constexpr const char* kVehicleFilterExpression = "vehicle_id = %0";
// The set filter. Its parameters are the ids, each written as its decimal byte count, ':' and its
// bytes, concatenated and cut into parameters of at most kVehicleSetParameterBytes (an id may span
// two). Bounds: Fast DDS 2.9.1 carries each parameter as a string_255, and a participant accepts
// at most 100 parameters per remote reader filter by default (ContentFilterProperty::
// AllocationConfiguration; a reader announcing more is not matched), so a set holds at most
// kVehicleSetCapacityBytes encoded bytes (about 2,300 ids of 8 bytes, 98 of 255 bytes).
inline constexpr const char* kVehicleSetFilterExpression = "vehicle_id IN %0..";
inline constexpr std::size_t kVehicleSetParameterBytes = 255;
inline constexpr std::size_t kMaxVehicleSetParameters = 100;
inline constexpr std::size_t kVehicleSetCapacityBytes = kVehicleSetParameterBytes * kMaxVehicleSetParameters;

// Bytes `vehicle_id` takes in the set encoding.
std::size_t vehicle_set_entry_bytes(std::string_view vehicle_id);
// The parameters for a set of ids (empty for an empty set). The caller keeps the total of
// vehicle_set_entry_bytes within kVehicleSetCapacityBytes.
std::vector<std::string> encode_vehicle_set(const std::vector<std::string>& ids);
// The ids of a set filter's parameters; false when they are not such an encoding.
bool decode_vehicle_set(const std::vector<std::string_view>& parameters, std::vector<std::string>& ids);

// Reader filters a service writer evaluates itself (DataWriterQos::writer_resource_limits()
// .reader_filters_allocation.maximum; Fast DDS's default is 32: the 33rd vehicle and every later
// one would receive every vehicle's replies again). Readers past this many are served unfiltered
// (their client drops other vehicles' samples). The bound: each sample a filtering writer sends
// carries a PID_CONTENT_FILTER_INFO inline QoS of 16 bytes per reader filter plus a 32-bit bitmap
// word per 32 filters, and that parameter's length is 16 bits, so Fast DDS 2.9.1 cannot encode
// more than 4,063 filters (past that it filters for no reader at all). Costs at the writer, per
// sample: one filter evaluation per reader and 16 bytes of inline QoS per reader filter (at 4,000
// vehicles, 64 KB on the one DATA that is sent); and every history sample keeps the list of the
// readers that filtered it out (16 bytes each).
inline constexpr int kMaxWriterReaderFilters = 4000;

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

  // Accepts kVehicleFilterExpression with one parameter (the vehicle id, unquoted) and
  // kVehicleSetFilterExpression with a set's encoding. With filter_instance already one of this
  // factory's filters (Fast DDS updating a filter: a remote reader announced new parameters, or
  // ContentFilteredTopic::set_expression_parameters, whose expression is null), the filter is
  // changed in place and the call never fails: Fast DDS 2.9.1 erases a writer's reader filter
  // whose update fails, without the factory calls the service's FilterGate relies on. Parameters
  // that do not make a filter then make it pass everything (the client drops other vehicles'
  // samples on reception).
  ReturnCode_t create_content_filter(const char* filter_class_name, const char* type_name,
                                     const eprosima::fastdds::dds::TopicDataType* data_type,
                                     const char* filter_expression, const ParameterSeq& filter_parameters,
                                     eprosima::fastdds::dds::IContentFilter*& filter_instance) override;
  ReturnCode_t delete_content_filter(const char* filter_class_name,
                                     eprosima::fastdds::dds::IContentFilter* filter_instance) override;

  // Called on the calling thread when a new filter was created (after creating it) or before a
  // filter is deleted (before freeing it: a writer may still be evaluating it): at a writer, Fast
  // DDS 2.9.1 adds or erases that reader's entry in the writer's filter map right after the
  // factory call returns. The service uses it to keep its writes out
  // of that change (service/src/service/dds_edge.cpp, FilterGate). Not called when a create
  // fails or when it updates an existing filter in place. Set before the factory is registered.
  void set_change_hook(std::function<void()> hook) { change_hook_ = std::move(hook); }

 private:
  class Filter;
  std::mutex mutex_;
  std::vector<std::unique_ptr<Filter>> filters_;
  std::function<void()> change_hook_;
};

}  // namespace pullout::idl
