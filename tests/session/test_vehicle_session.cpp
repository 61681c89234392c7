// VehicleSession, state by state and transition by transition, on a fake clock: no DDS, no
// threads, no sleeps. The planner is the real pipeline on small worlds and bundled scenarios.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/safety/safety_monitor.hpp"
#include "pullout/search/stop_condition.hpp"
#include "pullout/session/vehicle_session.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

using Clock = VehicleSession::Clock;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr std::int64_t kSecond = 1'000'000'000;

Scenario scenario(const std::string& name) {
  return load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + name + ".yaml");
}

ExecutionProgress sample(std::uint64_t request_id, std::int64_t stamp_ns, const Pose2& pose, double v, bool approved) {
  ExecutionProgress p;
  p.vehicle_id = "test";
  p.request_id = request_id;
  p.stamp_ns = stamp_ns;
  p.pose = pose;
  p.velocity_mps = v;
  p.approved = approved;
  return p;
}

// A session on one world, driven through its life with a clock the test moves.
class Session : public ::testing::Test {
 protected:
  void use(const VehicleInfo& vehicle, const StartPlannerParameters& parameters,
           std::shared_ptr<const LaneletMap> map = nullptr) {
    planner_ = std::make_unique<StartPlanner>(vehicle, parameters, RequestLimits{}, std::move(map));
    session_ = std::make_unique<VehicleSession>("test", *planner_);
  }
  void use(const Scenario& sc) { use(sc.vehicle, sc.parameters, sc.map); }
  void SetUp() override { use(VehicleInfo{}, StartPlannerParameters{}); }

  // Sends the request, runs the search it orders and hands the result back.
  SessionEffects plan(PullOutRequest request) {
    request.vehicle_id = "test";
    SessionEffects ordered = session_->on_request(std::move(request), {}, now_);
    EXPECT_TRUE(ordered.search.has_value());
    EXPECT_EQ(ordered.status->state, ExecutionState::kPlanning);
    if (!ordered.search) return ordered;
    const PlanningResult result = planner_->plan(ordered.search->request, StopCondition());
    return session_->on_result(ordered.search->sequence, result, now_);
  }
  // One sample `dt` after the previous one, on both clocks.
  SessionEffects progress(const Pose2& pose, double v, bool approved, Clock::duration dt = milliseconds(100)) {
    now_ += dt;
    stamp_ += std::chrono::duration_cast<std::chrono::nanoseconds>(dt).count();
    return session_->on_progress(sample(request_id(), stamp_, pose, v, approved), now_);
  }
  std::uint64_t request_id() const { return session_->status().request_id; }
  const PullOutStatus& status() const { return session_->status(); }

  std::unique_ptr<StartPlanner> planner_;
  std::unique_ptr<VehicleSession> session_;
  Clock::time_point now_{seconds(1000)};
  std::int64_t stamp_{5 * kSecond};
};

Pose2 start_of(const PullOutPath& path) { return path.partial_paths.front().points.front().pose; }
Pose2 end_of_segment(const PullOutPath& path, std::size_t i) { return path.partial_paths[i].points.back().pose; }

// --- requests ---

TEST_F(Session, AValidRequestOrdersASearchAndSaysPlanning) {
  SessionEffects e = session_->on_request(test::straight_shoulder_request(), {}, now_);
  ASSERT_TRUE(e.search);
  EXPECT_TRUE(e.cancel_search);
  EXPECT_FALSE(e.path);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kPlanning);
  EXPECT_EQ(e.status->request_id, 1u);
  EXPECT_EQ(e.search->sequence, session_->pending_search());
}

TEST_F(Session, TheNextSearchIsOfferedThePreviousWorldAndARejectionDropsIt) {
  // The first search has nothing to reuse.
  SessionEffects e = session_->on_request(test::straight_shoulder_request(), {}, now_);
  ASSERT_TRUE(e.search);
  EXPECT_EQ(e.search->previous_world, nullptr);
  const PlanningResult r1 = planner_->plan(e.search->request, StopCondition());
  ASSERT_TRUE(r1.world && r1.world->lane_world);
  session_->on_result(e.search->sequence, r1, now_);
  ASSERT_EQ(status().state, ExecutionState::kWaitingApproval);

  // A new goal: a new search, offered the world the path was planned on.
  PullOutRequest next = test::straight_shoulder_request();
  next.request_id = 2;
  next.goal_pose.x = 80.0;
  now_ += seconds(1);
  e = session_->on_request(next, {}, now_);
  ASSERT_TRUE(e.search);
  EXPECT_EQ(e.search->previous_world, r1.world);

  // Rejected: nothing of the earlier requests is kept, nor offered to the one after.
  PullOutRequest bad = next;
  bad.request_id = 3;
  bad.ego_pose.x = std::numeric_limits<double>::quiet_NaN();
  e = session_->on_request(bad, {}, now_);
  ASSERT_EQ(status().state, ExecutionState::kRejected);
  next.request_id = 4;
  e = session_->on_request(next, {}, now_);
  ASSERT_TRUE(e.search);
  EXPECT_EQ(e.search->previous_world, nullptr);
}

TEST_F(Session, AnInvalidRequestIsRejectedWithTheFieldAndNoSearch) {
  PullOutRequest r = test::straight_shoulder_request();
  r.ego_pose.x = std::numeric_limits<double>::quiet_NaN();
  SessionEffects e = session_->on_request(r, {}, now_);
  EXPECT_FALSE(e.search);
  ASSERT_TRUE(e.status && e.path);
  EXPECT_EQ(e.status->state, ExecutionState::kRejected);
  EXPECT_NE(e.status->error.find("ego_pose"), std::string::npos) << e.status->error;
  EXPECT_FALSE(e.path->found);
  EXPECT_TRUE(e.path->partial_paths.empty());
}

TEST_F(Session, ConversionIssuesRejectWithoutFurtherValidation) {
  SessionEffects e = session_->on_request(test::straight_shoulder_request(),
                                          {{"objects[0].pose.orientation", "not a unit quaternion"}}, now_);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kRejected);
  EXPECT_EQ(e.status->error, "objects[0].pose.orientation: not a unit quaternion");
}

TEST_F(Session, AFoundPathWaitsForApprovalWithTheVerdictAtTheStart) {
  const SessionEffects e = plan(test::straight_shoulder_request());
  ASSERT_TRUE(e.path && e.status);
  EXPECT_TRUE(e.path->found);
  EXPECT_EQ(e.status->state, ExecutionState::kWaitingApproval);
  EXPECT_EQ(e.status->stop_reason, "waiting approval");
  EXPECT_TRUE(e.status->safe);
  EXPECT_FALSE(e.status->departed);
  EXPECT_EQ(e.status->segment_count, e.path->partial_paths.size());
}

TEST_F(Session, TheStatusSaysWhereAPathStopsBeforeAnObjectBeyondTheEndPose) {
  const Scenario sc = scenario("car_parked_beyond_end");
  use(sc);
  const SessionEffects e = plan(sc.request);
  ASSERT_TRUE(e.path && e.path->found && e.status);
  EXPECT_NE(e.status->path_end.find("before object 7"), std::string::npos) << e.status->path_end;
  EXPECT_EQ(e.path->partial_paths.back().points.back().longitudinal_velocity_mps, 0.0);
}

TEST_F(Session, AResultOfASupersededSearchIsDropped) {
  SessionEffects first = session_->on_request(test::straight_shoulder_request(), {}, now_);
  PullOutRequest second = test::straight_shoulder_request();
  second.request_id = 2;
  second.goal_pose.x = 80.0;
  SessionEffects later = session_->on_request(second, {}, now_);
  ASSERT_TRUE(first.search && later.search);
  const PlanningResult result = planner_->plan(first.search->request, StopCondition());
  EXPECT_TRUE(session_->on_result(first.search->sequence, result, now_).empty());
  EXPECT_EQ(status().state, ExecutionState::kPlanning);
  EXPECT_EQ(status().request_id, 2u);
}

TEST_F(Session, NoPathIsAStopPathWithTheReason) {
  PullOutRequest r = test::straight_shoulder_request();
  r.objects = {test::parked_car(7, 14.0, 3.25), test::parked_car(8, 5.5, 3.25)};  // boxed in
  StartPlannerParameters p;
  p.freespace_planner.enable_freespace_planner = false;
  use(VehicleInfo{}, p);
  const SessionEffects e = plan(r);
  ASSERT_TRUE(e.status && e.path);
  EXPECT_EQ(e.status->state, ExecutionState::kNoPath);
  EXPECT_FALSE(e.path->found);
  EXPECT_FALSE(e.status->stop_reason.empty());
  EXPECT_FALSE(e.status->evaluation_table.empty());
}

TEST_F(Session, ASearchThatThrewIsNoPathWithTheReason) {
  SessionEffects e = session_->on_request(test::straight_shoulder_request(), {}, now_);
  const SessionEffects failed = session_->on_search_failed(e.search->sequence, "bad_alloc", now_);
  ASSERT_TRUE(failed.status);
  EXPECT_EQ(failed.status->state, ExecutionState::kNoPath);
  EXPECT_EQ(failed.status->stop_reason, "internal error: bad_alloc");
}

// --- approval (defect: approved by default) ---

TEST(ExecutionProgressModel, ApprovalIsNotTheDefault) { EXPECT_FALSE(ExecutionProgress{}.approved); }

TEST_F(Session, ProgressWithoutApprovalNeverDeparts) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  ExecutionProgress p;  // approved as the model defaults it
  p.request_id = request_id();
  for (int i = 1; i <= 20; ++i) {
    now_ += milliseconds(100);
    p.stamp_ns = stamp_ + i * kSecond / 10;
    p.pose = start_of(*found.path);
    session_->on_progress(p, now_);
    EXPECT_EQ(status().state, ExecutionState::kWaitingApproval);
  }
  EXPECT_FALSE(status().departed);
}

TEST_F(Session, ApprovalDepartsWhenSafe) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  const SessionEffects e = progress(start_of(*found.path), 0.0, true);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kExecuting);
  EXPECT_TRUE(e.status->departed);
  EXPECT_EQ(e.status->turn_signal_start_ns, stamp_);
}

TEST_F(Session, ProgressForAnotherRequestIsIgnored) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  now_ += milliseconds(100);
  const SessionEffects e = session_->on_progress(sample(99, stamp_ + kSecond, start_of(*found.path), 0.0, true), now_);
  EXPECT_FALSE(e.status);
  EXPECT_EQ(status().state, ExecutionState::kWaitingApproval);
}

TEST_F(Session, ASampleBeyondTheSpeedLimitIsRefusedWithTheFieldAndChangesNothing) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  progress(start_of(*found.path), 0.0, true);
  ASSERT_EQ(status().state, ExecutionState::kExecuting);
  // After departure a refused approval would insert a stop from this speed: its profile grew with
  // the speed without bound (an infinite speed never ended).
  const SessionEffects e = progress(start_of(*found.path), std::numeric_limits<double>::infinity(), false);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->error, "progress.velocity_mps: not a finite number (infinite)");
  EXPECT_EQ(e.status->state, ExecutionState::kExecuting);
  EXPECT_FALSE(e.path);
  EXPECT_TRUE(status().error.empty());
  const SessionEffects fast = progress(start_of(*found.path), 1e9, false);
  ASSERT_TRUE(fast.status);
  EXPECT_EQ(fast.status->error, "progress.velocity_mps: |speed| 1e+09 exceeds 100 m/s");
  // A valid sample after them is followed as before: the withdrawn approval stops the vehicle.
  const SessionEffects next = progress(start_of(*found.path), 1.0, false);
  ASSERT_TRUE(next.status);
  EXPECT_TRUE(next.status->error.empty());
  EXPECT_TRUE(next.path);
}

TEST_F(Session, PrepareTimeCountsOnlyTimeThatPassedOnTheServiceClock) {
  StartPlannerParameters p;
  p.prepare_time_before_start = 2.0;
  use(VehicleInfo{}, p);
  const SessionEffects found = plan(test::straight_shoulder_request());
  const Pose2 start = start_of(*found.path);
  progress(start, 0.0, true);
  EXPECT_EQ(status().state, ExecutionState::kWaitingSafety);
  EXPECT_EQ(status().stop_reason, "turn signal prepare time");
  // Stamps claim 0.9 s per sample while 0.1 s pass here: never more than the clock saw.
  for (int i = 0; i < 5; ++i) {
    now_ += milliseconds(100);
    stamp_ += 900'000'000;
    session_->on_progress(sample(request_id(), stamp_, start, 0.0, true), now_);
  }
  EXPECT_EQ(status().state, ExecutionState::kWaitingSafety);
  for (int i = 0; i < 16; ++i) progress(start, 0.0, true);  // 1.6 s more on both clocks: 2.1 s in all
  EXPECT_EQ(status().state, ExecutionState::kExecuting);
}

// --- the verdict before departure and the world it is computed on ---

TEST_F(Session, AFastCarFromBehindShowsUnsafeBeforeDepartureAndHolds) {
  const Scenario sc = scenario("traffic_fast_from_behind");
  use(sc);
  const SessionEffects found = plan(sc.request);
  ASSERT_TRUE(found.status);
  EXPECT_EQ(found.status->state, ExecutionState::kWaitingApproval);
  EXPECT_FALSE(found.status->safe);
  EXPECT_EQ(found.status->unsafe_object_id, 21);
  progress(start_of(*found.path), 0.0, true);
  EXPECT_EQ(status().state, ExecutionState::kWaitingSafety);
  EXPECT_NE(status().stop_reason.find("object 21"), std::string::npos) << status().stop_reason;
  EXPECT_FALSE(status().departed);
}

TEST_F(Session, ARouteRequestIsCheckedOnTheMapLanesItWasPlannedOn) {
  const Scenario sc = scenario("map_traffic_fast_from_behind");
  ASSERT_TRUE(sc.request.lanes.empty());
  ASSERT_FALSE(sc.request.route_lanelet_ids.empty());
  use(sc);
  const SessionEffects found = plan(sc.request);
  ASSERT_TRUE(found.path && found.path->found) << found.status->stop_reason;
  EXPECT_FALSE(found.status->safe);
  progress(start_of(*found.path), 0.0, true);
  EXPECT_EQ(status().state, ExecutionState::kWaitingSafety);
  EXPECT_EQ(status().unsafe_object_id, 21);
}

// --- re-sent requests ---

TEST_F(Session, AResentRequestWithinTheThrottleOnlyReplacesTheObjects) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  PullOutRequest again = test::straight_shoulder_request();
  again.request_id = 2;
  now_ += seconds(1);
  const SessionEffects e = session_->on_request(again, {}, now_);
  EXPECT_FALSE(e.search);
  ASSERT_TRUE(e.path && e.status);
  EXPECT_EQ(e.path->request_id, 2u);
  EXPECT_EQ(e.status->request_id, 2u);
  EXPECT_EQ(e.status->state, ExecutionState::kWaitingApproval);
  EXPECT_EQ(e.path->partial_paths.size(), found.path->partial_paths.size());
}

// The client's retry re-sends the very sample (same request id and stamp) until answered.
TEST_F(Session, ARepeatedRequestWhilePlanningOrdersNoSecondSearch) {
  PullOutRequest r = test::straight_shoulder_request();
  r.stamp_ns = 77;
  const SessionEffects first = session_->on_request(r, {}, now_);
  ASSERT_TRUE(first.search);
  now_ += seconds(1);
  const SessionEffects again = session_->on_request(r, {}, now_);
  EXPECT_FALSE(again.search);
  EXPECT_FALSE(again.cancel_search);
  EXPECT_FALSE(again.path);
  ASSERT_TRUE(again.status);
  EXPECT_EQ(again.status->state, ExecutionState::kPlanning);
  EXPECT_EQ(session_->pending_search(), first.search->sequence);
  // The search ordered first still counts.
  const PlanningResult result = planner_->plan(first.search->request, StopCondition());
  const SessionEffects done = session_->on_result(first.search->sequence, result, now_);
  ASSERT_TRUE(done.path);
  EXPECT_TRUE(done.path->found);
}

TEST_F(Session, ARepeatedRequestAfterPlanningRepublishesThePathWithoutASearch) {
  PullOutRequest r = test::straight_shoulder_request();
  r.stamp_ns = 77;
  const SessionEffects found = plan(r);
  ASSERT_TRUE(found.path && found.path->found);
  now_ += seconds(5);  // past the re-plan throttle: a new request would plan afresh
  const SessionEffects again = session_->on_request(r, {}, now_);
  EXPECT_FALSE(again.search);
  ASSERT_TRUE(again.path && again.status);
  EXPECT_EQ(again.path->request_id, r.request_id);
  EXPECT_EQ(again.path->partial_paths.size(), found.path->partial_paths.size());
  EXPECT_EQ(again.status->state, ExecutionState::kWaitingApproval);
}

TEST_F(Session, TheSameIdWithAnotherStampIsANewRequest) {
  PullOutRequest r = test::straight_shoulder_request();
  r.stamp_ns = 77;
  plan(r);
  now_ += seconds(5);
  r.stamp_ns = 78;
  EXPECT_TRUE(session_->on_request(r, {}, now_).search);
}

TEST_F(Session, ARepeatedRejectedRequestIsRejectedAgainWithoutASearch) {
  PullOutRequest r = test::straight_shoulder_request();
  r.ego_pose.x = std::numeric_limits<double>::quiet_NaN();
  ASSERT_EQ(session_->on_request(r, {}, now_).status->state, ExecutionState::kRejected);
  const SessionEffects again = session_->on_request(r, {}, now_);
  EXPECT_FALSE(again.search);
  ASSERT_TRUE(again.status);
  EXPECT_EQ(again.status->state, ExecutionState::kRejected);
}

TEST_F(Session, AResentRequestAfterTheThrottleReplans) {
  plan(test::straight_shoulder_request());
  PullOutRequest again = test::straight_shoulder_request();
  again.request_id = 2;
  now_ += seconds(4);  // backward_path_update_duration is 3 s
  const SessionEffects e = session_->on_request(again, {}, now_);
  EXPECT_TRUE(e.search);
}

TEST_F(Session, AResentRequestIsValidatedInFullBeforeItsObjectsAreKept) {
  const auto resend = [&](std::uint64_t id, auto&& spoil) {
    PullOutRequest r = test::straight_shoulder_request();
    r.request_id = id;
    r.objects = {test::parked_car(5, 60.0, -8.0)};
    spoil(r);
    return session_->on_request(r, {}, now_);
  };
  struct Case {
    const char* field;
    std::function<void(PullOutRequest&)> spoil;
  };
  const std::vector<Case> cases = {
      {"objects", [](PullOutRequest& r) { r.objects.assign(RequestLimits{}.max_objects + 1, r.objects.front()); }},
      {"objects[0].length", [](PullOutRequest& r) { r.objects[0].length_m = -1.0; }},
      {"objects[0].predicted_paths[0].time_step",
       [](PullOutRequest& r) {
         r.objects[0].predicted_paths = {{{{60, -8, 0}, {61, -8, 0}}, 0.0, 1.0}};
       }},
      {"objects[0].predicted_paths[0].confidence",
       [](PullOutRequest& r) {
         r.objects[0].predicted_paths = {{{{60, -8, 0}, {61, -8, 0}}, 1.0, 5.0}};
       }},
  };
  std::uint64_t id = 10;
  for (const Case& c : cases) {
    use(VehicleInfo{}, StartPlannerParameters{});  // a fresh session following a found path
    ASSERT_TRUE(plan(test::straight_shoulder_request()).path->found);
    const SessionEffects e = resend(++id, c.spoil);
    ASSERT_TRUE(e.status) << c.field;
    EXPECT_EQ(e.status->state, ExecutionState::kRejected) << c.field;
    EXPECT_NE(e.status->error.find(c.field), std::string::npos) << c.field << ": " << e.status->error;
    EXPECT_FALSE(e.search);
    // Nothing of it was kept: the vehicle no longer follows the path.
    EXPECT_FALSE(progress({10.0, 3.25, 0.0}, 0.0, true).status);
  }
}

TEST_F(Session, ARejectedRequestKeepsNothingOfItOrOfThePathBefore) {
  PullOutRequest good = test::straight_shoulder_request();
  good.objects = {test::parked_car(5, 60.0, -8.0)};
  ASSERT_TRUE(plan(good).path->found);
  ASSERT_GT(session_->retained().path_points, 0u);  // the followed path
  // Over the objects limit: more objects than a session may keep, none of them kept.
  PullOutRequest huge = test::straight_shoulder_request();
  huge.request_id = 2;
  huge.objects.assign(RequestLimits{}.max_objects + 1, test::parked_car(5, 60.0, -8.0));
  const SessionEffects e = session_->on_request(huge, {}, now_);
  ASSERT_TRUE(e.status);
  ASSERT_EQ(e.status->state, ExecutionState::kRejected);
  EXPECT_EQ(session_->retained().objects, 0u);
  EXPECT_EQ(session_->retained().path_points, 0u);
}

TEST_F(Session, ObjectsAreNotKeptOnceTheSearchReturned) {
  PullOutRequest r = test::straight_shoulder_request();
  r.objects = {test::parked_car(5, 60.0, -8.0), test::parked_car(6, 70.0, -8.0)};
  SessionEffects ordered = session_->on_request(r, {}, now_);
  ASSERT_TRUE(ordered.search);
  EXPECT_EQ(session_->retained().objects, 2u);  // for the safety check of the path to come
  const PlanningResult result = planner_->plan(ordered.search->request, StopCondition());
  ASSERT_TRUE(session_->on_result(ordered.search->sequence, result, now_).path->found);
  EXPECT_EQ(session_->retained().objects, 0u);  // the safety monitor holds them now
  // A no-path keeps no path points either.
  const Scenario boxed = scenario("boxed_in");
  use(boxed);
  const SessionEffects none = plan(boxed.request);
  ASSERT_TRUE(none.status);
  ASSERT_EQ(none.status->state, ExecutionState::kNoPath);
  EXPECT_EQ(session_->retained().objects, 0u);
  EXPECT_EQ(session_->retained().path_points, 0u);
}

TEST_F(Session, AfterDepartureTheFollowedPathIsLatchedAndKeepsItsSegment) {
  const Scenario sc = scenario("car_close_ahead");
  use(sc);
  const SessionEffects found = plan(sc.request);
  ASSERT_GE(found.path->partial_paths.size(), 2u);
  progress(start_of(*found.path), 0.0, true);
  ASSERT_TRUE(status().departed);
  // Finish the reverse leg: at its end, stopped for th_stopped_time.
  const Pose2 end0 = end_of_segment(*found.path, 0);
  for (int i = 0; i < 12; ++i) progress(end0, 0.0, true);
  ASSERT_EQ(status().current_path_idx, 1u);
  PullOutRequest again = sc.request;
  again.request_id = 77;
  again.ego_pose = end0;  // moved away from the start
  now_ += seconds(10);
  const SessionEffects e = session_->on_request(again, {}, now_);
  EXPECT_FALSE(e.search);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->current_path_idx, 1u);
  EXPECT_EQ(e.status->request_id, 77u);
}

// --- progress stamps (defect: stamps trusted) ---

TEST_F(Session, StandstillIsNotCreditedBeyondTheServiceClock) {
  const Scenario sc = scenario("car_close_ahead");
  use(sc);
  const SessionEffects found = plan(sc.request);
  ASSERT_GE(found.path->partial_paths.size(), 2u);
  progress(start_of(*found.path), 0.0, true);
  const Pose2 end0 = end_of_segment(*found.path, 0);
  // A burst of stopped samples whose stamps claim 0.5 s each while 10 ms pass here.
  for (int i = 0; i < 10; ++i) {
    now_ += milliseconds(10);
    stamp_ += kSecond / 2;
    session_->on_progress(sample(request_id(), stamp_, end0, 0.0, true), now_);
  }
  EXPECT_EQ(status().current_path_idx, 0u);
  for (int i = 0; i < 11; ++i) progress(end0, 0.0, true);  // 1.1 s on both clocks
  EXPECT_EQ(status().current_path_idx, 1u);
}

TEST_F(Session, AStaleSampleIsIgnored) {
  const Scenario sc = scenario("car_close_ahead");
  use(sc);
  const SessionEffects found = plan(sc.request);
  progress(start_of(*found.path), 0.0, true);
  const Pose2 end0 = end_of_segment(*found.path, 0);
  progress(end0, 0.5, true);  // arriving, still moving
  // Stopped, but stamped 100 s ago: not after the last accepted sample.
  now_ += milliseconds(100);
  const SessionEffects stale =
      session_->on_progress(sample(request_id(), stamp_ - 100 * kSecond, end0, 0.0, true), now_);
  EXPECT_FALSE(stale.status);
  EXPECT_NE(stale.note.find("not after"), std::string::npos) << stale.note;
  progress(end0, 0.0, true);
  EXPECT_EQ(status().current_path_idx, 0u);
}

TEST_F(Session, ASampleFromTheFarFutureIsIgnored) {
  const Scenario sc = scenario("car_close_ahead");
  use(sc);
  const SessionEffects found = plan(sc.request);
  progress(start_of(*found.path), 0.0, true);
  const Pose2 end0 = end_of_segment(*found.path, 0);
  progress(end0, 0.0, true);
  now_ += milliseconds(100);
  const SessionEffects future =
      session_->on_progress(sample(request_id(), stamp_ + 1'000'000 * kSecond, end0, 0.0, true), now_);
  EXPECT_FALSE(future.status);
  EXPECT_NE(future.note.find("ahead"), std::string::npos) << future.note;
  EXPECT_EQ(status().current_path_idx, 0u);
  // Honest samples go on being accepted (the future one did not become the reference).
  for (int i = 0; i < 11; ++i) progress(end0, 0.0, true);
  EXPECT_EQ(status().current_path_idx, 1u);
}

TEST_F(Session, AClockThatSteppedIsRecoveredFromAfterConsistentSamples) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  const Pose2 start = start_of(*found.path);
  // The first sample comes with a stamp 1e6 s ahead and becomes the reference ...
  now_ += milliseconds(100);
  session_->on_progress(sample(request_id(), stamp_ + 1'000'000 * kSecond, start, 0.0, false), now_);
  // ... then honest samples are refused until kReanchorSamples of them agree.
  for (int i = 1; i < kReanchorSamples; ++i) {
    const SessionEffects e = progress(start, 0.0, true);
    EXPECT_FALSE(e.status) << i;
    EXPECT_EQ(status().state, ExecutionState::kWaitingApproval);
  }
  const SessionEffects e = progress(start, 0.0, true);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kExecuting);
  EXPECT_NE(e.note.find("re-anchored"), std::string::npos) << e.note;
}

TEST_F(Session, InconsistentRefusedSamplesDoNotReplaceTheReference) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  const Pose2 start = start_of(*found.path);
  progress(start, 0.0, false);
  // Stale samples, each older than the one before: they never agree with each other.
  for (int i = 1; i <= 2 * kReanchorSamples; ++i) {
    now_ += milliseconds(100);
    EXPECT_FALSE(session_->on_progress(sample(request_id(), stamp_ - i * kSecond, start, 0.0, true), now_).status);
  }
  EXPECT_EQ(status().state, ExecutionState::kWaitingApproval);
}

// --- after departure ---

TEST_F(Session, TrafficAfterDepartureInsertsAStopAndTheStoppedVehicleResumes) {
  const Scenario fast = scenario("traffic_fast_from_behind");
  use(fast);
  PullOutRequest clear = fast.request;
  clear.objects.clear();
  const SessionEffects found = plan(clear);
  const Pose2 start = start_of(*found.path);
  progress(start, 0.0, true);
  ASSERT_EQ(status().state, ExecutionState::kExecuting);
  progress(start, 1.0, true);
  // The car appears: a re-sent request (latched, objects only).
  PullOutRequest with_car = fast.request;
  with_car.request_id = 2;
  now_ += milliseconds(100);
  ASSERT_FALSE(session_->on_request(with_car, {}, now_).search);
  const SessionEffects stop = progress(start, 1.0, true);
  ASSERT_TRUE(stop.path && stop.status);
  EXPECT_EQ(stop.status->state, ExecutionState::kWaitingSafety);
  EXPECT_EQ(stop.path->request_id, 2u);
  EXPECT_TRUE(stop.path->found);
  EXPECT_EQ(stop.path->partial_paths.back().points.back().longitudinal_velocity_mps, 0.0);
  // The car is gone and the vehicle stands: the original path again.
  PullOutRequest gone = clear;
  gone.request_id = 3;
  now_ += milliseconds(100);
  session_->on_request(gone, {}, now_);
  const SessionEffects resume = progress(start, 0.0, true);
  ASSERT_TRUE(resume.path && resume.status);
  EXPECT_EQ(resume.status->state, ExecutionState::kExecuting);
  EXPECT_EQ(resume.path->partial_paths.front().points[5].longitudinal_velocity_mps,
            found.path->partial_paths.front().points[5].longitudinal_velocity_mps);
}

TEST_F(Session, WithdrawnApprovalAfterDepartureInsertsAStop) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  const Pose2 start = start_of(*found.path);
  progress(start, 0.0, true);
  const SessionEffects e = progress(start, 1.0, false);
  ASSERT_TRUE(e.path && e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kWaitingSafety);
  EXPECT_EQ(e.status->stop_reason, "approval withdrawn");
}

TEST_F(Session, LostOdometryAfterDepartureInsertsAStop) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  const Pose2 start = start_of(*found.path);
  progress(start, 0.0, true);
  progress(start, 2.0, true);
  ASSERT_EQ(status().state, ExecutionState::kExecuting);
  EXPECT_TRUE(session_->on_time(now_ + milliseconds(1900)).empty());
  const SessionEffects e = session_->on_time(now_ + milliseconds(2100));
  ASSERT_TRUE(e.path && e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kWaitingSafety);
  EXPECT_NE(e.status->stop_reason.find("odometry lost"), std::string::npos);
  EXPECT_EQ(e.path->partial_paths.back().points.back().longitudinal_velocity_mps, 0.0);
}

TEST_F(Session, WaitingVehiclesAreNotStoppedByTheWatchdog) {
  plan(test::straight_shoulder_request());
  EXPECT_TRUE(session_->on_time(now_ + seconds(60)).empty());
}

TEST_F(Session, PassingTheEndPoseCompletes) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  progress(start_of(*found.path), 0.0, true);
  Pose2 past = found.path->end_pose;
  past.x += 0.5;
  const SessionEffects e = progress(past, 5.0, true);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kCompleted);
  // Nothing is followed any more.
  EXPECT_FALSE(progress(past, 5.0, true).status);
}

TEST_F(Session, AnUndeliverablePathIsNotFollowed) {
  const SessionEffects found = plan(test::straight_shoulder_request());
  const SessionEffects e = session_->on_path_undeliverable(found.path->request_id);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kNoPath);
  EXPECT_FALSE(progress(start_of(*found.path), 0.0, true).status);
}

// --- restore (a replica taking a vehicle over, a restart) ---

class RestoredSession : public Session {
 protected:
  // Plans car_close_ahead, departs and finishes the reverse leg: executing segment 1 of 2.
  void drive_to_second_segment() {
    sc_ = scenario("car_close_ahead");
    use(sc_);
    sc_.request.vehicle_id = "test";
    found_ = *plan(sc_.request).path;
    ASSERT_GE(found_.partial_paths.size(), 2u);
    progress(start_of(found_), 0.0, true);
    const Pose2 end0 = end_of_segment(found_, 0);
    for (int i = 0; i < 12; ++i) progress(end0, 0.0, true);
    ASSERT_EQ(status().current_path_idx, 1u);
    ASSERT_EQ(status().state, ExecutionState::kExecuting);
  }
  SessionSnapshot snapshot() const { return SessionSnapshot{sc_.request, found_, status()}; }
  // A new session (another process) restored from `snap`.
  SessionEffects restore_into_new(const SessionSnapshot& snap, bool with_world = true) {
    std::vector<RequestIssue> issues;
    auto world = with_world ? planner_->planned_world(snap.request, issues) : nullptr;
    EXPECT_TRUE(issues.empty());
    session_ = std::make_unique<VehicleSession>("test", *planner_);
    now_ += seconds(1);
    return session_->restore(snap, world, now_);
  }
  Scenario sc_;
  PullOutPath found_;
};

TEST_F(RestoredSession, AVehicleInMidManoeuvreKeepsItsPathSegmentAndDeparture) {
  drive_to_second_segment();
  const SessionSnapshot snap = snapshot();
  const SessionEffects e = restore_into_new(snap);
  ASSERT_TRUE(e.path && e.status);
  EXPECT_FALSE(e.search);
  EXPECT_EQ(e.path->request_id, found_.request_id);
  EXPECT_EQ(e.path->partial_paths.size(), found_.partial_paths.size());
  EXPECT_TRUE(e.path->found);
  EXPECT_EQ(e.status->current_path_idx, 1u);
  EXPECT_TRUE(e.status->departed);
  EXPECT_EQ(e.status->state, ExecutionState::kExecuting);
  // The next approved sample on segment 1 keeps it executing there: no second approval, no
  // prepare time, no restart from segment 0.
  const auto& seg1 = found_.partial_paths[1].points;
  const SessionEffects next = progress(seg1[1].pose, 1.0, true);
  EXPECT_EQ(status().state, ExecutionState::kExecuting);
  EXPECT_EQ(status().current_path_idx, 1u);
  EXPECT_TRUE(status().departed);
  (void)next;
}

TEST_F(RestoredSession, WithoutTheRequestsWorldNothingMayDrive) {
  drive_to_second_segment();
  const SessionEffects e = restore_into_new(snapshot(), false);
  ASSERT_TRUE(e.path && e.status);
  EXPECT_FALSE(e.path->found);
  EXPECT_EQ(e.status->state, ExecutionState::kNoPath);
  EXPECT_NE(e.status->stop_reason.find("send the request again"), std::string::npos) << e.status->stop_reason;
  progress(end_of_segment(found_, 0), 0.0, true);
  EXPECT_NE(status().state, ExecutionState::kExecuting);
}

// A replica that took the vehicle over saw its re-sent request but not the status that answered
// it: the later request gives the world, and handled after the restore it latches onto the path.
TEST_F(RestoredSession, WithTheWorldOfALaterRequestTheVehicleKeepsItsSegmentUnderThatRequest) {
  drive_to_second_segment();
  PullOutRequest later = sc_.request;
  later.request_id = sc_.request.request_id + 1;
  later.stamp_ns = sc_.request.stamp_ns + 1'000'000'000;
  later.ego_pose = end_of_segment(found_, 0);
  SessionSnapshot snap = snapshot();
  snap.request = later;
  snap.request_is_later = true;
  const SessionEffects e = restore_into_new(snap);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kExecuting);
  EXPECT_EQ(e.status->request_id, sc_.request.request_id);
  const SessionEffects again = session_->on_request(later, {}, now_);
  EXPECT_FALSE(again.search) << "a departed vehicle's path is latched, not planned again";
  ASSERT_TRUE(again.status && again.path);
  EXPECT_EQ(again.status->request_id, later.request_id);
  EXPECT_EQ(again.status->current_path_idx, 1u);
  EXPECT_TRUE(again.status->departed);
  EXPECT_EQ(again.status->state, ExecutionState::kExecuting);
  EXPECT_EQ(again.path->partial_paths.size(), found_.partial_paths.size());
  // Without the flag, a request that is not the one the status answers gives no world.
  snap.request_is_later = false;
  const SessionEffects refused = restore_into_new(snap);
  ASSERT_TRUE(refused.status);
  EXPECT_EQ(refused.status->state, ExecutionState::kNoPath);
}

// A bus restored by another process is checked with the bus's footprint, not the configured car's:
// a car comes from behind at 5 m/s, 33 m back, on the road the bus pulls out onto. The car's RSS
// distance leaves room for a car's rear (1.1 m behind its rear axle) but not for the bus's (3.5 m).
TEST_F(RestoredSession, ABusIsCheckedWithItsOwnFootprintNotTheConfiguredCars) {
  planner_ = std::make_unique<StartPlanner>(VehicleInfo{}, StartPlannerParameters{}, RequestLimits{}, nullptr,
                                            default_vehicle_profiles());
  session_ = std::make_unique<VehicleSession>("test", *planner_);
  PullOutRequest request = test::straight_shoulder_request();
  // The lanes lengthened backwards, so that the car behind is on the road.
  request.lanes = {test::straight_lane(1, LaneSubtype::kRoad, -200, 100, -1.75, 1.75),
                   test::straight_lane(2, LaneSubtype::kRoadShoulder, -200, 100, 1.75, 4.75)};
  request.vehicle_profile = "bus";
  Object behind = test::parked_car(21, -33.0, 0.0);
  behind.velocity_mps = 5.0;
  request.objects = {behind};
  const SessionEffects found = plan(request);
  ASSERT_TRUE(found.path && found.status);
  ASSERT_TRUE(found.path->found);
  EXPECT_FALSE(found.status->safe);
  sc_.request = request;
  sc_.request.vehicle_id = "test";
  found_ = *found.path;
  const Pose2 start = start_of(found_);

  // What makes the difference: the same path and world checked with the configured car's
  // footprint is safe, with the bus's it is not.
  std::vector<RequestIssue> issues;
  const auto world = planner_->planned_world(sc_.request, issues);
  ASSERT_TRUE(world && issues.empty());
  ASSERT_EQ(world->vehicle, default_vehicle_profiles().at("bus"));
  SafetyMonitor as_car(planner_->parameters(), VehicleInfo{}, world->lanes, world->objects, found_);
  ASSERT_TRUE(as_car.evaluate(start, 0.0, 0, false).safe);
  SafetyMonitor as_bus(planner_->parameters(), world->vehicle, world->lanes, world->objects, found_);
  ASSERT_FALSE(as_bus.evaluate(start, 0.0, 0, false).safe);

  const SessionEffects e = restore_into_new(snapshot());
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kWaitingApproval);
  progress(start, 0.0, true);
  EXPECT_EQ(status().state, ExecutionState::kWaitingSafety);
  EXPECT_FALSE(status().departed);
  EXPECT_NE(status().stop_reason.find("object 21"), std::string::npos) << status().stop_reason;
}

TEST_F(RestoredSession, AWaitingVehicleStillNeedsItsApproval) {
  sc_ = scenario("car_close_ahead");
  use(sc_);
  sc_.request.vehicle_id = "test";
  found_ = *plan(sc_.request).path;
  ASSERT_EQ(status().state, ExecutionState::kWaitingApproval);
  const SessionEffects e = restore_into_new(snapshot());
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kWaitingApproval);
  progress(start_of(found_), 0.0, false);
  EXPECT_EQ(status().state, ExecutionState::kWaitingApproval);
  EXPECT_FALSE(status().departed);
}

TEST_F(RestoredSession, ASearchThatDiedWithItsProcessRunsAgain) {
  sc_ = scenario("car_close_ahead");
  use(sc_);
  sc_.request.vehicle_id = "test";
  const SessionEffects planning = session_->on_request(sc_.request, {}, now_);
  ASSERT_EQ(planning.status->state, ExecutionState::kPlanning);
  const SessionEffects e = restore_into_new(SessionSnapshot{sc_.request, std::nullopt, *planning.status});
  ASSERT_TRUE(e.search);
  EXPECT_EQ(e.search->request.request_id, sc_.request.request_id);
  ASSERT_TRUE(e.status);
  EXPECT_EQ(e.status->state, ExecutionState::kPlanning);
}

}  // namespace
}  // namespace pullout
