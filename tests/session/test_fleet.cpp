// Vehicles that see each other (pullout/session/fleet.hpp), in the core: two sessions, a
// FleetBoard between them as the registry keeps it, the scenario tests/scenarios/
// fleet_opposite_shoulders.yaml (fleet-a executing, fleet-b in the neighbouring spot), a fake clock.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>

#include "pullout/config/scenario.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/search/stop_condition.hpp"
#include "pullout/session/fleet.hpp"
#include "pullout/session/vehicle_session.hpp"

namespace pullout {
namespace {

using Clock = VehicleSession::Clock;
using std::chrono::milliseconds;

constexpr double kRadius = 200.0;

// One vehicle: its session, its request id and its clocks.
struct Vehicle {
  Vehicle(const std::string& id, const StartPlanner& planner) : vehicle_id(id), session(id, planner) {}
  std::string vehicle_id;
  VehicleSession session;
  std::int64_t stamp_ns{5'000'000'000};
  PullOutPath path;
};

class Fleet : public ::testing::Test {
 protected:
  void SetUp() override {
    sc_ = load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/fleet_opposite_shoulders.yaml");
    ASSERT_EQ(sc_.fleet.size(), 1u);
    planner_ = std::make_unique<StartPlanner>(sc_.vehicle, sc_.parameters, RequestLimits{}, sc_.map);
    a_ = std::make_unique<Vehicle>(sc_.fleet[0].vehicle_id, *planner_);
    b_ = std::make_unique<Vehicle>(sc_.request.vehicle_id, *planner_);
  }

  // Plans `request` for `v` with the other vehicles on the board as objects (as the registry does).
  void plan(Vehicle& v, const PullOutRequest& request) {
    SessionEffects ordered = v.session.on_request(request, {}, now_);
    ASSERT_TRUE(ordered.search);
    PullOutRequest search = ordered.search->request;
    for (FleetObstacle& o : board_.obstacles_for(v.vehicle_id, search.ego_pose, kRadius)) {
      search.objects.push_back(o.object);
    }
    const PlanningResult result = planner_->plan(search, StopCondition());
    ASSERT_EQ(result.outcome, PlanningResult::Outcome::kFound) << v.vehicle_id << ": " << result.stop_reason;
    v.session.on_result(ordered.search->sequence, result, now_);
    v.path = result.path;
  }
  // One approved sample of `v` (100 ms later), with the others on the board; the board updated after.
  const PullOutStatus& report(Vehicle& v, const Pose2& pose, double velocity) {
    now_ += milliseconds(100);
    v.stamp_ns += 100'000'000;
    ExecutionProgress p;
    p.vehicle_id = v.vehicle_id;
    p.request_id = v.session.status().request_id;
    p.stamp_ns = v.stamp_ns;
    p.pose = pose;
    p.velocity_mps = velocity;
    p.approved = true;
    v.session.on_progress(p, now_, board_.obstacles_for(v.vehicle_id, pose, kRadius));
    if (auto e = v.session.executing()) {
      board_.update(std::move(*e));
    } else {
      board_.remove(v.vehicle_id);
    }
    return v.session.status();
  }
  static Pose2 start_of(const PullOutPath& path) { return path.partial_paths.front().points.front().pose; }

  Scenario sc_;
  std::unique_ptr<StartPlanner> planner_;
  std::unique_ptr<Vehicle> a_;
  std::unique_ptr<Vehicle> b_;
  FleetBoard board_;
  Clock::time_point now_{std::chrono::seconds(1000)};
};

TEST_F(Fleet, AVehicleInTheNeighbouringSpotWaitsForTheExecutingOneUntilItsProgressHasPassed) {
  plan(*a_, sc_.fleet[0]);
  ASSERT_EQ(report(*a_, start_of(a_->path), 0.0).state, ExecutionState::kExecuting);
  ASSERT_TRUE(board_.holds("fleet-a"));

  plan(*b_, sc_.request);
  const PullOutStatus held = report(*b_, start_of(b_->path), 0.0);
  EXPECT_EQ(held.state, ExecutionState::kWaitingSafety);
  EXPECT_FALSE(held.departed);
  EXPECT_EQ(held.waiting_for_vehicle_id, "fleet-a");
  EXPECT_NE(held.stop_reason.find("fleet-a"), std::string::npos) << held.stop_reason;
  ASSERT_TRUE(sc_.expect.waits_for);
  EXPECT_EQ(*sc_.expect.waits_for, held.waiting_for_vehicle_id);

  // fleet-a drives its path; fleet-b asks again after each of its samples. fleet-b departs only
  // once fleet-a's remaining path no longer crosses its own.
  bool b_departed = false;
  std::size_t a_points = 0;
  for (const auto& segment : a_->path.partial_paths) {
    for (const auto& point : segment.points) {
      ++a_points;
      const double v = point.longitudinal_velocity_mps == 0.0 ? 0.5 : point.longitudinal_velocity_mps;
      report(*a_, point.pose, v);
      const PullOutStatus& b = report(*b_, start_of(b_->path), 0.0);
      if (b.state == ExecutionState::kExecuting) {
        b_departed = true;
        EXPECT_TRUE(b.waiting_for_vehicle_id.empty());
        // At that moment fleet-a's remaining path and body are clear of fleet-b's path.
        const auto a_now = a_->session.executing();
        if (a_now) {
          EXPECT_FALSE(first_fleet_conflict(b_->path, 0, start_of(b_->path), planner_->vehicle(), 0.5,
                                            {fleet_obstacle(*a_now, true, -1)}));
        }
        break;
      }
      EXPECT_EQ(b.waiting_for_vehicle_id, "fleet-a") << "fleet-a at point " << a_points;
    }
    if (b_departed) break;
  }
  if (!b_departed) {
    // fleet-a passed its end pose: it completes and leaves the board, then fleet-b goes.
    const Pose2 end = a_->path.partial_paths.back().points.back().pose;
    for (int i = 0; i < 50 && a_->session.status().state != ExecutionState::kCompleted; ++i) {
      report(*a_, {end.x + 0.5 * (i + 1), end.y, end.yaw}, 2.0);
    }
    ASSERT_EQ(a_->session.status().state, ExecutionState::kCompleted);
    EXPECT_FALSE(board_.holds("fleet-a"));
    const PullOutStatus& b = report(*b_, start_of(b_->path), 0.0);
    EXPECT_EQ(b.state, ExecutionState::kExecuting);
    b_departed = b.state == ExecutionState::kExecuting;
  }
  EXPECT_TRUE(b_departed);
  EXPECT_GT(a_points, 1u) << "fleet-b did not wait while fleet-a started out";
}

TEST_F(Fleet, WithoutTheOtherVehicleExecutingItDepartsAtOnce) {
  // Control: fleet-a planned and approved-to-be, but not departed (no sample): not on the board.
  plan(*a_, sc_.fleet[0]);
  EXPECT_FALSE(board_.holds("fleet-a"));
  plan(*b_, sc_.request);
  const PullOutStatus& b = report(*b_, start_of(b_->path), 0.0);
  EXPECT_EQ(b.state, ExecutionState::kExecuting);
  EXPECT_TRUE(b.waiting_for_vehicle_id.empty());
}

TEST_F(Fleet, TheVehicleThatDepartedFirstDoesNotWaitForTheOtherOnesPath) {
  plan(*a_, sc_.fleet[0]);
  plan(*b_, sc_.request);
  ASSERT_EQ(report(*a_, start_of(a_->path), 0.0).state, ExecutionState::kExecuting);
  EXPECT_EQ(report(*b_, start_of(b_->path), 0.0).state, ExecutionState::kWaitingSafety);
  // fleet-a's next sample sees fleet-b only as a body beside the road: it keeps executing.
  const auto& first = a_->path.partial_paths.front().points;
  const PullOutStatus& a = report(*a_, first[std::min<std::size_t>(1, first.size() - 1)].pose, 1.0);
  EXPECT_EQ(a.state, ExecutionState::kExecuting);
  EXPECT_TRUE(a.waiting_for_vehicle_id.empty());
}

TEST(FleetObstacle, TheOtherVehicleIsItsOwnFootprintWithItsRemainingPathTimedByItsVelocityProfile) {
  ExecutingPath other;
  other.vehicle_id = "bus-1";
  other.vehicle.wheel_base_m = 5.9;
  other.vehicle.rear_overhang_m = 3.5;
  other.vehicle.front_overhang_m = 2.6;
  PathWithLaneId segment;
  for (int i = 0; i <= 20; ++i) {  // 20 m straight at 2 m/s
    PathPoint p;
    p.pose = {static_cast<double>(i), 0.0, 0.0};
    p.longitudinal_velocity_mps = 2.0;
    segment.points.push_back(p);
  }
  other.path.partial_paths = {segment};
  other.pose = {5.0, 0.0, 0.0};
  other.velocity_mps = 2.0;
  const FleetObstacle o = fleet_obstacle(other, true, -3);
  EXPECT_EQ(o.vehicle_id, "bus-1");
  EXPECT_EQ(o.object.id, -3);
  EXPECT_DOUBLE_EQ(o.object.length_m, 12.0);
  EXPECT_EQ(o.swept.size(), 16u) << "points 5..20";
  ASSERT_EQ(o.object.predicted_paths.size(), 1u);
  const PredictedPath& predicted = o.object.predicted_paths.front();
  EXPECT_DOUBLE_EQ(predicted.time_step_s, kFleetTimeStep);
  // 2 m/s: 1 m every 0.5 s, from x = 5 to x = 20 (15 m in 7.5 s: 15 steps), then standing at the end.
  ASSERT_EQ(predicted.poses.size(), 17u);
  EXPECT_NEAR(predicted.poses[4].x, 9.0, 1e-9);
  EXPECT_NEAR(predicted.poses[15].x, 20.0, 1e-9);
  EXPECT_NEAR(predicted.poses[16].x, 20.0, 1e-9);
  // Body only: no path.
  EXPECT_TRUE(fleet_obstacle(other, false, -3).swept.empty());
  EXPECT_TRUE(fleet_obstacle(other, false, -3).object.predicted_paths.empty());
}

}  // namespace
}  // namespace pullout
