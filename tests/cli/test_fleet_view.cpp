// What `pullout watch` prints and `pullout view` sends for a fleet snapshot (client/cli/
// fleet_view.hpp), without DDS: rows, the table's layout, ages, and the page's JSON (footprint
// corners worked out by hand from the default vehicle, segment flags, the current segment).
#include <chrono>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "fleet_view.hpp"

namespace pullout::cli {
namespace {

using Clock = std::chrono::system_clock;

PathWithLaneId segment(std::initializer_list<Pose2> poses, double v) {
  PathWithLaneId s;
  for (const Pose2& p : poses) s.points.push_back({p, v, {}});
  return s;
}

VehicleView executing_vehicle(Clock::time_point now) {
  VehicleView v;
  v.vehicle_id = "car-1";
  auto status = std::make_shared<PullOutStatus>();
  status->state = ExecutionState::kExecuting;
  status->planner_type = PlannerType::kGeometric;
  status->current_path_idx = 1;
  status->segment_count = 3;
  status->safe = true;
  v.status = status;
  auto path = std::make_shared<PullOutPath>();
  path->request_id = 9007199254740993ULL;  // 2^53 + 1: not a JavaScript number
  path->found = true;
  path->planner_type = PlannerType::kGeometric;
  path->partial_paths = {segment({{10, 3, 0}, {8, 3, 0}}, -1.0), segment({{8, 3, 0}, {12, 1, 0}}, 1.0),
                         segment({{12, 1, 0}, {30, 0, 0}}, 1.0)};
  v.path = path;
  auto request = std::make_shared<PullOutRequest>();
  request->ego_pose = {10, 3, 0};
  Lane lane;
  lane.id = 5;
  lane.subtype = LaneSubtype::kRoadShoulder;
  lane.left_bound = {{0, 4}, {50, 4}};
  lane.right_bound = {{0, 2}, {50, 2}};
  request->lanes = {lane};
  v.request = request;
  auto progress = std::make_shared<ExecutionProgress>();
  progress->pose = {0, 0, 0};
  v.progress = progress;
  v.last_update = now - std::chrono::milliseconds(2345);
  return v;
}

TEST(FleetRow, ShowsTheSegmentCountedFromOneAndTheSafety) {
  const auto now = Clock::now();
  VehicleView v = executing_vehicle(now);
  FleetRow row = fleet_row(v, now);
  EXPECT_EQ(row.vehicle, "car-1");
  EXPECT_EQ(row.state, "executing");
  EXPECT_EQ(row.planner, "geometric");
  EXPECT_EQ(row.segment, "2/3");
  EXPECT_EQ(row.safe, "yes");
  EXPECT_EQ(row.age, "2.3s");

  auto unsafe = std::make_shared<PullOutStatus>(*v.status);
  unsafe->state = ExecutionState::kWaitingSafety;
  unsafe->safe = false;
  unsafe->unsafe_object_id = 7;
  unsafe->stop_reason = "object 7 approaches\nsecond line";
  v.status = unsafe;
  v.last_update = now - std::chrono::seconds(75);
  row = fleet_row(v, now);
  EXPECT_EQ(row.safe, "no (object 7)");
  EXPECT_EQ(row.note, "object 7 approaches");
  EXPECT_EQ(row.age, "1m15s");
}

TEST(FleetRow, AVehicleWithoutStatusShowsDashes) {
  const auto now = Clock::now();
  VehicleView v;
  v.vehicle_id = "new";
  v.last_update = now - std::chrono::seconds(12);
  const FleetRow row = fleet_row(v, now);
  EXPECT_EQ(row.state, "-");
  EXPECT_EQ(row.planner, "-");
  EXPECT_EQ(row.segment, "-");
  EXPECT_EQ(row.safe, "-");
  EXPECT_EQ(row.age, "12s");
}

TEST(FleetTable, ColumnsAreAligned) {
  const auto now = Clock::now();
  FleetSnapshot snapshot;
  snapshot.vehicles.push_back(executing_vehicle(now));
  VehicleView other;
  other.vehicle_id = "a-much-longer-vehicle-id";
  other.last_update = now;
  snapshot.vehicles.push_back(other);
  std::istringstream lines(render_fleet_table(snapshot, now));
  std::string header;
  std::string first;
  std::string second;
  std::getline(lines, header);
  std::getline(lines, first);
  std::getline(lines, second);
  const std::size_t state_column = header.find("STATE");
  ASSERT_NE(state_column, std::string::npos);
  EXPECT_EQ(state_column, std::string("a-much-longer-vehicle-id").size() + 2);
  EXPECT_EQ(first.find("executing"), state_column) << first;
  EXPECT_EQ(second.substr(state_column, 1), "-") << second;
}

TEST(FleetTable, NoVehicles) {
  EXPECT_EQ(render_fleet_table(FleetSnapshot{}, Clock::now()),
            "VEHICLE  STATE  PLANNER  SEGMENT  SAFE  AGE  NOTE\n(no vehicles)\n");
}

TEST(FleetJson, DrawsThePathTheFootprintAtTheLatestPoseAndTheLanes) {
  const auto now = Clock::now();
  FleetSnapshot snapshot;
  snapshot.version = 4;
  snapshot.service_matched = true;
  snapshot.vehicles.push_back(executing_vehicle(now));
  const nlohmann::json j = fleet_json(snapshot, VehicleInfo{}, now);
  EXPECT_EQ(j["version"], 4);
  EXPECT_EQ(j["service"], true);
  ASSERT_EQ(j["vehicles"].size(), 1u);
  const auto& v = j["vehicles"][0];
  EXPECT_EQ(v["id"], "car-1");
  EXPECT_EQ(v["current_segment"], 1);
  EXPECT_EQ(v["segment"], "2/3");
  ASSERT_EQ(v["path"]["segments"].size(), 3u);
  EXPECT_EQ(v["path"]["segments"][0]["reverse"], true);
  EXPECT_EQ(v["path"]["segments"][1]["reverse"], false);
  EXPECT_EQ(v["path"]["segments"][2]["points"].size(), 2u);
  EXPECT_EQ(v["path"]["request_id"], "9007199254740993");
  // At the progress pose (0, 0, 0), not the request's ego pose. Default vehicle: front = wheel base
  // 2.79 + front overhang 1.0, rear = 1.1, half width = tread 1.64 / 2 + overhang 0.128.
  const nlohmann::json corners = {{3.79, 0.948}, {-1.1, 0.948}, {-1.1, -0.948}, {3.79, -0.948}};
  ASSERT_EQ(v["footprint"].size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(v["footprint"][i][0].get<double>(), corners[i][0].get<double>(), 1e-9) << i;
    EXPECT_NEAR(v["footprint"][i][1].get<double>(), corners[i][1].get<double>(), 1e-9) << i;
  }
  ASSERT_EQ(v["lanes"].size(), 1u);
  EXPECT_EQ(v["lanes"][0]["subtype"], "road_shoulder");
  EXPECT_EQ(v["lanes"][0]["outline"], nlohmann::json({{0, 4}, {50, 4}, {50, 2}, {0, 2}}));
}

}  // namespace
}  // namespace pullout::cli
