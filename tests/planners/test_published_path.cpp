// The published path (pipeline/published_path.hpp): every point a vehicle would drive is clear of
// the static objects, and a path cut before an object beyond the end pose stops there.
//
// The oracle is independent of the core's collision code: boxes are built here from the vehicle
// dimensions and the object fields, and overlap is a separating-axis test on convex polygons
// written in this file (not FCL, not the core's polygon helpers).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/collision/object_checker.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/published_path.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout {
namespace {

struct P {
  double x;
  double y;
};
using Convex = std::vector<P>;

// A box: `front` ahead of the pose, `rear` behind it, `left` / `right` to the sides.
Convex box(const Pose2& pose, double front, double rear, double left, double right) {
  const double c = std::cos(pose.yaw);
  const double s = std::sin(pose.yaw);
  const auto at = [&](double lx, double ly) { return P{pose.x + c * lx - s * ly, pose.y + s * lx + c * ly}; };
  return {at(front, left), at(-rear, left), at(-rear, -right), at(front, -right)};
}

Convex vehicle_box(const VehicleInfo& v, const Pose2& pose, double grow = 0.0) {
  return box(pose, v.wheel_base_m + v.front_overhang_m + grow, v.rear_overhang_m + grow,
             v.wheel_tread_m / 2.0 + v.left_overhang_m + grow, v.wheel_tread_m / 2.0 + v.right_overhang_m + grow);
}

Convex object_shape(const Object& o) {
  if (o.polygon.empty()) return box(o.pose, o.length_m / 2.0, o.length_m / 2.0, o.width_m / 2.0, o.width_m / 2.0);
  Convex out;
  const double c = std::cos(o.pose.yaw);
  const double s = std::sin(o.pose.yaw);
  for (const Point2& q : o.polygon) out.push_back({o.pose.x + c * q.x - s * q.y, o.pose.y + s * q.x + c * q.y});
  return out;
}

// Separating-axis test: two convex polygons overlap (or touch) unless the projections on some
// edge normal of either are disjoint.
bool overlap(const Convex& a, const Convex& b) {
  for (const Convex* poly : {&a, &b}) {
    for (std::size_t i = 0; i < poly->size(); ++i) {
      const P p = (*poly)[i];
      const P q = (*poly)[(i + 1) % poly->size()];
      const double nx = q.y - p.y;
      const double ny = p.x - q.x;
      double a_min = INFINITY, a_max = -INFINITY, b_min = INFINITY, b_max = -INFINITY;
      for (const P& r : a) {
        a_min = std::min(a_min, nx * r.x + ny * r.y);
        a_max = std::max(a_max, nx * r.x + ny * r.y);
      }
      for (const P& r : b) {
        b_min = std::min(b_min, nx * r.x + ny * r.y);
        b_max = std::max(b_max, nx * r.x + ny * r.y);
      }
      if (a_max < b_min || b_max < a_min) return false;
    }
  }
  return true;
}

TEST(SeparatingAxisOracle, KnowsOverlapFromGap) {
  const Convex a = box({0, 0, 0}, 1, 1, 1, 1);
  EXPECT_TRUE(overlap(a, box({1.9, 0, 0}, 1, 1, 1, 1)));
  EXPECT_FALSE(overlap(a, box({2.1, 0, 0}, 1, 1, 1, 1)));
  EXPECT_FALSE(overlap(a, box({2.5, 2.5, kPi / 4}, 1, 1, 1, 1)));  // corner to corner, apart
  EXPECT_TRUE(overlap(a, box({2.3, 0, kPi / 4}, 1, 1, 1, 1)));     // a corner of the diamond inside
}

const std::string kScenarioDir = std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios";

std::vector<std::string> bundled_scenarios() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(kScenarioDir)) {
    if (e.path().extension() == ".yaml") out.push_back(e.path().stem().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The deceleration between two consecutive points of the ramp: (v0^2 - v1^2) / (2 ds).
double deceleration(const PathPoint& a, const PathPoint& b) {
  const double ds = std::hypot(b.pose.x - a.pose.x, b.pose.y - a.pose.y);
  const double v0 = a.longitudinal_velocity_mps;
  const double v1 = b.longitudinal_velocity_mps;
  return ds < 1e-9 ? (std::abs(v1) > std::abs(v0) + 1e-9 ? INFINITY : 0.0) : (v0 * v0 - v1 * v1) / (2.0 * ds);
}

// Checks one found path point by point; returns how many were checked.
std::size_t check_published(const Scenario& sc, const StartPlannerParameters& params, const PlanningResult& r,
                            const std::string& label) {
  std::vector<Object> statics;
  for (const Object& o : sc.request.objects) {
    if (std::abs(o.velocity_mps) < params.th_moving_object_velocity) statics.push_back(o);
  }
  std::size_t checked = 0;
  for (std::size_t k = 0; k < r.path.partial_paths.size(); ++k) {
    const auto& pts = r.path.partial_paths[k].points;
    for (std::size_t i = 0; i < pts.size(); ++i, ++checked) {
      for (const Object& o : statics) {
        EXPECT_FALSE(overlap(vehicle_box(sc.vehicle, pts[i].pose), object_shape(o)))
            << label << ": segment " << k << " point " << i << " (" << pts[i].pose.x << ", " << pts[i].pose.y
            << ") runs into object " << o.id;
      }
    }
  }
  EXPECT_FALSE(r.path_end.note.empty()) << label;
  EXPECT_FALSE(r.path.reasons.empty()) << label << ": a found path says how it ends";
  if (r.path_end.stops_before_object) {
    const auto& last = r.path.partial_paths.back().points;
    EXPECT_EQ(last.back().longitudinal_velocity_mps, 0.0) << label << ": a cut path ends stopped";
    EXPECT_EQ(r.path.pairs_terminal_velocity_and_accel.size(), r.path.partial_paths.size()) << label;
    for (std::size_t i = 0; i + 1 < last.size(); ++i) {
      // 1 %: the stoppable speed is bisected, and points are 1 m apart on a smooth ramp.
      EXPECT_LE(deceleration(last[i], last[i + 1]), params.stop_condition.maximum_deceleration_for_stop * 1.01)
          << label << ": ramp point " << i;
    }
  }
  return checked;
}

// Every bundled scenario, with its own planner list and with each planner alone.
TEST(PublishedPath, EveryPointOfEveryFoundPathIsClearOfTheObjects) {
  std::size_t found = 0;
  std::size_t cut = 0;
  std::size_t points = 0;
  for (const std::string& name : bundled_scenarios()) {
    const Scenario sc = load_scenario(kScenarioDir + "/" + name + ".yaml");
    std::vector<std::vector<PlannerType>> priorities{sc.parameters.search_priority};
    for (PlannerType t :
         {PlannerType::kShift, PlannerType::kGeometric, PlannerType::kClothoid, PlannerType::kFreespace})
      priorities.push_back({t});
    for (const auto& priority : priorities) {
      StartPlannerParameters params = sc.parameters;
      params.search_priority = priority;
      const PlanningResult r = StartPlanner(sc.vehicle, params, {}, sc.map).plan(sc.request, StopCondition());
      if (r.outcome != PlanningResult::Outcome::kFound) continue;
      ++found;
      cut += r.path_end.stops_before_object ? 1 : 0;
      points += check_published(sc, params, r, name + " / " + to_string(priority.front()));
    }
  }
  // The suite must exercise the check: found paths, and cut ones.
  EXPECT_GE(found, 20u);
  EXPECT_GE(cut, 2u);
  RecordProperty("points", std::to_string(points));
}

// What the files' `expect: {stops_before_object: N}` says.
TEST(PublishedPath, ScenariosThatStopBeforeAnObjectDo) {
  std::size_t with_key = 0;
  for (const std::string& name : bundled_scenarios()) {
    const Scenario sc = load_scenario(kScenarioDir + "/" + name + ".yaml");
    const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters, {}, sc.map).plan(sc.request, StopCondition());
    if (!sc.expect.stops_before_object) {
      if (r.outcome == PlanningResult::Outcome::kFound) EXPECT_FALSE(r.path_end.stops_before_object) << name;
      continue;
    }
    ++with_key;
    ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << name;
    EXPECT_TRUE(r.path_end.stops_before_object) << name;
    EXPECT_EQ(r.path_end.object_id, *sc.expect.stops_before_object) << name;
    EXPECT_GT(r.path_end.beyond_end_pose_m, 0.0) << name;
    const std::string prefix = "stops ";
    ASSERT_FALSE(r.path.reasons.empty());
    EXPECT_EQ(r.path.reasons.back().rfind(prefix, 0), 0u) << r.path.reasons.back();
    EXPECT_NE(r.path.reasons.back().find("object " + std::to_string(*sc.expect.stops_before_object)),
              std::string::npos);
    const PathPoint& last = r.path.partial_paths.back().points.back();
    EXPECT_EQ(last.longitudinal_velocity_mps, 0.0) << name;
    // The margin is kept: the vehicle box grown by the margin (less 2 cm for the 1 cm bisection)
    // stays off the object. Exact for these files: the object stands square ahead on the lane.
    const double margin = r.evaluation_table.back().margin_m;
    for (const Object& o : sc.request.objects) {
      if (o.id != *sc.expect.stops_before_object) continue;
      EXPECT_FALSE(overlap(vehicle_box(sc.vehicle, last.pose, margin - 0.02), object_shape(o))) << name;
      // ... and it stops no farther than 10 cm short of that.
      EXPECT_TRUE(overlap(vehicle_box(sc.vehicle, last.pose, margin + 0.1), object_shape(o))) << name;
    }
  }
  EXPECT_EQ(with_key, 3u);  // car_parked_beyond_end, centerline_car_ahead, freespace_blocked_ahead
}

// ---- the unit on hand-made paths ----

VehicleInfo vehicle() { return VehicleInfo{}; }

// A straight path from x = 0 to 100 on y = 0, every metre, at `v`; end pose at x = end_x.
PullOutPath straight_path(double v, double end_x) {
  PullOutPath path;
  path.found = true;
  path.partial_paths.emplace_back();
  for (int i = 0; i <= 100; ++i) {
    PathPoint p;
    p.pose = {static_cast<double>(i), 0.0, 0.0};
    p.longitudinal_velocity_mps = v;
    path.partial_paths.back().points.push_back(p);
  }
  path.pairs_terminal_velocity_and_accel = {{v, 0.5}};
  path.start_pose = {0, 0, 0};
  path.end_pose = {end_x, 0, 0};
  return path;
}

ObjectChecker checker_with_car_at(double x, double y) {
  Object car;
  car.id = 9;
  car.pose = {x, y, 0.0};
  return ObjectChecker(vehicle_footprint(vehicle()), {{car.id, object_polygon(car)}});
}

TEST(FinishPublishedPath, StopsBeforeACarBeyondTheEndPoseKeepingTheMargin) {
  PullOutPath path = straight_path(5.0, 20.0);
  const PublishedPathEnd end = finish_published_path(path, checker_with_car_at(60.0, 0.0), {2.0, 1.0, 1.0});
  ASSERT_TRUE(end.stops_before_object);
  EXPECT_EQ(end.object_id, 9);
  EXPECT_TRUE(end.stop_within_limits);  // 15 m needed from 5 m/s, about 30 m of room
  const auto& pts = path.partial_paths.back().points;
  // Front bumper (2.79 + 1.0 ahead of base_link) 2 m short of the car's rear at 57.75: x = 51.96.
  EXPECT_NEAR(pts.back().pose.x, 57.75 - 2.0 - 3.79, 0.011);
  EXPECT_NEAR(end.clearance_m, 2.0, 0.011);
  EXPECT_NEAR(end.beyond_end_pose_m, 57.75 - 2.0 - 3.79 - 20.0, 0.011);
  EXPECT_EQ(pts.back().longitudinal_velocity_mps, 0.0);
  EXPECT_DOUBLE_EQ(pts[20].longitudinal_velocity_mps, 5.0);  // the ramp starts after the end pose
  EXPECT_DOUBLE_EQ(path.pairs_terminal_velocity_and_accel[0].velocity_mps, 5.0);
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) EXPECT_LE(deceleration(pts[i], pts[i + 1]), 1.0 + 1e-6) << i;
  // The stop is bisected to 1 cm on the safe side: 2.00 or 2.01 m.
  EXPECT_EQ(end.note.rfind("stops 2.0", 0), 0u) << end.note;
  EXPECT_NE(end.note.find(" m before object 9, 32.0 m beyond the end pose"), std::string::npos) << end.note;
}

TEST(FinishPublishedPath, TooCloseToStopFromTheTerminalVelocityRampsDownBeforeTheEndPose) {
  PullOutPath path = straight_path(10.0, 20.0);
  // From 10 m/s: 10^2 / 2 + 10 / 2 = 55 m needed; the stop is about 10 m beyond the end pose.
  const PublishedPathEnd end = finish_published_path(path, checker_with_car_at(38.0, 0.0), {2.0, 1.0, 1.0});
  ASSERT_TRUE(end.stops_before_object);
  EXPECT_FALSE(end.stop_within_limits);
  const auto& pts = path.partial_paths.back().points;
  EXPECT_EQ(pts.back().longitudinal_velocity_mps, 0.0);
  EXPECT_LT(pts[20].longitudinal_velocity_mps, 10.0);
  EXPECT_NEAR(path.pairs_terminal_velocity_and_accel[0].velocity_mps, pts[20].longitudinal_velocity_mps, 1e-9);
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) EXPECT_LE(deceleration(pts[i], pts[i + 1]), 1.0 + 1e-6) << i;
  EXPECT_NE(end.note.find("too close to stop from 10.0 m/s"), std::string::npos) << end.note;
}

TEST(FinishPublishedPath, ACarBesideThePathBeforeTheEndPoseOnlyNeedsNoContact) {
  PullOutPath path = straight_path(5.0, 40.0);
  // 0.5 m between the footprint's side (0.948) and the car's (2.398 - 0.95): below the 2 m
  // margin, but before the end pose, where the planner chose the margin.
  const PublishedPathEnd end = finish_published_path(path, checker_with_car_at(20.0, 2.398), {2.0, 1.0, 1.0});
  EXPECT_FALSE(end.stops_before_object);
  EXPECT_EQ(path.partial_paths[0].points.size(), 101u);
  EXPECT_NEAR(end.beyond_end_pose_m, 60.0, 1e-9);
  EXPECT_EQ(end.note,
            "no object on the published path; it ends 60.0 m beyond the end pose at 5.0 m/s (end of the "
            "road lanes or forward_path_length)");
}

TEST(FinishPublishedPath, DropsLaterSegmentsWhenAnEarlierOneIsBlocked) {
  PullOutPath path = straight_path(5.0, 100.0);
  PullOutPath second = straight_path(5.0, 100.0);
  path.partial_paths.push_back(second.partial_paths[0]);  // (joins are not this unit's concern)
  path.pairs_terminal_velocity_and_accel.push_back({5.0, 0.0});
  path.end_pose = {100.0, 0.0, 0.0};
  const PublishedPathEnd end = finish_published_path(path, checker_with_car_at(50.0, 0.0), {2.0, 1.0, 1.0});
  ASSERT_TRUE(end.stops_before_object);
  EXPECT_LT(end.beyond_end_pose_m, 0.0);
  ASSERT_EQ(path.partial_paths.size(), 1u);
  EXPECT_EQ(path.pairs_terminal_velocity_and_accel.size(), 1u);
  // Contact only before the end pose: the front bumper stops at the car's rear (47.75).
  EXPECT_NEAR(path.partial_paths[0].points.back().pose.x + 3.79, 47.75, 0.011);
  EXPECT_EQ(path.partial_paths[0].points.back().longitudinal_velocity_mps, 0.0);
}

// The stop distance against a simulation of the jerk-limited stop (0.1 ms steps).
double simulated_stop(double v, double a_max, double j_max) {
  const double dt = 1e-4;
  double a = 0.0;
  double s = 0.0;
  // Brake harder until either a_max or the point where releasing at j_max just ends at v = 0.
  while (v > 0.0) {
    const double release = a * a / (2.0 * j_max);  // speed lost while the deceleration ramps to 0
    if (v <= release + 1e-12) {
      a = std::max(0.0, a - j_max * dt);
    } else {
      a = std::min(a_max, a + j_max * dt);
    }
    s += std::max(v, 0.0) * dt;
    v -= a * dt;
    if (a <= 0.0 && v > 0.0 && v < 1e-3) break;
  }
  return s;
}

TEST(JerkLimitedStopDistance, MatchesASimulatedStop) {
  for (const auto& [v, a, j] :
       std::vector<std::array<double, 3>>{{13.89, 1.0, 1.0}, {0.5, 1.0, 1.0}, {5.0, 2.0, 0.5}}) {
    EXPECT_NEAR(jerk_limited_stop_distance(v, a, j), simulated_stop(v, a, j), 0.01 * simulated_stop(v, a, j) + 0.01)
        << v << " " << a << " " << j;
  }
  EXPECT_EQ(jerk_limited_stop_distance(0.0, 1.0, 1.0), 0.0);
}

}  // namespace
}  // namespace pullout
