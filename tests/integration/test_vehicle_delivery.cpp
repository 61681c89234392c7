// Each vehicle receives only its own samples, at the DDS level: the real pullout_service filters
// at its writers, so another vehicle's path and status never reach this vehicle's reader.
//
// The observable: a raw DataReader on a ContentFilteredTopic of the vehicle filter class, whose
// filter factory (in this process) counts the samples it is asked to evaluate. A reader
// evaluates its filter on every sample that arrives without a writer-side verdict for it; a
// sample the writer filtered out does not arrive at all (the writer sends a GAP). So the count
// of other vehicles' samples evaluated here is the count of other vehicles' samples received.
// No sleep: the count is read after this vehicle's own reply has been taken from the same reader,
// and the service wrote the other vehicle's replies before it (a reliable reader delivers a
// writer's samples in order, so anything written earlier has arrived or been skipped by then).
#include <atomic>
#include <chrono>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "integration_support.hpp"
#include "pullout/idl/topics.hpp"
#include "pullout/idl/vehicle_filter.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

namespace pullout::integration {
namespace {

namespace dds = eprosima::fastdds::dds;
using ReturnCode = eprosima::fastrtps::types::ReturnCode_t;
using namespace std::chrono_literals;

// The vehicle filter, counting what it evaluates.
class CountingFilterFactory final : public dds::IContentFilterFactory {
 public:
  std::atomic<int> own{0};
  std::atomic<int> foreign{0};

  ReturnCode_t create_content_filter(const char* /*filter_class_name*/, const char* /*type_name*/,
                                     const dds::TopicDataType* /*data_type*/, const char* /*filter_expression*/,
                                     const ParameterSeq& filter_parameters,
                                     dds::IContentFilter*& filter_instance) override {
    if (filter_parameters.length() != 1) return ReturnCode_t::RETCODE_BAD_PARAMETER;
    std::lock_guard<std::mutex> lock(mutex_);
    filters_.push_back(std::make_unique<Filter>(*this, filter_parameters[0]));
    filter_instance = filters_.back().get();
    return ReturnCode_t::RETCODE_OK;
  }
  ReturnCode_t delete_content_filter(const char* /*filter_class_name*/, dds::IContentFilter* /*filter*/) override {
    return ReturnCode_t::RETCODE_OK;  // owned here until the factory goes
  }

 private:
  class Filter final : public dds::IContentFilter {
   public:
    Filter(CountingFilterFactory& owner, std::string vehicle) : owner_(owner), vehicle_(std::move(vehicle)) {}
    bool evaluate(const SerializedPayload& payload, const FilterSampleInfo& /*info*/,
                  const GUID_t& /*reader*/) const override {
      const bool mine = idl::payload_has_vehicle_id(payload.data, payload.length, vehicle_);
      ++(mine ? owner_.own : owner_.foreign);
      return mine;
    }

   private:
    CountingFilterFactory& owner_;
    std::string vehicle_;
  };
  std::mutex mutex_;
  std::vector<std::unique_ptr<Filter>> filters_;
};

// A participant of its own with one filtered path reader for `vehicle`.
class WatchingReader {
 public:
  WatchingReader(int domain, const std::string& vehicle) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    if (factory->load_XML_profiles_file(loopback_profiles_path()) != ReturnCode::RETCODE_OK) {
      throw std::runtime_error("cannot load " + loopback_profiles_path());
    }
    dds::DomainParticipantQos pqos;
    factory->get_participant_qos_from_profile(idl::kParticipantProfile, pqos);
    participant_ = factory->create_participant(domain, pqos);
    if (participant_ == nullptr) throw std::runtime_error("no participant");
    participant_->register_content_filter_factory(idl::kVehicleFilterClass, &filters_);
    dds::TypeSupport type(new msg::PullOutPathPubSubType());
    type.register_type(participant_);
    dds::Topic* topic = participant_->create_topic(idl::kPathTopic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    dds::ContentFilteredTopic* filtered = participant_->create_contentfilteredtopic(
        "pullout/path/watched", topic, idl::kVehicleFilterExpression, {vehicle}, idl::kVehicleFilterClass);
    if (filtered == nullptr) throw std::runtime_error("no content filtered topic");
    dds::Subscriber* subscriber = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    dds::DataReaderQos qos;
    subscriber->get_datareader_qos_from_profile(idl::kPathReaderProfile, qos);
    reader_ = subscriber->create_datareader(filtered, qos);
    if (reader_ == nullptr) throw std::runtime_error("no reader");
  }
  ~WatchingReader() {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  WatchingReader(const WatchingReader&) = delete;
  WatchingReader& operator=(const WatchingReader&) = delete;

  bool wait_matched(std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      dds::SubscriptionMatchedStatus s;
      reader_->get_subscription_matched_status(s);
      if (s.current_count > 0) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }
  // Takes paths until one for `request_id` arrives; every path taken is counted by vehicle.
  bool wait_path(std::uint64_t request_id, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      msg::PullOutPath sample;
      dds::SampleInfo info;
      while (reader_->take_next_sample(&sample, &info) == ReturnCode::RETCODE_OK) {
        if (!info.valid_data) continue;
        taken.push_back(sample.vehicle_id());
        if (sample.request_id() == request_id) return true;
      }
      std::this_thread::sleep_for(5ms);
    }
    return false;
  }

  CountingFilterFactory filters_;  // registered with the participant: declared first
  std::vector<std::string> taken;

 private:
  dds::DomainParticipant* participant_{nullptr};
  dds::DataReader* reader_{nullptr};
};

class VehicleDelivery : public ServiceTest {};

TEST_F(VehicleDelivery, AnotherVehiclesRepliesNeverReachThisVehiclesReader) {
  start_service();
  WatchingReader watch(domain(), "watched-car");
  ASSERT_TRUE(watch.wait_matched(std::chrono::milliseconds(kMatchTimeout)));
  const Scenario scenario = load_test_scenario("straight_shoulder");

  // Three requests of another vehicle, each answered (path and statuses written by the service).
  auto other = connect("other-car");
  for (int i = 0; i < 3; ++i) {
    const std::uint64_t id = other->send(scenario.request);
    ASSERT_TRUE(other->wait_for_path(id, kReplyTimeout).has_value()) << service_stderr();
  }
  // Then one of the watched vehicle: its path comes after every path above on the same writer.
  auto watched = connect("watched-car");
  const std::uint64_t id = watched->send(scenario.request);
  ASSERT_TRUE(watched->wait_for_path(id, kReplyTimeout).has_value()) << service_stderr();
  ASSERT_TRUE(watch.wait_path(id, std::chrono::milliseconds(kReplyTimeout))) << service_stderr();

  EXPECT_EQ(watch.filters_.foreign.load(), 0) << "samples of other vehicles reached this reader";
  for (const std::string& vehicle : watch.taken) EXPECT_EQ(vehicle, "watched-car");
}

}  // namespace
}  // namespace pullout::integration
