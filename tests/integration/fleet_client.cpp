#include "fleet_client.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>

#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/idl/topics.hpp"

namespace pullout::integration {
namespace {

namespace dds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;
using Clock = std::chrono::steady_clock;

dds::Topic* make_topic(dds::DomainParticipant& participant, const char* name, dds::TopicDataType* type_ptr) {
  dds::TypeSupport type(type_ptr);
  if (type.register_type(&participant) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error(std::string("FleetClient: cannot register the type of ") + name);
  }
  dds::Topic* topic = participant.create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) throw std::runtime_error(std::string("FleetClient: cannot create topic ") + name);
  return topic;
}

}  // namespace

FleetClient::FleetClient(int domain, const std::string& profiles_file) {
  auto* factory = dds::DomainParticipantFactory::get_instance();
  if (factory->load_XML_profiles_file(profiles_file) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("FleetClient: cannot load " + profiles_file);
  }
  participant_ = factory->create_participant_with_profile(domain, idl::kParticipantProfile);
  if (participant_ == nullptr) throw std::runtime_error("FleetClient: cannot create the participant");
  auto* request_topic =
      make_topic(*participant_, idl::kRequestTopic, idl::make_guarded_type<msg::PullOutRequestPubSubType>());
  auto* path_topic = make_topic(*participant_, idl::kPathTopic, idl::make_guarded_type<msg::PullOutPathPubSubType>());
  auto* status_topic =
      make_topic(*participant_, idl::kStatusTopic, idl::make_guarded_type<msg::PullOutStatusPubSubType>());
  auto* publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  auto* subscriber = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher == nullptr || subscriber == nullptr) throw std::runtime_error("FleetClient: publisher/subscriber");
  request_writer_ = publisher->create_datawriter_with_profile(request_topic, idl::kRequestWriterProfile);
  path_reader_ = subscriber->create_datareader_with_profile(path_topic, idl::kPathReaderProfile);
  status_reader_ = subscriber->create_datareader_with_profile(status_topic, idl::kStatusReaderProfile);
  if (request_writer_ == nullptr || path_reader_ == nullptr || status_reader_ == nullptr) {
    participant_->delete_contained_entities();
    factory->delete_participant(participant_);
    throw std::runtime_error("FleetClient: cannot create the endpoints from " + profiles_file);
  }
  waitset_ = std::make_unique<dds::WaitSet>();
  for (dds::DataReader* reader : {path_reader_, status_reader_}) {
    reader->get_statuscondition().set_enabled_statuses(dds::StatusMask::data_available());
    waitset_->attach_condition(reader->get_statuscondition());
  }
}

FleetClient::~FleetClient() {
  waitset_->detach_condition(path_reader_->get_statuscondition());
  waitset_->detach_condition(status_reader_->get_statuscondition());
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

bool FleetClient::wait_matched(std::chrono::milliseconds timeout) {
  const auto until = Clock::now() + timeout;
  while (true) {
    dds::PublicationMatchedStatus requests;
    dds::SubscriptionMatchedStatus paths;
    dds::SubscriptionMatchedStatus statuses;
    request_writer_->get_publication_matched_status(requests);
    path_reader_->get_subscription_matched_status(paths);
    status_reader_->get_subscription_matched_status(statuses);
    if (requests.current_count >= 1 && paths.current_count >= 1 && statuses.current_count >= 1) return true;
    if (Clock::now() >= until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

bool FleetClient::send(const PullOutRequest& request) {
  watched_.insert(request.vehicle_id);
  paths_gone_.erase(request.vehicle_id);
  msg::PullOutRequest sample = idl::to_msg(request);
  return request_writer_->write(&sample);
}

bool FleetClient::forget(const std::string& vehicle_id, bool await_gone) {
  drain();
  watched_.erase(vehicle_id);
  if (await_gone) awaiting_gone_.insert(vehicle_id);
  for (auto it = statuses_.begin(); it != statuses_.end();) {
    it = it->first.first == vehicle_id ? statuses_.erase(it) : std::next(it);
  }
  for (auto it = paths_.begin(); it != paths_.end();)
    it = it->first.first == vehicle_id ? paths_.erase(it) : std::next(it);
  msg::PullOutRequest key;
  key.vehicle_id(vehicle_id);
  return request_writer_->unregister_instance(&key, dds::HANDLE_NIL) == ReturnCode_t::RETCODE_OK;
}

void FleetClient::drain() {
  dds::SampleInfo info;
  msg::PullOutPath path;
  while (path_reader_->take_next_sample(&path, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) {
      if (info.instance_state != dds::ALIVE_INSTANCE_STATE) {
        const auto it = path_instances_.find(info.instance_handle);
        if (it != path_instances_.end()) {
          if (watched_.count(it->second) != 0 || awaiting_gone_.count(it->second) != 0) paths_gone_.insert(it->second);
          path_instances_.erase(it);
        }
      }
      continue;
    }
    path_instances_[info.instance_handle] = path.vehicle_id();
    if (watched_.count(path.vehicle_id()) == 0) continue;
    PullOutPath model = idl::from_msg(path);
    paths_[{model.vehicle_id, model.request_id}] = std::move(model);
  }
  msg::PullOutStatus status;
  while (status_reader_->take_next_sample(&status, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || watched_.count(status.vehicle_id()) == 0) continue;
    PullOutStatus model = idl::from_msg(status);
    if (model.state == ExecutionState::kPlanning) continue;
    statuses_.try_emplace({model.vehicle_id, model.request_id}, std::move(model));
  }
}

std::optional<FleetClient::Answer> FleetClient::wait_answer(const std::string& vehicle_id, std::uint64_t request_id,
                                                            std::chrono::milliseconds timeout) {
  const auto until = Clock::now() + timeout;
  const auto key = std::make_pair(vehicle_id, request_id);
  while (true) {
    drain();
    const auto status = statuses_.find(key);
    const auto path = paths_.find(key);
    if (status != statuses_.end() && path != paths_.end()) return Answer{status->second, path->second};
    if (Clock::now() >= until) return std::nullopt;
    wait_data(until);
  }
}

bool FleetClient::wait_path_gone(const std::string& vehicle_id, std::chrono::milliseconds timeout) {
  const auto until = Clock::now() + timeout;
  while (true) {
    drain();
    if (paths_gone_.count(vehicle_id) != 0) {
      if (watched_.count(vehicle_id) == 0) {
        paths_gone_.erase(vehicle_id);
        awaiting_gone_.erase(vehicle_id);
      }
      return true;
    }
    if (Clock::now() >= until) return false;
    wait_data(until);
  }
}

void FleetClient::wait_data(Clock::time_point until) {
  const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(until - Clock::now()).count();
  if (left <= 0) return;
  // At most 50 ms at a time: a wake-up lost between drain() and wait() costs no more than that.
  const std::int64_t ns = std::min<std::int64_t>(left, 50'000'000);
  dds::ConditionSeq active;
  waitset_->wait(active, eprosima::fastrtps::Duration_t(0, static_cast<std::uint32_t>(ns)));
}

}  // namespace pullout::integration
