// Mixed vehicles: one StartPlanner plans each request with that request's vehicle (its own
// dimensions, a profile of the config, or the default), and rejects bad ones naming the field.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "pullout/collision/footprint.hpp"
#include "pullout/config/config.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/safety/rss_check.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

// One planner for the whole fleet: the default car and the shipped profiles (car, van, bus).
const StartPlanner& fleet_planner() {
  static const StartPlanner planner(VehicleInfo{}, StartPlannerParameters{}, RequestLimits{}, nullptr,
                                    default_vehicle_profiles());
  return planner;
}

const VehicleInfo& profile(const std::string& name) { return fleet_planner().profiles().at(name); }

// A car parked on the shoulder behind the vehicle: its box spans x in [2.75, 7.25]. The vehicle's
// rear axle is at x = 10, so its rear bumper is at 10 - rear_overhang: 8.9 for the car (1.65 m
// clear), 8.65 for the van (1.4 m clear) and 6.5 for the bus, whose rear overlaps the parked car.
PullOutRequest request_with_car_behind(const std::string& vehicle_profile) {
  PullOutRequest r = test::straight_shoulder_request();
  r.objects = {test::parked_car(7, 5.0, 3.25)};
  r.vehicle_profile = vehicle_profile;
  return r;
}

bool has_issue(const std::vector<RequestIssue>& issues, const std::string& field) {
  for (const auto& i : issues) {
    if (i.field == field) return true;
  }
  return false;
}

// Every pose of the path, with `vehicle`'s footprint, clear of every object.
void expect_clear(const PullOutPath& path, const VehicleInfo& vehicle, const std::vector<Object>& objects) {
  const Footprint footprint = vehicle_footprint(vehicle);
  for (const auto& segment : path.partial_paths) {
    for (const auto& point : segment.points) {
      for (const auto& object : objects) {
        EXPECT_FALSE(polygons_intersect(footprint_polygon(footprint, point.pose), object_polygon(object)))
            << "object " << object.id << " at (" << point.pose.x << ", " << point.pose.y << ")";
      }
    }
  }
}

TEST(MixedVehicles, TheShippedProfilesDifferWhereItMatters) {
  // The test below relies on these: a bus longer behind its rear axle and wider than a car.
  EXPECT_GT(profile("bus").rear_overhang_m, 10.0 - 7.25);
  EXPECT_LT(profile("car").rear_overhang_m, 10.0 - 7.25);
  EXPECT_LT(profile("van").rear_overhang_m, 10.0 - 7.25);
  EXPECT_GT(profile("bus").width_m(), profile("car").width_m());
  EXPECT_GT(profile("bus").min_turning_radius_m(), profile("car").min_turning_radius_m());
}

TEST(MixedVehicles, ACarAVanAndABusArePlannedWithTheirOwnFootprintsInOneRun) {
  const StartPlanner& planner = fleet_planner();
  for (const char* name : {"car", "van"}) {
    SCOPED_TRACE(name);
    const PullOutRequest r = request_with_car_behind(name);
    const PlanningResult result = planner.plan(r, StopCondition());
    ASSERT_EQ(result.outcome, PlanningResult::Outcome::kFound) << result.stop_reason;
    ASSERT_TRUE(result.world);
    EXPECT_EQ(result.world->vehicle, profile(name));  // the safety checks get this vehicle too
    expect_clear(result.path, profile(name), r.objects);
  }
  // The bus does not fit where the car and the van do: its rear overhangs the parked car.
  const PlanningResult bus = planner.plan(request_with_car_behind("bus"), StopCondition());
  EXPECT_NE(bus.outcome, PlanningResult::Outcome::kFound);
  ASSERT_FALSE(bus.evaluation_table.empty());
  for (const PlannerAttempt& a : bus.evaluation_table) EXPECT_NE(a.outcome, AttemptOutcome::kSuccess);

  // Without the parked car the bus is planned, with the bus's footprint and turning radius.
  PullOutRequest open = request_with_car_behind("bus");
  open.objects.clear();
  const PlanningResult free = planner.plan(open, StopCondition());
  ASSERT_EQ(free.outcome, PlanningResult::Outcome::kFound) << free.stop_reason;
  EXPECT_EQ(free.world->vehicle, profile("bus"));
}

TEST(MixedVehicles, OwnDimensionsArePlannedLikeTheProfileWithTheSameDimensions) {
  const StartPlanner& planner = fleet_planner();
  PullOutRequest own = request_with_car_behind("");
  own.vehicle = profile("bus");
  const PlanningResult result = planner.plan(own, StopCondition());
  EXPECT_NE(result.outcome, PlanningResult::Outcome::kFound);
  EXPECT_TRUE(planner.validate(own).empty());
  // The same request without a vehicle: the default car, which fits.
  PullOutRequest plain = request_with_car_behind("");
  const PlanningResult car = planner.plan(plain, StopCondition());
  ASSERT_EQ(car.outcome, PlanningResult::Outcome::kFound) << car.stop_reason;
  EXPECT_EQ(car.world->vehicle, VehicleInfo{});
}

TEST(MixedVehicles, AnUnknownProfileIsRejectedNamingTheField) {
  const StartPlanner& planner = fleet_planner();
  const PullOutRequest r = request_with_car_behind("tram");
  const auto issues = planner.validate(r);
  ASSERT_TRUE(has_issue(issues, "vehicle_profile"));
  EXPECT_NE(format_issues(issues).find("unknown profile 'tram'"), std::string::npos) << format_issues(issues);
  EXPECT_NE(format_issues(issues).find("bus, car, van"), std::string::npos) << format_issues(issues);
  const PlanningResult result = planner.plan(r, StopCondition());
  EXPECT_EQ(result.outcome, PlanningResult::Outcome::kRejected);
  EXPECT_TRUE(has_issue(result.issues, "vehicle_profile"));
  // A planner without profiles knows none.
  const StartPlanner bare(VehicleInfo{}, StartPlannerParameters{});
  EXPECT_TRUE(has_issue(bare.validate(request_with_car_behind("car")), "vehicle_profile"));
  // A huge name is not looked up.
  EXPECT_TRUE(has_issue(planner.validate(request_with_car_behind(std::string(10000, 'b'))), "vehicle_profile"));
}

TEST(MixedVehicles, BadDimensionsAreRejectedEachFieldNamed) {
  const StartPlanner& planner = fleet_planner();
  PullOutRequest r = request_with_car_behind("");
  VehicleInfo bad;
  bad.wheel_base_m = 0.0;
  bad.left_overhang_m = -0.1;
  bad.max_steer_angle_rad = std::numeric_limits<double>::quiet_NaN();
  bad.front_overhang_m = 1e9;
  r.vehicle = bad;
  const auto issues = planner.validate(r);
  EXPECT_TRUE(has_issue(issues, "vehicle.wheel_base")) << format_issues(issues);
  EXPECT_TRUE(has_issue(issues, "vehicle.left_overhang")) << format_issues(issues);
  EXPECT_TRUE(has_issue(issues, "vehicle.max_steer_angle")) << format_issues(issues);
  EXPECT_TRUE(has_issue(issues, "vehicle.front_overhang")) << format_issues(issues);
  EXPECT_FALSE(has_issue(issues, "vehicle.wheel_tread"));
  EXPECT_EQ(planner.plan(r, StopCondition()).outcome, PlanningResult::Outcome::kRejected);

  // Both a profile and dimensions: which one is meant is unclear.
  PullOutRequest both = request_with_car_behind("bus");
  both.vehicle = VehicleInfo{};
  EXPECT_TRUE(has_issue(planner.validate(both), "vehicle_profile"));
}

}  // namespace
}  // namespace pullout
