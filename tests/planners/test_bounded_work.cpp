// Work bounded by what is near the vehicle (issue 11, "a 600-byte request can take the machine"):
// lanes cropped to the planning horizon, coordinates and the kept length within the limits, every
// build step honouring the stop condition, huge Lanelet2 lanelets loaded and planned on in bounded
// work. Bounds are asserted on what the code built (lane lengths, build_work(), costmap size),
// never on the clock.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "pullout/freespace/costmap.hpp"
#include "pullout/geometry/polyline.hpp"
#include "pullout/lanes/lane_crop.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/safety/rss_check.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

// The straight shoulder scenario (test_world.hpp) with both lanes running from x = 0 to `length`.
PullOutRequest long_shoulder_request(double length) {
  PullOutRequest r = test::straight_shoulder_request();
  r.lanes = {test::straight_lane(1, LaneSubtype::kRoad, 0, length, -1.75, 1.75),
             test::straight_lane(2, LaneSubtype::kRoadShoulder, 0, length, 1.75, 4.75)};
  return r;
}

const StartPlanner& planner() {
  static const StartPlanner p(VehicleInfo{}, StartPlannerParameters{});
  return p;
}

double horizon() { return planning_horizon_m(StartPlannerParameters{}, VehicleInfo{}); }

// The longest bound of the lanes a result was planned on.
double longest_planned_bound(const PlanningResult& r) {
  double longest = 0.0;
  for (const Lane& l : r.world->lanes) {
    longest = std::max({longest, polyline_length(l.left_bound), polyline_length(l.right_bound)});
  }
  return longest;
}

std::string issues_of(const PlanningResult& r) { return format_issues(r.issues); }

TEST(BoundedWork, HorizonCoversWhatAPlanReaches) {
  const StartPlannerParameters p;
  const double h = horizon();
  // A path runs forward_path_length beyond its start: the square must hold it with room to spare.
  EXPECT_GT(h, p.forward_path_length + p.path_safety_check.target_filtering.object_check_forward_distance);
  EXPECT_GT(h, p.max_back_distance + p.path_safety_check.target_filtering.object_check_backward_distance);
  EXPECT_LT(h, 1000.0);  // and it is a horizon, not the whole input
}

// 20 km and 1e7 m long lanes (2-point bounds): planned like the 100 m scenario, on lanes cut to the
// horizon. Before the crop, the planned lanes were the request's (20 km, 1e7 m).
class LongLane : public ::testing::TestWithParam<double> {};

TEST_P(LongLane, IsPlannedOnTheCroppedLanes) {
  const PlanningResult r = planner().plan(long_shoulder_request(GetParam()), StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << issues_of(r) << r.stop_reason;
  EXPECT_EQ(r.path.planner_type, PlannerType::kShift);
  ASSERT_TRUE(r.world);
  ASSERT_EQ(r.world->lanes.size(), 2U);
  // The ego stands at x = 10: the lanes keep x in [0, 10 + horizon] (plus the crop's resolution).
  EXPECT_LE(longest_planned_bound(r), 10.0 + horizon() + kCropResolutionM + 1e-6);
  EXPECT_GE(longest_planned_bound(r), 10.0 + horizon());
  const LaneWorld world(r.world->lanes);
  // Samples every 0.5 m and edge pieces: a few thousand for ~400 m, never the 1e5 per line of 1e7 m.
  EXPECT_LT(world.build_work(), 20000U);
}

INSTANTIATE_TEST_SUITE_P(Lengths, LongLane, ::testing::Values(2e4, 1e7));

TEST(BoundedWork, SameRouteSamePathAsTheShortLanes) {
  // Cropping changes no plan: the path on 1e7 m lanes is the one on 1 km lanes.
  const PlanningResult short_lanes = planner().plan(long_shoulder_request(1000.0), StopCondition());
  const PlanningResult long_lanes = planner().plan(long_shoulder_request(1e7), StopCondition());
  ASSERT_EQ(short_lanes.outcome, PlanningResult::Outcome::kFound);
  ASSERT_EQ(long_lanes.outcome, PlanningResult::Outcome::kFound);
  ASSERT_EQ(short_lanes.path.partial_paths.size(), long_lanes.path.partial_paths.size());
  for (std::size_t i = 0; i < short_lanes.path.partial_paths.size(); ++i) {
    const auto& a = short_lanes.path.partial_paths[i].points;
    const auto& b = long_lanes.path.partial_paths[i].points;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_NEAR(a[k].pose.x, b[k].pose.x, 1e-6);
      EXPECT_NEAR(a[k].pose.y, b[k].pose.y, 1e-6);
      EXPECT_NEAR(a[k].longitudinal_velocity_mps, b[k].longitudinal_velocity_mps, 1e-9);
    }
  }
}

TEST(BoundedWork, CoordinatesBeyondTheLimitAreRejectedNamingTheField) {
  // 1e8 m: beyond max_coordinate_m (1e7).
  PlanningResult r = planner().plan(long_shoulder_request(1e8), StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  EXPECT_NE(issues_of(r).find("lanes[0].left_bound[1].x: |x| 1e+08 exceeds 1e+07 m"), std::string::npos)
      << issues_of(r);

  PullOutRequest req = test::straight_shoulder_request();
  req.lanes[0].left_bound[1].x = 1e20;
  req.goal_pose.y = -3e7;
  req.objects.push_back(test::parked_car(7, 50.0, 3.25));
  req.objects.back().length_m = 2e7;
  r = planner().plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  const std::string text = issues_of(r);
  EXPECT_NE(text.find("lanes[0].left_bound[1].x: |x| 1e+20 exceeds 1e+07 m"), std::string::npos) << text;
  EXPECT_NE(text.find("goal_pose.y: |y| 3e+07 exceeds 1e+07 m"), std::string::npos) << text;
  EXPECT_NE(text.find("objects[0].length_m: length 2e+07 exceeds 1e+07 m"), std::string::npos) << text;
  EXPECT_FALSE(planner().validate(req).empty());
}

// A bound too short to give a direction is named with its limit in plain figures (it read
// "shorter than 0.100000 m").
TEST(BoundedWork, ADegenerateBoundIsNamedWithItsLimit) {
  PullOutRequest req = test::straight_shoulder_request();
  req.lanes[0].left_bound = {{0.0, 1.75}, {0.05, 1.75}};
  const auto issues = planner().validate(req);
  ASSERT_EQ(issues.size(), 1U) << format_issues(issues);
  EXPECT_EQ(issues[0].field, "lanes[0].left_bound");
  EXPECT_EQ(issues[0].problem, "degenerate: shorter than 0.1 m");
}

TEST(BoundedWork, SpeedsBeyondTheLimitAreRejectedNamingTheField) {
  // A fuzzed request (fuzz/corpus/request/regress_stop_profile_speed_oom.cdr) with an ego speed of
  // 2e236 m/s was planned, and the safety check at the start then built its stop profile until it
  // ran out of memory. Speeds are bounded by max_speed_mps (100 m/s).
  PullOutRequest req = test::straight_shoulder_request();
  req.ego_velocity_mps = 1e14;
  req.objects.push_back(test::parked_car(7, 50.0, 3.25));
  req.objects.back().velocity_mps = -250.0;
  const PlanningResult r = planner().plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  const std::string text = issues_of(r);
  EXPECT_NE(text.find("ego_velocity_mps: |speed| 1e+14 exceeds 100 m/s"), std::string::npos) << text;
  EXPECT_NE(text.find("objects[0].velocity_mps: |speed| 250 exceeds 100 m/s"), std::string::npos) << text;

  req.ego_velocity_mps = -100.0;  // the limit itself is a valid speed, either way
  req.objects.back().velocity_mps = 100.0;
  EXPECT_TRUE(planner().validate(req).empty()) << format_issues(planner().validate(req));

  ExecutionProgress progress;
  progress.velocity_mps = std::numeric_limits<double>::infinity();
  progress.pose.y = 2e7;
  const std::string progress_text = format_issues(planner().validate(progress));
  EXPECT_NE(progress_text.find("progress.velocity_mps: not a finite number (infinite)"), std::string::npos)
      << progress_text;
  EXPECT_NE(progress_text.find("progress.pose.y: |y| 2e+07 exceeds 1e+07 m"), std::string::npos) << progress_text;
  progress.velocity_mps = 3.0;
  progress.pose.y = 0.0;
  EXPECT_TRUE(planner().validate(progress).empty());
}

TEST(BoundedWork, AStopFromAnySpeedHoldsAFewThousandSamples) {
  // 100 m/s at 0.01 m/s^2 (the smallest deceleration the configuration allows) stops after
  // 10,001 s: sampled every 5 ms that was 2 million samples, and unbounded for a larger speed.
  const StopProfile stop(100.0, 0.01, 0.01);
  EXPECT_LE(stop.samples(), 4200U);
  // 1 s of jerk ramp (100 - 0.01 / 6 m, down to 99.995 m/s), then 99.995^2 / 0.02 m.
  EXPECT_NEAR(stop.distance(), 100.0 - 0.01 / 6.0 + 99.995 * 99.995 / 0.02, 1e-3 * stop.distance());
  const StopProfile never(std::numeric_limits<double>::infinity(), 1.0, 1.0);
  EXPECT_EQ(never.distance(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(never.velocity_at(10.0), std::numeric_limits<double>::infinity());
}

TEST(BoundedWork, ManyLongLanesBuildABoundedWorld) {
  // 64 parallel lanes of 1e7 m (an 11 KB request): on main they took seconds and hundreds of MB.
  PullOutRequest req = long_shoulder_request(1e7);
  for (int k = 2; k < 64; ++k) {
    req.lanes.push_back(
        test::straight_lane(k + 1, LaneSubtype::kRoadShoulder, 0, 1e7, 1.75 + 3.0 * (k - 1), 4.75 + 3.0 * (k - 1)));
  }
  const PlanningResult r = planner().plan(req, StopCondition());
  ASSERT_NE(r.outcome, PlanningResult::Outcome::kRejected) << issues_of(r);
  ASSERT_TRUE(r.world);
  EXPECT_LE(longest_planned_bound(r), 10.0 + horizon() + kCropResolutionM + 1e-6);
  const LaneWorld world(r.world->lanes);
  // Per lane about 3 x 400 m / 0.5 m of samples and pieces: the world follows the horizon.
  EXPECT_LT(world.build_work(), 64U * 3000U);
}

TEST(BoundedWork, LanesOutsideTheHorizonAndTheKeptLengthLimit) {
  // The road lies 5 km away: nothing to pull out onto within reach.
  PullOutRequest req = test::straight_shoulder_request();
  req.lanes[0] = test::straight_lane(1, LaneSubtype::kRoad, 0, 100, 4998.25, 5001.75);
  PlanningResult r = planner().plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  EXPECT_NE(issues_of(r).find("lanes: no lane of subtype road within the planning horizon"), std::string::npos)
      << issues_of(r);

  // A lane that zig-zags across the horizon: no crop shortens it, the kept length limit rejects it.
  RequestLimits limits;
  limits.max_horizon_lane_length_m = 5000.0;
  const StartPlanner strict(VehicleInfo{}, StartPlannerParameters{}, limits);
  req = long_shoulder_request(1e7);
  r = strict.plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << issues_of(r);  // ~1.6 km kept: within
  Lane zigzag = test::straight_lane(3, LaneSubtype::kRoadShoulder, 0, 0, 4.75, 7.75);
  zigzag.left_bound.clear();
  zigzag.right_bound.clear();
  for (int i = 0; i < 20; ++i) {
    const double x = i % 2 == 0 ? -300.0 : 300.0;
    zigzag.left_bound.push_back({x, 7.75 + 3.1 * i});
    zigzag.right_bound.push_back({x, 4.75 + 3.1 * i});
  }
  req.lanes.push_back(zigzag);
  r = strict.plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  EXPECT_NE(issues_of(r).find("exceed the limit of 5000 m"), std::string::npos) << issues_of(r);
  EXPECT_EQ(r.issues.front().field, "lanes");
}

TEST(BoundedWork, LaneWorldBuildHonoursTheStopCondition) {
  std::vector<Lane> lanes;
  for (int k = 0; k < 8; ++k)
    lanes.push_back(test::straight_lane(k + 1, LaneSubtype::kRoad, 0, 1e7, 3.5 * k, 3.5 * k + 3.5));
  const LaneWorld expired(lanes, StopCondition::after_ms(0.0));
  EXPECT_EQ(expired.stopped(), StopReason::kDeadline);
  EXPECT_EQ(expired.build_work(), 0U);
  std::atomic<bool> cancel{true};
  const LaneWorld cancelled(lanes, StopCondition().with_cancel(&cancel));
  EXPECT_EQ(cancelled.stopped(), StopReason::kCancelled);
  // Unstopped, the same (uncropped) lanes cost 1e5 samples per line: what the crop avoids.
  const LaneWorld whole(lanes);
  EXPECT_EQ(whole.stopped(), StopReason::kNone);
  EXPECT_GT(whole.build_work(), 8U * 100000U);

  // The pipeline reports a stop during the build as a timed-out search with no attempt.
  const PlanningResult r = planner().plan(long_shoulder_request(1e7), StopCondition::after_ms(0.0));
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_EQ(r.stopped, StopReason::kDeadline);
  EXPECT_TRUE(r.timed_out);
  EXPECT_TRUE(r.evaluation_table.empty());
}

TEST(BoundedWork, CostmapBuildHonoursTheStopCondition) {
  Aabb extent;
  extent.extend({0.0, 0.0});
  extent.extend({3000.0, 3000.0});  // 15000 x 15000 cells at 0.2 m: not even allocated
  const Polygon all{{-1, -1}, {3001, -1}, {3001, 3001}, {-1, 3001}};
  const Costmap stopped = Costmap::from_polygons(extent, 0.2, {all}, {}, {}, StopCondition::after_ms(0.0));
  EXPECT_EQ(stopped.stopped(), StopReason::kDeadline);
  EXPECT_TRUE(stopped.empty());

  OccupancyGrid grid;
  grid.resolution_m = 0.1;
  grid.width = 1000;
  grid.height = 1000;
  grid.data.assign(std::size_t{1000} * 1000, 0);
  std::atomic<bool> cancel{true};
  const Costmap from_grid = Costmap::from_occupancy_grid(grid, 30, StopCondition().with_cancel(&cancel));
  EXPECT_EQ(from_grid.stopped(), StopReason::kCancelled);
  EXPECT_TRUE(from_grid.empty());
  const Costmap small = Costmap::from_occupancy_grid(OccupancyGrid{0.5, {}, 4, 4, std::vector<std::int8_t>(16, 0)}, 30,
                                                     StopCondition::after_ms(1e9));
  EXPECT_EQ(small.stopped(), StopReason::kNone);
  EXPECT_FALSE(small.occupied(1, 1));
}

// One obstacle polygon may cover most of a grid of max_grid_cells, and the stop condition was
// checked every 64 polygons only: 64 objects of a request, 64-point zigzags across a 4096 x 4096
// grid of 0.01 m cells, kept a planning thread 3.5 to 5.2 s past a 200 ms deadline (about 60 ms
// a polygon). Now the build stops within 64 rows of one polygon once the budget has run out.
TEST(BoundedWork, CostmapObstaclesHonourTheStopConditionWithinAPolygon) {
  OccupancyGrid grid;
  grid.resolution_m = 0.01;
  grid.width = 4096;
  grid.height = 4096;
  grid.data.assign(std::size_t{4096} * 4096, 0);
  std::vector<Polygon> zigzags;
  for (int j = 0; j < 64; ++j) {
    Polygon p;
    for (int k = 0; k < 64; ++k) p.push_back({(k % 2) * 40.96, 40.96 * k / 64.0 + j * 0.001});
    zigzags.push_back(p);
  }
  Costmap map = Costmap::from_occupancy_grid(grid, 30);
  map.add_obstacles(zigzags, StopCondition::after_ms(200.0));
  EXPECT_EQ(map.stopped(), StopReason::kDeadline);
  EXPECT_LT(map.shapes().size(), zigzags.size()) << "every polygon was drawn before the first check";
}

// A grid's cell size is bounded before anything is built from it: a fuzzed 1e-308 m cell once
// overflowed the collision checker's cell counts (UBSan, fuzz_request).
TEST(BoundedWork, GridCellSizeIsBoundedNamingTheField) {
  PullOutRequest req = test::straight_shoulder_request();
  const auto with_cells_of = [&](double resolution) {
    req.occupancy_grid = OccupancyGrid{resolution, {}, 4, 4, std::vector<std::int8_t>(16, 0)};
    return planner().validate(req);
  };
  for (const double bad : {1e-308, 1e-3, 5.5, 1e300}) {
    const auto issues = with_cells_of(bad);
    ASSERT_EQ(issues.size(), 1U) << bad << ": " << format_issues(issues);
    EXPECT_EQ(issues.front().field, "occupancy_grid.resolution_m");
    EXPECT_NE(issues.front().problem.find("is outside [0.01, 5] m"), std::string::npos) << issues.front().problem;
  }
  for (const double good : {0.01, 0.2, 5.0}) EXPECT_TRUE(with_cells_of(good).empty()) << good;
  req.occupancy_grid->resolution_m = 1e-308;
  const PlanningResult r = planner().plan(req, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
}

// A grid's extent is bounded as every other extent of a request: one row of 16 Mi cells of 5 m
// (84,000 km) is refused, naming the field, before anything is built from it.
TEST(BoundedWork, GridExtentIsBoundedNamingTheField) {
  PullOutRequest req = test::straight_shoulder_request();
  const std::uint32_t long_side = 16U * 1024U * 1024U;
  req.occupancy_grid = OccupancyGrid{5.0, {}, long_side, 1, std::vector<std::int8_t>(long_side, 0)};
  const auto issues = planner().validate(req);
  ASSERT_EQ(issues.size(), 1U) << format_issues(issues);
  EXPECT_EQ(issues.front().field, "occupancy_grid.width");
  EXPECT_EQ(issues.front().problem, "width x resolution_m 8.38861e+07 exceeds 1e+07 m");
  req.occupancy_grid = OccupancyGrid{5.0, {}, 1, long_side, std::vector<std::int8_t>(long_side, 0)};
  ASSERT_EQ(planner().validate(req).size(), 1U);
  EXPECT_EQ(planner().validate(req).front().field, "occupancy_grid.height");
  // 1 Mi cells of 5 m (5,243 km) are within the limit of 1e7 m.
  req.occupancy_grid = OccupancyGrid{5.0, {}, 1024U * 1024U, 1, std::vector<std::int8_t>(1024U * 1024U, 0)};
  EXPECT_TRUE(planner().validate(req).empty()) << format_issues(planner().validate(req));
}

// ---- the crop itself ----

TEST(LaneCrop, KeepsTheStretchNearTheSquare) {
  const Aabb square = horizon_square(0.0, 0.0, 100.0);
  const std::vector<Lane> lanes = {
      test::straight_lane(1, LaneSubtype::kRoad, -50, 50, -1.75, 1.75),    // inside: unchanged
      test::straight_lane(2, LaneSubtype::kRoad, -1e7, 1e7, -1.75, 1.75),  // through: cut
      test::straight_lane(3, LaneSubtype::kRoad, 500, 900, -1.75, 1.75),   // outside: dropped
      test::straight_lane(4, LaneSubtype::kRoad, 0, 2e4, -1e4, 1e4),       // 20 km wide around it
  };
  const CroppedLanes c = crop_lanes(lanes, square);
  ASSERT_EQ(c.lanes.size(), 3U);
  EXPECT_EQ(c.dropped, 1U);
  EXPECT_EQ(c.cropped, 2U);
  EXPECT_EQ(c.source, (std::vector<std::size_t>{0, 1, 3}));
  ASSERT_EQ(c.lanes[0].left_bound.size(), 2U);
  EXPECT_EQ(c.lanes[0].left_bound[0].x, -50.0);
  EXPECT_EQ(c.lanes[0].left_bound[1].x, 50.0);
  // Lane 2: cut within kCropResolutionM outside the square on both ends, never inside.
  for (const auto* bound : {&c.lanes[1].left_bound, &c.lanes[1].right_bound}) {
    ASSERT_EQ(bound->size(), 2U);
    EXPECT_LE(bound->front().x, -100.0);
    EXPECT_GE(bound->front().x, -100.0 - kCropResolutionM);
    EXPECT_GE(bound->back().x, 100.0);
    EXPECT_LE(bound->back().x, 100.0 + kCropResolutionM);
  }
  // Lane 4: its bounds never enter the square, its cross-sections do: kept from x = 0 to ~100.
  EXPECT_DOUBLE_EQ(c.lanes[2].left_bound.front().x, 0.0);
  EXPECT_GE(c.lanes[2].left_bound.back().x, 100.0);
  EXPECT_LE(c.lanes[2].left_bound.back().x, 100.0 + kCropResolutionM);
}

TEST(LaneCrop, AGivenCenterlineIsCutWithTheBounds) {
  Lane lane = test::straight_lane(1, LaneSubtype::kRoad, 0, 1e6, -1.75, 1.75);
  lane.centerline = {{0, 0}, {1e6, 0}};
  const CroppedLanes c = crop_lanes({lane}, horizon_square(10.0, 0.0, 50.0));
  ASSERT_EQ(c.lanes.size(), 1U);
  ASSERT_EQ(c.lanes[0].centerline.size(), 2U);
  EXPECT_DOUBLE_EQ(c.lanes[0].centerline.front().x, 0.0);
  EXPECT_NEAR(c.lanes[0].centerline.back().x, c.lanes[0].left_bound.back().x, 1e-6);
}

TEST(LaneCrop, ObjectsNearTheSquare) {
  const Aabb square = horizon_square(0.0, 0.0, 100.0);
  EXPECT_TRUE(object_near(test::parked_car(1, 50.0, 0.0), square));
  EXPECT_TRUE(object_near(test::parked_car(2, 102.0, 0.0), square));  // its front reaches in
  EXPECT_FALSE(object_near(test::parked_car(3, 500.0, 0.0), square));
  Object wall = test::parked_car(4, 5000.0, 0.0);
  wall.polygon = {{-5000, -1}, {0, -1}, {0, 1}, {-5000, 1}};  // object frame: reaches back to x = 0
  EXPECT_TRUE(object_near(wall, square));
}

// ---- a Lanelet2 map with huge lanelets ----

std::string huge_map(double length) {
  std::ostringstream os;
  os.precision(17);
  os << "<?xml version=\"1.0\"?>\n<osm version=\"0.6\">\n";
  const double ys[] = {-1.75, 1.75, 4.75};
  int id = 1;
  for (const double y : ys) {
    for (const double x : {0.0, length}) {
      os << "<node id=\"" << id++ << "\" lat=\"0\" lon=\"0\"><tag k=\"local_x\" v=\"" << x
         << "\"/><tag k=\"local_y\" v=\"" << y << "\"/></node>\n";
    }
  }
  os << "<way id=\"10\"><nd ref=\"1\"/><nd ref=\"2\"/></way>\n"
     << "<way id=\"11\"><nd ref=\"3\"/><nd ref=\"4\"/></way>\n"
     << "<way id=\"12\"><nd ref=\"5\"/><nd ref=\"6\"/></way>\n"
     << "<relation id=\"100\"><member type=\"way\" role=\"left\" ref=\"11\"/>"
     << "<member type=\"way\" role=\"right\" ref=\"10\"/><tag k=\"type\" v=\"lanelet\"/>"
     << "<tag k=\"subtype\" v=\"road\"/></relation>\n"
     << "<relation id=\"101\"><member type=\"way\" role=\"left\" ref=\"12\"/>"
     << "<member type=\"way\" role=\"right\" ref=\"11\"/><tag k=\"type\" v=\"lanelet\"/>"
     << "<tag k=\"subtype\" v=\"road_shoulder\"/></relation>\n</osm>\n";
  return os.str();
}

std::string write_temp(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / ("pullout_bounded_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(BoundedWork, HugeLaneletMapLoadsAndPlansOnTheHorizon) {
  // 1,000 km lanelets (a road and its shoulder), read from a file like the service does.
  const std::string path = write_temp("huge_lanelet.osm", huge_map(1e6));
  const auto map = load_lanelet_map(path);
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
  ASSERT_EQ(map->lanelets().size(), 2U);
  const StartPlanner on_map(VehicleInfo{}, StartPlannerParameters{}, RequestLimits{}, map);
  PullOutRequest req = test::straight_shoulder_request();
  req.lanes.clear();
  req.route_lanelet_ids = {100};
  const PlanningResult r = on_map.plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << issues_of(r) << r.stop_reason;
  ASSERT_TRUE(r.world);
  EXPECT_LE(longest_planned_bound(r), 10.0 + horizon() + kCropResolutionM + 1e-6);
  EXPECT_LT(LaneWorld(r.world->lanes).build_work(), 20000U);
}

TEST(BoundedWork, MapCoordinatesBeyondTheLimitFailToLoadNamingTheNode) {
  try {
    parse_lanelet_map(huge_map(1e8), "far.osm");
    FAIL() << "a node 1e8 m out was accepted";
  } catch (const MapLoadError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("node 2 (line "), std::string::npos) << what;
    EXPECT_NE(what.find("local_x 1e+08 exceeds 1e+07 m"), std::string::npos) << what;
  }
}

// ---- the lane outline (fuzz/corpus/request/regress_lane_index_spike_timeout.cdr) ----

// What fuzz_request found: the straight shoulder scenario whose road has a left bound of 2,000
// points 5 cm apart, one of them moved 78.6 km out along the bound (a spike out and back). The
// crop keeps the whole lane (its cross-sections meet the horizon at both ends), 157 km of bound.
// The outline probes every 0.5 m of edge (1e5 probes per spike edge) against the lane pieces near
// each probe; before, every probe was tested against the lane's own pieces stretched along the
// spike (kept in the index's wide list, so near every probe) and two pieces holding 800 and 1,200
// of the bound's vertices: 28.7 million point-edge tests for 302,826 probes (95 per probe), 4 s
// under ASan, during validation, which ran without a deadline.
std::vector<Lane> spiked_bound_lanes() {
  std::vector<Lane> lanes = test::straight_shoulder_request().lanes;
  Lane& road = lanes.front();
  road.left_bound.clear();
  for (int i = 0; i < 2000; ++i) road.left_bound.push_back(Point2{0.05 * i, 1.75});
  road.left_bound[798].x = 78644.2;
  return lanes;
}

TEST(LaneOutline, ASpikedBoundCostsAFewPointEdgeTestsPerProbe) {
  const LaneWorld world(spiked_bound_lanes());
  ASSERT_EQ(world.stopped(), StopReason::kNone);
  // The probes: two 78.6 km edges at 1e5 pieces each (the cap per edge), and the rest.
  ASSERT_GT(world.build_work(), 200000U);
  // A probe along the spike meets no piece of another lane, one near the shoulder its 4-vertex
  // piece: at most a few tests per probe (was 95).
  EXPECT_LT(world.build_edge_tests(), 4 * world.build_work())
      << world.build_edge_tests() << " point-edge tests for " << world.build_work() << " probes";
  // Still the same outline: the road's edge shared with the shoulder (y = 1.75 for x in [0, 100])
  // is not part of it, the road's right edge is.
  EXPECT_TRUE(world.footprint_inside({Vec2{5, 1.0}, Vec2{9, 1.0}, Vec2{9, 2.5}, Vec2{5, 2.5}}));
  EXPECT_FALSE(world.footprint_inside({Vec2{5, -2.5}, Vec2{9, -2.5}, Vec2{9, -1.0}, Vec2{5, -1.0}}));
}

TEST(LaneOutline, NoPieceHoldsMoreThan64VerticesOfABound) {
  const Lane road = spiked_bound_lanes().front();
  std::vector<Vec2> pts;
  for (const Point2& p : road.left_bound) pts.push_back(to_vec(p));
  const std::vector<Polygon> pieces =
      cut_lane_into_pieces(Polyline(pts), Polyline({to_vec(road.right_bound[0]), to_vec(road.right_bound[1])}));
  std::size_t vertices = 0;
  for (const Polygon& piece : pieces) {
    // Each piece: its left part (vertices strictly inside plus two cut points) and right part.
    EXPECT_LE(piece.size(), 64U + 2U + 2U);
    vertices += piece.size();
  }
  EXPECT_GE(vertices, 2000U);  // every vertex is in some piece

  // Evenly spaced bounds are cut as before: one piece per 16 vertices, at equal arc lengths.
  std::vector<Vec2> even_left;
  std::vector<Vec2> even_right;
  for (int i = 0; i < 160; ++i) {
    even_left.emplace_back(i, 1.75);
    even_right.emplace_back(i, -1.75);
  }
  EXPECT_EQ(cut_lane_into_pieces(Polyline(even_left), Polyline(even_right)).size(), 10U);
}

TEST(LaneOutline, ValidationAnswersWithoutBuildingTheWorld) {
  // lanes_contain (validation, O(vertices)) gives LaneWorld::contains's answer.
  std::vector<std::vector<Lane>> layouts = {spiked_bound_lanes(), test::straight_shoulder_request().lanes};
  for (const auto& lanes : layouts) {
    const LaneWorld world(lanes);
    for (double x = -5.0; x <= 105.0; x += 1.37) {
      for (double y = -6.0; y <= 6.0; y += 0.61) {
        ASSERT_EQ(lanes_contain(lanes, {x, y}), world.contains({x, y})) << x << ", " << y;
      }
    }
  }
  PullOutRequest req = test::straight_shoulder_request();
  req.lanes = spiked_bound_lanes();
  EXPECT_TRUE(planner().validate(req).empty()) << format_issues(planner().validate(req));
  req.ego_pose = {10.0, 30.0, 0.0};
  const auto issues = planner().validate(req);
  ASSERT_EQ(issues.size(), 1U);
  EXPECT_EQ(issues.front().field, "ego_pose");
  EXPECT_NE(issues.front().problem.find("is on no lane; the nearest, lane 2, is 25.25 m away"), std::string::npos)
      << issues.front().problem;
}

}  // namespace
}  // namespace pullout
