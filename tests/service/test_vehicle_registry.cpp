// VehicleRegistry's eviction rules on a fake clock and a recording outbox: no DDS, no threads,
// no sleeps. The planner is the real pipeline on the small straight-shoulder world.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <string>
#include <vector>

#include "pullout/pipeline/start_planner.hpp"
#include "pullout/search/stop_condition.hpp"
#include "service/vehicle_registry.hpp"
#include "test_world.hpp"

namespace pullout::service {
namespace {

using Clock = VehicleRegistry::Clock;
using std::chrono::seconds;

class RecordingOutbox : public Outbox {
 public:
  bool publish_path(const PullOutPath& path) override {
    paths.push_back(path);
    return true;
  }
  bool publish_status(const PullOutStatus& status) override {
    statuses.push_back(status);
    return true;
  }
  bool forget_vehicle(const std::string& vehicle_id) override {
    forgotten.push_back(vehicle_id);
    return true;
  }
  bool was_forgotten(const std::string& vehicle_id) const {
    return std::find(forgotten.begin(), forgotten.end(), vehicle_id) != forgotten.end();
  }

  std::vector<PullOutPath> paths;
  std::vector<PullOutStatus> statuses;
  std::vector<std::string> forgotten;
};

class Registry : public ::testing::Test {
 protected:
  void make(std::size_t max_vehicles, double idle_timeout_s) {
    RegistryOptions o;
    o.max_vehicles = max_vehicles;
    o.session_idle_timeout_s = idle_timeout_s;
    o.clock = [this] { return now_; };
    registry_ = std::make_unique<VehicleRegistry>(planner_, outbox_, o);
  }
  void SetUp() override {
    spdlog::set_level(spdlog::level::warn);  // one line per eviction otherwise
    make(8, 60.0);
  }

  PullOutRequest request(const std::string& vehicle, std::uint64_t id) const {
    PullOutRequest r = test::straight_shoulder_request();
    r.vehicle_id = vehicle;
    r.request_id = id;
    return r;
  }
  // A request whose search is ordered but not run: the session is planning.
  PlanningJob start(const std::string& vehicle, std::uint64_t id) {
    std::optional<PlanningJob> job = registry_->on_request(request(vehicle, id), {});
    EXPECT_TRUE(job.has_value()) << vehicle;
    return job ? std::move(*job) : PlanningJob{};
  }
  // A request planned to the end: the session waits for approval (idle).
  void serve(const std::string& vehicle, std::uint64_t id) {
    const PlanningJob job = start(vehicle, id);
    registry_->on_result(job, planner_.plan(job.request, StopCondition()));
  }
  void progress(const std::string& vehicle, std::uint64_t id, std::int64_t stamp_ns, bool approved) {
    ExecutionProgress p;
    p.vehicle_id = vehicle;
    p.request_id = id;
    p.stamp_ns = stamp_ns;
    p.pose = test::straight_shoulder_request().ego_pose;
    p.approved = approved;
    registry_->on_progress(p);
  }
  const PullOutStatus* last_status_of(const std::string& vehicle) const {
    for (auto it = outbox_.statuses.rbegin(); it != outbox_.statuses.rend(); ++it) {
      if (it->vehicle_id == vehicle) return &*it;
    }
    return nullptr;
  }

  StartPlanner planner_{VehicleInfo{}, StartPlannerParameters{}, RequestLimits{}};
  RecordingOutbox outbox_;
  Clock::time_point now_{seconds(1000)};
  std::unique_ptr<VehicleRegistry> registry_;
};

TEST_F(Registry, AnIdleSessionIsEvictedAtTheTimeoutAndItsInstancesForgotten) {
  serve("a", 1);
  now_ += seconds(59);
  registry_->on_time();
  EXPECT_TRUE(registry_->holds("a"));
  EXPECT_FALSE(outbox_.was_forgotten("a"));
  now_ += seconds(1);
  registry_->on_time();
  EXPECT_FALSE(registry_->holds("a"));
  EXPECT_TRUE(outbox_.was_forgotten("a"));
  EXPECT_EQ(registry_->evicted_count(), 1u);
}

TEST_F(Registry, ProgressKeepsASessionActive) {
  serve("a", 1);
  now_ += seconds(50);
  progress("a", 1, 1'000'000'000, false);  // not approved: it still waits, but it is there
  ASSERT_EQ(last_status_of("a")->state, ExecutionState::kWaitingApproval);
  now_ += seconds(50);  // 100 s since the request, 50 s since the progress
  registry_->on_time();
  EXPECT_TRUE(registry_->holds("a"));
}

TEST_F(Registry, ASessionAwaitingItsSearchIsNeverEvicted) {
  const PlanningJob job = start("a", 1);
  registry_->on_instance_gone("a", VehicleInput::kRequest);
  now_ += seconds(100000);
  registry_->on_time();
  EXPECT_TRUE(registry_->holds("a"));
  // Once the result is published it is idle and gone.
  registry_->on_result(job, planner_.plan(job.request, StopCondition()));
  registry_->on_time();
  EXPECT_FALSE(registry_->holds("a"));
}

TEST_F(Registry, ADepartedVehicleIsKeptWhileItsWritersLiveHoweverSilent) {
  serve("a", 1);
  progress("a", 1, 1'000'000'000, true);
  ASSERT_TRUE(last_status_of("a")->departed);
  now_ += seconds(100000);
  registry_->on_time();  // the odometry watchdog stops it; it stays
  EXPECT_TRUE(registry_->holds("a"));
  EXPECT_EQ(last_status_of("a")->state, ExecutionState::kWaitingSafety);
  // Its writers gone too: evicted.
  registry_->on_instance_gone("a", VehicleInput::kRequest);
  registry_->on_instance_gone("a", VehicleInput::kProgress);
  registry_->on_time();
  EXPECT_FALSE(registry_->holds("a"));
}

TEST_F(Registry, AVehicleWhoseWritersAreGoneIsEvictedAsSoonAsItIsIdle) {
  serve("a", 1);
  registry_->on_instance_gone("a", VehicleInput::kRequest);
  registry_->on_time();  // no time passed
  EXPECT_FALSE(registry_->holds("a"));
  EXPECT_TRUE(outbox_.was_forgotten("a"));
}

TEST_F(Registry, AVehicleWithALiveProgressWriterIsNotGone) {
  serve("a", 1);
  progress("a", 1, 1'000'000'000, true);  // a progress instance is alive now
  registry_->on_instance_gone("a", VehicleInput::kRequest);
  registry_->on_time();
  EXPECT_TRUE(registry_->holds("a"));
}

TEST_F(Registry, AFullRegistryEvictsTheLeastRecentlyActiveIdleSession) {
  make(3, 0.0);  // no idle timeout: only capacity evicts
  serve("a", 1);
  now_ += seconds(1);
  serve("b", 2);
  now_ += seconds(1);
  serve("c", 3);
  now_ += seconds(1);
  progress("a", 1, 1'000'000'000, false);  // a is the most recently active now
  now_ += seconds(1);
  serve("d", 4);
  EXPECT_TRUE(registry_->holds("a"));
  EXPECT_FALSE(registry_->holds("b"));
  EXPECT_TRUE(outbox_.was_forgotten("b"));
  EXPECT_TRUE(registry_->holds("c"));
  EXPECT_TRUE(registry_->holds("d"));
  EXPECT_EQ(registry_->size(), 3u);
  ASSERT_NE(last_status_of("d"), nullptr);
  EXPECT_EQ(last_status_of("d")->state, ExecutionState::kWaitingApproval);
}

TEST_F(Registry, AGoneVehicleMakesRoomBeforeAMoreRecentlyActiveOne) {
  make(2, 0.0);
  serve("a", 1);
  now_ += seconds(1);
  serve("b", 2);
  registry_->on_instance_gone("b", VehicleInput::kRequest);  // no sweep ran since
  serve("c", 3);
  EXPECT_TRUE(registry_->holds("a"));
  EXPECT_FALSE(registry_->holds("b"));
}

TEST_F(Registry, WhenNoSessionIsIdleANewVehicleIsRejectedNamingTheLimit) {
  make(2, 60.0);
  start("a", 1);
  start("b", 2);
  const std::optional<PlanningJob> job = registry_->on_request(request("c", 3), {});
  EXPECT_FALSE(job.has_value());
  EXPECT_FALSE(registry_->holds("c"));
  const PullOutStatus* status = last_status_of("c");
  ASSERT_NE(status, nullptr);
  EXPECT_EQ(status->state, ExecutionState::kRejected);
  EXPECT_EQ(status->request_id, 3u);
  EXPECT_NE(status->error.find("service.max_vehicles"), std::string::npos) << status->error;
  // Its instances are not kept for a vehicle without a session.
  EXPECT_TRUE(outbox_.was_forgotten("c"));
  EXPECT_TRUE(registry_->holds("a"));
  EXPECT_TRUE(registry_->holds("b"));
  EXPECT_EQ(registry_->rejected_full_count(), 1u);
}

TEST_F(Registry, ASweepEvictsAtMostItsBound) {
  const std::size_t n = kMaxEvictionsPerSweep + 10;
  make(n, 10.0);
  for (std::size_t i = 0; i < n; ++i) {
    PullOutRequest bad = request("v" + std::to_string(i), i + 1);
    bad.ego_pose.x = std::numeric_limits<double>::quiet_NaN();  // rejected: idle at once
    EXPECT_FALSE(registry_->on_request(bad, {}).has_value());
  }
  ASSERT_EQ(registry_->size(), n);
  now_ += seconds(10);
  registry_->on_time();
  EXPECT_EQ(registry_->size(), n - kMaxEvictionsPerSweep);
  registry_->on_time();
  EXPECT_EQ(registry_->size(), 0u);
  EXPECT_EQ(outbox_.forgotten.size(), n);
}

}  // namespace
}  // namespace pullout::service

namespace pullout::service {
namespace {

// The statistics observers (the service's metrics): one reply per request and outcome, whatever
// the session re-publishes; one call per eviction with its reason.
class RegistryObservers : public Registry {
 protected:
  void SetUp() override {
    spdlog::set_level(spdlog::level::warn);
    RegistryOptions o;
    o.max_vehicles = 2;
    o.session_idle_timeout_s = 60.0;
    o.clock = [this] { return now_; };
    o.on_reply = [this](const PullOutStatus& s) { replies_.push_back(s); };
    o.on_evicted = [this](int reason) { evictions_.push_back(static_cast<EvictionReason>(reason)); };
    registry_ = std::make_unique<VehicleRegistry>(planner_, outbox_, o);
  }
  std::vector<PullOutStatus> replies_;
  std::vector<EvictionReason> evictions_;
};

TEST_F(RegistryObservers, OneReplyPerRequestEvenWhenTheSessionRepublishes) {
  serve("a", 1);
  ASSERT_EQ(replies_.size(), 1u);
  EXPECT_TRUE(has_path(replies_[0].state));
  // The client re-sends the answered request unchanged: the session answers again, no new reply.
  const std::size_t statuses = outbox_.statuses.size();
  EXPECT_FALSE(registry_->on_request(request("a", 1), {}).has_value());
  EXPECT_GT(outbox_.statuses.size(), statuses) << "the session did not re-publish (the check would be void)";
  // Progress changes the state (approved, executing) on the same request: still one reply.
  progress("a", 1, 1'000'000'000, true);
  progress("a", 1, 1'100'000'000, true);
  EXPECT_EQ(replies_.size(), 1u);
  // A new request is a new reply (searched, or answered with the same path under the new id).
  if (std::optional<PlanningJob> job = registry_->on_request(request("a", 2), {})) {
    registry_->on_result(*job, planner_.plan(job->request, StopCondition()));
  }
  ASSERT_EQ(replies_.size(), 2u);
  EXPECT_EQ(replies_[1].request_id, 2u);
}

TEST_F(RegistryObservers, RejectionsAndEvictionsAreReported) {
  PullOutRequest bad = request("b", 1);
  bad.lanes.clear();
  EXPECT_FALSE(registry_->on_request(bad, {}).has_value());
  ASSERT_EQ(replies_.size(), 1u);
  EXPECT_EQ(replies_[0].state, ExecutionState::kRejected);
  serve("a", 1);
  now_ += seconds(60);
  registry_->on_time();
  ASSERT_EQ(evictions_.size(), 2u);
  EXPECT_EQ(evictions_[0], EvictionReason::kIdle);
  EXPECT_EQ(evictions_[1], EvictionReason::kIdle);
}

// A `planning` status kept back (the dispatcher tries the search itself first): never written
// after the result or after a newer request's samples, written first when released before them.
class HeldPlanning : public Registry {
 protected:
  PlanningJob hold(const std::string& vehicle, std::uint64_t id) {
    std::optional<PlanningJob> job = registry_->on_request(request(vehicle, id), {}, /*hold_planning=*/true);
    EXPECT_TRUE(job.has_value()) << vehicle;
    return job ? std::move(*job) : PlanningJob{};
  }
  std::vector<ExecutionState> states_of(const std::string& vehicle) const {
    std::vector<ExecutionState> states;
    for (const PullOutStatus& s : outbox_.statuses) {
      if (s.vehicle_id == vehicle) states.push_back(s.state);
    }
    return states;
  }
};

TEST_F(HeldPlanning, WithoutHoldingThePlanningStatusIsWrittenAtOnce) {
  start("a", 1);
  EXPECT_EQ(states_of("a"), std::vector<ExecutionState>{ExecutionState::kPlanning});
}

TEST_F(HeldPlanning, AQuickResultIsTheFirstSampleAndALateReleaseWritesNothing) {
  const PlanningJob job = hold("a", 1);
  EXPECT_TRUE(outbox_.statuses.empty());
  EXPECT_TRUE(outbox_.paths.empty());
  registry_->on_result(job, planner_.plan(job.request, StopCondition()));
  ASSERT_EQ(outbox_.paths.size(), 1u);
  EXPECT_EQ(states_of("a"), std::vector<ExecutionState>{ExecutionState::kWaitingApproval});
  registry_->release_planning(job);  // too late: the answer is out
  EXPECT_EQ(states_of("a"), std::vector<ExecutionState>{ExecutionState::kWaitingApproval});
}

TEST_F(HeldPlanning, AReleasedPlanningStatusPrecedesTheResult) {
  const PlanningJob job = hold("a", 1);
  registry_->release_planning(job);
  EXPECT_EQ(states_of("a"), std::vector<ExecutionState>{ExecutionState::kPlanning});
  registry_->release_planning(job);  // once only
  registry_->on_result(job, planner_.plan(job.request, StopCondition()));
  EXPECT_EQ(states_of("a"), (std::vector<ExecutionState>{ExecutionState::kPlanning, ExecutionState::kWaitingApproval}));
  EXPECT_EQ(outbox_.statuses.back().request_id, 1u);
}

TEST_F(HeldPlanning, ANewerRequestsSampleDropsTheOlderHeldStatus) {
  const PlanningJob first = hold("a", 1);
  registry_->release_planning(first);  // the vehicle hears of request 1
  const PlanningJob second = hold("a", 2);
  const PlanningJob third = hold("a", 3);
  registry_->release_planning(second);  // request 3 came since: nothing for request 2
  ASSERT_EQ(outbox_.statuses.size(), 1u);
  registry_->release_planning(third);
  ASSERT_EQ(outbox_.statuses.size(), 2u);
  EXPECT_EQ(outbox_.statuses.back().request_id, 3u);
  EXPECT_EQ(outbox_.statuses.back().state, ExecutionState::kPlanning);
  // The second search's result is void; the third's is published.
  registry_->on_result(second, planner_.plan(second.request, StopCondition()));
  EXPECT_EQ(outbox_.statuses.size(), 2u);
  registry_->on_result(third, planner_.plan(third.request, StopCondition()));
  EXPECT_EQ(outbox_.statuses.back().request_id, 3u);
  EXPECT_EQ(outbox_.statuses.back().state, ExecutionState::kWaitingApproval);
}

TEST_F(HeldPlanning, ARepeatedRequestWritesTheCurrentPlanningStatusAndTheHeldOneIsNotWrittenAgain) {
  const PlanningJob job = hold("a", 1);
  PullOutRequest again = job.request;
  EXPECT_FALSE(registry_->on_request(again, {}, /*hold_planning=*/true).has_value());  // no second search
  EXPECT_EQ(states_of("a"), std::vector<ExecutionState>{ExecutionState::kPlanning});
  registry_->release_planning(job);
  EXPECT_EQ(states_of("a"), std::vector<ExecutionState>{ExecutionState::kPlanning});
}

}  // namespace
}  // namespace pullout::service
