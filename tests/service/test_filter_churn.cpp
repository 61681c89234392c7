// The service's filtering writers while vehicles' filtered readers come and go.
//
// Fast DDS 2.9.1 adds and removes a remote reader's writer-side filter on a discovery thread
// without the writer's lock, while DataWriter::write walks the same filter map under that lock
// (README, Guarantees). bench_load crashed the service that way when hundreds of vehicles left.
// Here the service's own DdsEdge publishes statuses and paths from two threads without pause
// while other participants create and delete vehicle-filtered readers; the process must survive
// and the last readers must still get their own vehicle's samples only.
//
// Intraprocess delivery is off for this process: Fast DDS skips writer-side filtering for a reader
// in the same process, which would hide the race.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fastrtps/attributes/LibrarySettingsAttributes.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pullout/config/config.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/idl/topics.hpp"
#include "pullout/idl/vehicle_filter.hpp"
#include "service/dds_edge.hpp"
#include "service_process.hpp"  // DomainLease

namespace pullout::service {
namespace {

namespace dds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;
using Clock = std::chrono::steady_clock;

constexpr int kVehicles = 48;
constexpr int kReadersPerRound = 24;
constexpr auto kChurnTime = std::chrono::seconds(12);

std::string vehicle_name(int i) { return "churn_" + std::to_string(i); }

// A participant of filtered status readers, one per vehicle in [first, first + count).
class FilteredReaders {
 public:
  FilteredReaders(int domain, int first, int count) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    participant_ = factory->create_participant_with_profile(domain, "pullout_participant");
    if (participant_ == nullptr) throw std::runtime_error("participant");
    if (participant_->register_content_filter_factory(idl::kVehicleFilterClass, &filters_) !=
        ReturnCode_t::RETCODE_OK) {
      throw std::runtime_error("filter factory");
    }
    dds::TypeSupport type(idl::make_guarded_type<msg::PullOutStatusPubSubType>());
    type.register_type(participant_);
    topic_ = participant_->create_topic(idl::kStatusTopic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (topic_ == nullptr || subscriber_ == nullptr) throw std::runtime_error("topic/subscriber");
    dds::DataReaderQos qos;
    if (subscriber_->get_datareader_qos_from_profile(idl::kStatusReaderProfile, qos) != ReturnCode_t::RETCODE_OK) {
      throw std::runtime_error("status reader profile");
    }
    for (int i = first; i < first + count; ++i) {
      const std::string id = vehicle_name(i);
      dds::ContentFilteredTopic* filtered =
          participant_->create_contentfilteredtopic(std::string(idl::kStatusTopic) + "/" + id, topic_,
                                                    idl::kVehicleFilterExpression, {id}, idl::kVehicleFilterClass);
      if (filtered == nullptr) throw std::runtime_error("content filtered topic");
      dds::DataReader* reader = subscriber_->create_datareader(filtered, qos);
      if (reader == nullptr) throw std::runtime_error("reader");
      readers_.push_back({id, reader, filtered});
    }
  }

  ~FilteredReaders() {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  // Deletes every other reader now (each one leaves on its own, not with the participant).
  void delete_half() {
    for (std::size_t i = 0; i < readers_.size(); i += 2) {
      subscriber_->delete_datareader(readers_[i].reader);
      participant_->delete_contentfilteredtopic(readers_[i].filtered);
      readers_[i].reader = nullptr;
    }
  }

  // Waits until every remaining reader got a sample of its own vehicle; fails on another
  // vehicle's sample.
  void expect_own_samples_only(Clock::time_point deadline) {
    for (auto& r : readers_) {
      if (r.reader == nullptr) continue;
      bool own = false;
      while (!own && Clock::now() < deadline) {
        msg::PullOutStatus sample;
        dds::SampleInfo info;
        while (r.reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
          if (!info.valid_data) continue;
          EXPECT_EQ(sample.vehicle_id(), r.vehicle_id);
          own = own || sample.vehicle_id() == r.vehicle_id;
        }
        if (!own) std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      EXPECT_TRUE(own) << r.vehicle_id << " got none of its statuses";
    }
  }

 private:
  struct Reader {
    std::string vehicle_id;
    dds::DataReader* reader;
    dds::ContentFilteredTopic* filtered;
  };
  idl::VehicleIdFilterFactory filters_;  // outlives the participant
  dds::DomainParticipant* participant_{nullptr};
  dds::Topic* topic_{nullptr};
  dds::Subscriber* subscriber_{nullptr};
  std::vector<Reader> readers_;
};

TEST(WriterFilterChurn, ReadersComingAndGoingWhileTheServicePublishesDoNotCrashIt) {
  eprosima::fastrtps::LibrarySettingsAttributes library;
  library.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(library);

  integration::DomainLease lease;
  Config config = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  config.dds.domain_id = lease.domain();
  DdsEdge edge(config.dds);

  std::atomic<bool> stop{false};
  std::atomic<long> writes{0};
  const auto publisher = [&](int offset) {
    long n = 0;
    while (!stop.load()) {
      PullOutStatus status;
      status.vehicle_id = vehicle_name(static_cast<int>((n * 7 + offset) % kVehicles));
      status.request_id = static_cast<std::uint64_t>(n + 1);
      edge.publish_status(status);
      if (n % 4 == 0) {
        PullOutPath path;
        path.vehicle_id = status.vehicle_id;
        path.request_id = status.request_id;
        edge.publish_path(path);
      }
      ++n;
      writes.fetch_add(1);
      // About 2,000 writes a second each: the discovery threads of a loaded machine keep up.
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  };
  std::thread first(publisher, 0);
  std::thread second(publisher, kVehicles / 2);

  const Clock::time_point end = Clock::now() + kChurnTime;
  int rounds = 0;
  while (Clock::now() < end) {
    // Two overlapping groups of readers: one joins while the other leaves.
    FilteredReaders a(lease.domain(), (rounds * 5) % kVehicles, kReadersPerRound / 2);
    FilteredReaders b(lease.domain(), (rounds * 5 + 11) % kVehicles, kReadersPerRound / 2);
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    a.delete_half();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ++rounds;
  }
  // The service still serves filtered readers after the churn.
  {
    FilteredReaders last(lease.domain(), 0, 8);
    last.expect_own_samples_only(Clock::now() + std::chrono::seconds(10));
  }
  stop = true;
  first.join();
  second.join();
  EXPECT_GT(rounds, 3);
  EXPECT_GT(writes.load(), 1000);
  std::printf("%d rounds of %d readers, %ld writes\n", rounds, kReadersPerRound, writes.load());
}

}  // namespace
}  // namespace pullout::service
