#include "integration_support.hpp"

#include <cmath>
#include <exception>
#include <iostream>

namespace pullout::integration {

namespace {

// [m] end of one partial path to the start of the next.
constexpr double kJoinTolerance = 0.1;

}  // namespace

std::string source_path(const std::string& relative) { return std::string(PULLOUT_SOURCE_DIR) + "/" + relative; }
std::string scenario_path(const std::string& name) { return source_path("tests/scenarios/" + name + ".yaml"); }
std::string default_config_path() { return source_path("config/pullout.yaml"); }
std::string loopback_profiles_path() { return source_path("config/dds/loopback.xml"); }

Scenario load_test_scenario(const std::string& name) {
  return load_scenario(scenario_path(name), load_config(default_config_path()));
}

void translate(PullOutRequest& request, double dx, double dy) {
  const auto move_pose = [dx, dy](Pose2& p) {
    p.x += dx;
    p.y += dy;
  };
  const auto move_points = [dx, dy](std::vector<Point2>& points) {
    for (Point2& p : points) {
      p.x += dx;
      p.y += dy;
    }
  };
  move_pose(request.ego_pose);
  move_pose(request.goal_pose);
  for (Lane& lane : request.lanes) {
    move_points(lane.left_bound);
    move_points(lane.right_bound);
    move_points(lane.centerline);
  }
  for (Object& o : request.objects) {
    move_pose(o.pose);
    for (PredictedPath& path : o.predicted_paths) {
      for (Pose2& p : path.poses) move_pose(p);
    }
  }
  if (request.occupancy_grid) move_pose(request.occupancy_grid->origin);
}

void expect_found_path_invariants(const PullOutPath& path) {
  EXPECT_TRUE(path.found);
  ASSERT_GE(path.partial_paths.size(), 1u);
  EXPECT_EQ(path.pairs_terminal_velocity_and_accel.size(), path.partial_paths.size());
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    const auto& points = path.partial_paths[k].points;
    EXPECT_GE(points.size(), 2u) << "partial path " << k;
    bool forward = false;
    bool reverse = false;
    for (const PathPoint& p : points) {
      ASSERT_TRUE(std::isfinite(p.pose.x) && std::isfinite(p.pose.y) && std::isfinite(p.pose.yaw) &&
                  std::isfinite(p.longitudinal_velocity_mps))
          << "partial path " << k;
      forward = forward || p.longitudinal_velocity_mps > 0.0;
      reverse = reverse || p.longitudinal_velocity_mps < 0.0;
    }
    EXPECT_FALSE(forward && reverse) << "partial path " << k << " changes direction";
    if (k + 1 < path.partial_paths.size() && !points.empty() && !path.partial_paths[k + 1].points.empty()) {
      const Pose2& end = points.back().pose;
      const Pose2& next = path.partial_paths[k + 1].points.front().pose;
      EXPECT_LE(std::hypot(end.x - next.x, end.y - next.y), kJoinTolerance) << "join " << k << " -> " << k + 1;
    }
  }
}

ExecutionProgress progress_sample(std::uint64_t request_id, std::int64_t stamp_ns, const Pose2& pose,
                                  double velocity_mps, bool approved) {
  ExecutionProgress p;
  p.request_id = request_id;
  p.stamp_ns = stamp_ns;
  p.pose = pose;
  p.velocity_mps = velocity_mps;
  p.approved = approved;
  return p;
}

ServiceTest::Sent ServiceTest::start_and_send(const std::string& scenario_name, const std::string& vehicle) {
  Sent sent;
  sent.scenario = load_test_scenario(scenario_name);
  start_service();
  sent.client = connect(vehicle);
  if (sent.client == nullptr) return sent;
  sent.id = sent.client->send(sent.scenario.request);
  sent.path = sent.client->wait_for_path(sent.id, kReplyTimeout);
  if (sent.path && sent.path->found) expect_found_path_invariants(*sent.path);
  return sent;
}

void ServiceTest::start_service(const std::string& config_path) {
  ServiceOptions options;
  options.executable = PULLOUT_SERVICE_EXE;
  options.config_path = config_path;
  try {
    service_.emplace(options);
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
}

std::unique_ptr<Client> ServiceTest::connect(const std::string& vehicle, const std::string& profiles_file) {
  ClientOptions options;
  options.vehicle_id = vehicle;
  options.domain_id = domain();
  options.profiles_file = profiles_file;
  auto client = std::make_unique<Client>(options);
  if (!client->wait_for_service(kMatchTimeout)) {
    ADD_FAILURE() << "client '" << vehicle << "' did not match the service within " << kMatchTimeout.count() << " s";
    return nullptr;
  }
  return client;
}

void ServiceTest::TearDown() {
  if (!service_) return;
  const StopReport report = service_->stop();
  EXPECT_TRUE(report.exit.clean()) << report.describe() << "\nservice stderr:\n" << service_->stderr_tail();
  EXPECT_TRUE(report.leaked_shm_files.empty()) << report.describe();
  if (HasFailure()) std::cerr << "--- service stderr (tail) ---\n" << service_->stderr_tail() << "\n";
  service_.reset();
}

}  // namespace pullout::integration
