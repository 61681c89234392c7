// pullout_vehicle_client: what a vehicle does with the pullout service, start to finish.
//
//   1. connect    a pullout::Client for this vehicle; wait until the service is matched
//   2. request    send the situation (lanes, pose, goal, objects) and wait for the answer
//   3. outcome    rejected (the request was wrong: fix the field named), no path (stay parked,
//                 the reasons say why), or a path made of segments
//   4. approve    an explicit step: nothing departs until approve_departure() says so (here a
//                 command-line flag; in a vehicle the driver or the supervisor)
//   5. follow     drive each segment (here: a simulated vehicle on the path's points), report the
//                 odometry at 20 Hz, stop at the end of a segment until the service moves on
//   6. completed  the service says the vehicle passed the end pose
//
// A lost service (killed, network gone) is noticed by the client (ServiceState::kLost) and ends
// the run with an error: a vehicle must then stop and not rely on the path's safety checks.
//
// Exit codes: 0 completed, 1 no path, 2 rejected or bad arguments, 3 no service / service lost /
// timeout, 4 approval refused.
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "pullout/client/client.hpp"
#include "pullout/model/names.hpp"
#include "pullout/model/types.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::system_clock;

struct Options {
  std::string vehicle_id{"example-vehicle"};
  int domain_id{0};
  std::string profiles_file{PULLOUT_DEFAULT_PROFILES};
  bool approve{false};
};

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// The situation: a straight road with a shoulder on its left, the vehicle parked on the shoulder
// 3 m behind a parked car (too close to pull out directly), the goal ahead on the road lane. The service plans two
// segments: reverse along the shoulder, then shift out. A vehicle builds this from its map and perception.
pullout::PullOutRequest make_request() {
  pullout::PullOutRequest request;
  pullout::Lane road;
  road.id = 1;
  road.subtype = pullout::LaneSubtype::kRoad;
  road.left_bound = {{0.0, 1.75}, {100.0, 1.75}};
  road.right_bound = {{0.0, -1.75}, {100.0, -1.75}};
  pullout::Lane shoulder;
  shoulder.id = 2;
  shoulder.subtype = pullout::LaneSubtype::kRoadShoulder;
  shoulder.left_bound = {{-30.0, 4.75}, {100.0, 4.75}};
  shoulder.right_bound = {{-30.0, 1.75}, {100.0, 1.75}};
  request.lanes = {road, shoulder};
  pullout::Object parked_car;
  parked_car.id = 7;
  parked_car.object_class = pullout::ObjectClass::kCar;
  parked_car.pose = {19.04, 3.25, 0.0};
  parked_car.length_m = 4.5;
  parked_car.width_m = 1.9;
  request.objects = {parked_car};
  request.ego_pose = {10.0, 3.25, 0.0};
  request.goal_pose = {90.0, 0.0, 0.0};
  return request;
}

// Step 4: the vehicle's own approval. Replace with the driver's confirmation or the supervisor's
// decision; the service never lets the vehicle depart without it.
bool approve_departure(const pullout::PullOutPath& path, const Options& options) {
  std::cout << "approval: " << path.partial_paths.size() << " segment(s) by the "
            << pullout::to_string(path.planner_type) << " planner; " << (options.approve ? "approved" : "refused")
            << " (--approve)\n";
  return options.approve;
}

void report(pullout::Client& client, std::uint64_t id, const pullout::Pose2& pose, double v, bool approved) {
  pullout::ExecutionProgress p;
  p.request_id = id;
  p.stamp_ns = now_ns();
  p.pose = pose;
  p.velocity_mps = v;
  p.approved = approved;
  client.report_progress(p);
}

bool lost(const pullout::Client& client) { return client.service_state() == pullout::ServiceState::kLost; }

int run(const Options& options) {
  // 1. connect
  pullout::ClientOptions client_options;
  client_options.vehicle_id = options.vehicle_id;
  client_options.domain_id = options.domain_id;
  client_options.profiles_file = options.profiles_file;
  pullout::Client client(client_options);
  if (!client.wait_for_service(15s)) {
    std::cerr << "no pullout service on DDS domain " << options.domain_id << '\n';
    return 3;
  }
  std::cout << "connected to the pullout service on domain " << options.domain_id << '\n';

  // 2. request
  const std::uint64_t id = client.send(make_request());
  std::cout << "request " << id << " sent\n";
  const auto answered = [](const pullout::PullOutStatus& s) { return s.state != pullout::ExecutionState::kPlanning; };
  const std::optional<pullout::PullOutStatus> status = client.wait_for_status(id, answered, 15s);
  if (!status) {
    std::cerr << (lost(client) ? "service lost" : "no answer in time") << '\n';
    return 3;
  }

  // 3. outcome
  switch (status->state) {
    case pullout::ExecutionState::kRejected:
      std::cerr << "rejected:\n" << status->error << '\n';
      return 2;
    case pullout::ExecutionState::kNoPath:
      std::cerr << "no path, stay parked: " << status->stop_reason << '\n';
      return 1;
    default:
      break;
  }
  const std::optional<pullout::PullOutPath> path = client.wait_for_path(id, 5s);
  if (!path || !path->found) {
    std::cerr << "no path received\n";
    return 3;
  }
  std::cout << "path: " << path->partial_paths.size() << " segment(s), state " << pullout::to_string(status->state)
            << '\n';

  // 4. approve: until then, report odometry standing still with approved = false.
  const pullout::Pose2 start = path->partial_paths.front().points.front().pose;
  if (!approve_departure(*path, options)) {
    report(client, id, start, 0.0, false);
    return 4;
  }

  // 5. follow. The service checks safety at every sample and may hold the vehicle (waiting
  // safety); a real vehicle obeys the latest status before moving on.
  const auto executing = [](const pullout::PullOutStatus& s) { return s.state == pullout::ExecutionState::kExecuting; };
  std::optional<pullout::PullOutStatus> go;
  for (int i = 0; i < 100 && !go; ++i) {  // at most 5 s of standing at 20 Hz
    report(client, id, start, 0.0, true);
    go = client.wait_for_status(id, executing, 50ms);
    if (lost(client)) break;
  }
  if (!go) {
    std::cerr << (lost(client) ? "service lost" : "not released for departure") << '\n';
    return 3;
  }
  std::cout << "executing\n";
  const std::size_t segments = path->partial_paths.size();
  for (std::size_t k = 0; k < segments; ++k) {
    const auto& points = path->partial_paths[k].points;
    std::cout << "segment " << k + 1 << "/" << segments << ": " << points.size() << " points, "
              << (points.front().longitudinal_velocity_mps < 0.0 ? "reverse" : "forward") << '\n';
    for (const pullout::PathPoint& p : points) {
      const double v = p.longitudinal_velocity_mps == 0.0 ? 0.5 : p.longitudinal_velocity_mps;
      report(client, id, p.pose, v, true);
      std::this_thread::sleep_for(20ms);
      if (lost(client)) {
        std::cerr << "service lost while driving: stop\n";
        return 3;
      }
    }
    if (k + 1 == segments) break;
    // Stand still at the end of the segment until the service moves on to the next one.
    std::optional<pullout::PullOutStatus> next;
    for (int i = 0; i < 100 && !next && !lost(client); ++i) {
      report(client, id, points.back().pose, 0.0, true);
      next = client.wait_for_status(
          id, [k](const pullout::PullOutStatus& s) { return s.current_path_idx == k + 1; }, 50ms);
    }
    if (!next) {
      std::cerr << "the service did not move on to segment " << k + 2 << '\n';
      return 3;
    }
  }

  // 6. completed
  const auto done = client.wait_for_status(
      id, [](const pullout::PullOutStatus& s) { return s.state == pullout::ExecutionState::kCompleted; }, 10s);
  if (!done) {
    std::cerr << (lost(client) ? "service lost" : "not completed") << '\n';
    return 3;
  }
  std::cout << "completed\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "-h" || arg == "--help") {
      std::cout << "usage: pullout_vehicle_client [--domain N] [--vehicle ID] [--profiles FILE.xml] [--approve]\n";
      return 0;
    }
    if (arg == "--approve") {
      options.approve = true;
    } else if (arg == "--domain" && has_value) {
      // Strictly a whole number: atoi made "abc" domain 0, where another fleet's service may be.
      const std::string value = argv[++i];
      char* end = nullptr;
      const long domain = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || end != value.c_str() + value.size() || domain < 0 || domain > 232) {
        std::cerr << "--domain: expected a DDS domain id in 0..232, got '" << value << "'\n";
        return 2;
      }
      options.domain_id = static_cast<int>(domain);
    } else if (arg == "--vehicle" && has_value) {
      options.vehicle_id = argv[++i];
    } else if (arg == "--profiles" && has_value) {
      options.profiles_file = argv[++i];
    } else {
      std::cerr << "usage: pullout_vehicle_client [--domain N] [--vehicle ID] [--profiles FILE.xml] [--approve]\n";
      return 2;
    }
  }
  try {
    return run(options);
  } catch (const std::invalid_argument& e) {  // a ClientOptions field the client refuses: a bad argument
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 3;
  }
}
