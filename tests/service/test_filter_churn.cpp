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
#include <set>
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

// A participant with the vehicle filter factory, the status topic and a subscriber, and the
// status reader profile's QoS: what the filtered readers below are made in.
class StatusSubscriber {
 public:
  explicit StatusSubscriber(int domain) {
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
    if (subscriber_->get_datareader_qos_from_profile(idl::kStatusReaderProfile, qos_) != ReturnCode_t::RETCODE_OK) {
      throw std::runtime_error("status reader profile");
    }
  }
  ~StatusSubscriber() {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  StatusSubscriber(const StatusSubscriber&) = delete;
  StatusSubscriber& operator=(const StatusSubscriber&) = delete;

 protected:
  idl::VehicleIdFilterFactory filters_;  // outlives the participant
  dds::DomainParticipant* participant_{nullptr};
  dds::Topic* topic_{nullptr};
  dds::Subscriber* subscriber_{nullptr};
  dds::DataReaderQos qos_;
};

// A participant of filtered status readers, one per vehicle in [first, first + count).
class FilteredReaders : public StatusSubscriber {
 public:
  FilteredReaders(int domain, int first, int count) : StatusSubscriber(domain) {
    for (int i = first; i < first + count; ++i) {
      const std::string id = vehicle_name(i);
      dds::ContentFilteredTopic* filtered =
          participant_->create_contentfilteredtopic(std::string(idl::kStatusTopic) + "/" + id, topic_,
                                                    idl::kVehicleFilterExpression, {id}, idl::kVehicleFilterClass);
      if (filtered == nullptr) throw std::runtime_error("content filtered topic");
      dds::DataReader* reader = subscriber_->create_datareader(filtered, qos_);
      if (reader == nullptr) throw std::runtime_error("reader");
      readers_.push_back({id, reader, filtered});
    }
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

// One reader of statuses whose filter is a set of vehicles (a ClientParticipant's), changing its
// set in place as its vehicles come and go.
class SetReader : public StatusSubscriber {
 public:
  explicit SetReader(int domain) : StatusSubscriber(domain) {
    filtered_ =
        participant_->create_contentfilteredtopic(std::string(idl::kStatusTopic) + "/set", topic_,
                                                  idl::kVehicleSetFilterExpression, {}, idl::kVehicleFilterClass);
    if (filtered_ == nullptr) throw std::runtime_error("content filtered topic");
    reader_ = subscriber_->create_datareader(filtered_, qos_);
    if (reader_ == nullptr) throw std::runtime_error("reader");
  }

  bool set(const std::vector<std::string>& ids) {
    return filtered_->set_expression_parameters(idl::encode_vehicle_set(ids)) == ReturnCode_t::RETCODE_OK;
  }

  // Takes everything received so far; returns the vehicle ids.
  std::vector<std::string> take_all() {
    std::vector<std::string> ids;
    msg::PullOutStatus sample;
    dds::SampleInfo info;
    while (reader_->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) ids.push_back(sample.vehicle_id());
    }
    return ids;
  }

 private:
  dds::ContentFilteredTopic* filtered_{nullptr};
  dds::DataReader* reader_{nullptr};
};

// The service's writers update a reader's set filter in place, on a discovery thread, while the
// writes evaluate it (the factory must never fail such an update: Fast DDS would erase the filter
// behind FilterGate's back). Readers changing their sets every 10 ms while the service publishes:
// no crash, and afterwards each reader gets its final set's vehicles and no other.
TEST(WriterFilterChurn, SetReadersChangingTheirVehiclesWhileTheServicePublishes) {
  eprosima::fastrtps::LibrarySettingsAttributes library;
  library.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(library);

  integration::DomainLease lease;
  Config config = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  config.dds.domain_id = lease.domain();
  DdsEdge edge(config.dds);

  std::atomic<bool> stop{false};
  std::atomic<long> writes{0};
  std::thread publisher([&] {
    long n = 0;
    while (!stop.load()) {
      PullOutStatus status;
      status.vehicle_id = vehicle_name(static_cast<int>((n * 7) % kVehicles));
      status.request_id = static_cast<std::uint64_t>(n + 1);
      edge.publish_status(status);
      ++n;
      writes.fetch_add(1);
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });

  constexpr int kSetReaders = 3;
  std::vector<std::unique_ptr<SetReader>> readers;
  for (int r = 0; r < kSetReaders; ++r) readers.push_back(std::make_unique<SetReader>(lease.domain()));
  // Sets drawn from vehicles 0..kVehicles/2-1 during the churn; the final sets come from the other
  // half (disjoint from every earlier set: their first sample proves the writer has the final set).
  const auto churn_end = Clock::now() + std::chrono::seconds(6);
  int updates = 0;
  while (Clock::now() < churn_end) {
    for (int r = 0; r < kSetReaders; ++r) {
      std::vector<std::string> ids;
      for (int k = 0; k < 1 + (updates + r) % 5; ++k)
        ids.push_back(vehicle_name((updates * 3 + r * 5 + k) % (kVehicles / 2)));
      ASSERT_TRUE(readers[r]->set(ids));
      readers[r]->take_all();
    }
    ++updates;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::vector<std::set<std::string>> finals(kSetReaders);
  for (int r = 0; r < kSetReaders; ++r) {
    std::vector<std::string> ids{vehicle_name(kVehicles / 2 + 2 * r), vehicle_name(kVehicles / 2 + 2 * r + 1)};
    finals[r] = std::set<std::string>(ids.begin(), ids.end());
    ASSERT_TRUE(readers[r]->set(ids));
  }
  for (int r = 0; r < kSetReaders; ++r) {
    // Until a sample of the final set arrives (in the writer's order, every later one was
    // filtered with the final set), then the next ones: all in the set, and both vehicles seen.
    const auto deadline = Clock::now() + std::chrono::seconds(10);
    bool final_seen = false;
    while (!final_seen && Clock::now() < deadline) {
      for (const auto& id : readers[r]->take_all()) final_seen = final_seen || finals[r].count(id) != 0;
      if (!final_seen) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_TRUE(final_seen) << "reader " << r << " got nothing of its final set";
    std::set<std::string> seen;
    int foreign = 0;
    while (seen.size() < finals[r].size() && Clock::now() < deadline) {
      for (const auto& id : readers[r]->take_all()) {
        if (finals[r].count(id) != 0) {
          seen.insert(id);
        } else {
          ++foreign;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_EQ(seen, finals[r]) << "reader " << r;
    EXPECT_EQ(foreign, 0) << "reader " << r;
  }
  stop = true;
  publisher.join();
  EXPECT_GT(updates, 50);
  EXPECT_GT(writes.load(), 1000);
  std::printf("%d set updates per reader, %ld writes\n", updates, writes.load());
}

}  // namespace
}  // namespace pullout::service
