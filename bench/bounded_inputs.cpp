// Huge inputs (issue 11, "a 600-byte request can take the machine"): time and peak memory of one
// plan of each, every case in a child process of its own, so that its peak RSS is its own
// (wait4's ru_maxrss). Uses only the public planning API, so the same file builds against older
// versions of the core for a before/after comparison in one run (bench/RESULTS.md).
//
//   build/bench/bench_bounded [--case NAME] [--deadline-ms MS]   (default: every case, no deadline)
//
// Cases: 2-point lanes (a road and its shoulder) 20 km, 1e7 m and 1e8 m long; 64 such lanes of
// 1e7 m; a Lanelet2 map whose road and shoulder are single lanelets 100 km and 1,000 km long
// (written to a temporary file, loaded as the service loads it, then one route request); 512
// objects of 64 points each, non-convex (combs).
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "pullout/maps/osm_loader.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace {

using pullout::Lane;
using pullout::LaneSubtype;
using pullout::PlanningResult;
using pullout::PullOutRequest;

Lane straight(std::int64_t id, LaneSubtype subtype, double length, double y_right, double y_left) {
  Lane l;
  l.id = id;
  l.subtype = subtype;
  l.left_bound = {{0.0, y_left}, {length, y_left}};
  l.right_bound = {{0.0, y_right}, {length, y_right}};
  return l;
}

PullOutRequest shoulder_request(double length, int lanes) {
  PullOutRequest r;
  r.vehicle_id = "bench";
  r.request_id = 1;
  r.lanes = {straight(1, LaneSubtype::kRoad, length, -1.75, 1.75),
             straight(2, LaneSubtype::kRoadShoulder, length, 1.75, 4.75)};
  for (int k = 2; k < lanes; ++k) {
    r.lanes.push_back(straight(k + 1, LaneSubtype::kRoadShoulder, length, 1.75 + 3.0 * (k - 1), 4.75 + 3.0 * (k - 1)));
  }
  r.ego_pose = {10.0, 3.25, 0.0};
  r.goal_pose = {90.0, 0.0, 0.0};
  return r;
}

std::string map_file(double length) {
  std::ostringstream os;
  os.precision(17);
  os << "<?xml version=\"1.0\"?>\n<osm version=\"0.6\">\n";
  int id = 1;
  for (const double y : {-1.75, 1.75, 4.75}) {
    for (const double x : {0.0, length}) {
      os << "<node id=\"" << id++ << "\" lat=\"0\" lon=\"0\"><tag k=\"local_x\" v=\"" << x
         << "\"/><tag k=\"local_y\" v=\"" << y << "\"/></node>\n";
    }
  }
  os << "<way id=\"10\"><nd ref=\"1\"/><nd ref=\"2\"/></way><way id=\"11\"><nd ref=\"3\"/><nd ref=\"4\"/></way>"
     << "<way id=\"12\"><nd ref=\"5\"/><nd ref=\"6\"/></way>\n"
     << "<relation id=\"100\"><member type=\"way\" role=\"left\" ref=\"11\"/><member type=\"way\" role=\"right\" "
     << "ref=\"10\"/><tag k=\"type\" v=\"lanelet\"/><tag k=\"subtype\" v=\"road\"/></relation>\n"
     << "<relation id=\"101\"><member type=\"way\" role=\"left\" ref=\"12\"/><member type=\"way\" role=\"right\" "
     << "ref=\"11\"/><tag k=\"type\" v=\"lanelet\"/><tag k=\"subtype\" v=\"road_shoulder\"/></relation>\n</osm>\n";
  const std::string path = "/tmp/pullout_bench_bounded_" + std::to_string(::getpid()) + ".osm";
  std::ofstream(path) << os.str();
  return path;
}

const char* outcome_name(PlanningResult::Outcome o) {
  switch (o) {
    case PlanningResult::Outcome::kFound:
      return "found";
    case PlanningResult::Outcome::kNoPath:
      return "no_path";
    case PlanningResult::Outcome::kRejected:
      return "rejected";
  }
  return "?";
}

// One case, in the child: plan once and print what came out.
void run_case(const std::string& name, double deadline_ms) {
  std::shared_ptr<const pullout::LaneletMap> map;
  PullOutRequest request;
  if (name.rfind("map_", 0) == 0) {
    const double length = name == "map_100km" ? 1e5 : 1e6;
    const std::string path = map_file(length);
    map = pullout::load_lanelet_map(path);
    std::remove(path.c_str());
    request = shoulder_request(100.0, 2);
    request.lanes.clear();
    request.route_lanelet_ids = {100};
  } else if (name == "objects512_comb64") {
    // The most objects a request may carry, each the most points a polygon may have, as a comb
    // (simple, non-convex: 31 teeth) lining the far edge of the road, 2.5 m from its centreline,
    // within the collision checks' reach of the paths: every one cut into convex pieces.
    request = shoulder_request(100.0, 2);
    for (int k = 0; k < 512; ++k) {
      pullout::Object o;
      o.id = k + 1;
      o.object_class = pullout::ObjectClass::kUnknown;
      o.pose = {5.0 + 0.17 * k, -2.5, 0.0};
      o.length_m = 1.0;
      o.width_m = 1.0;
      for (int t = 0; t < 31; ++t) {  // the teeth along x, 0.1 m wide, 1 m deep
        o.polygon.push_back({0.1 * t, 0.0});
        o.polygon.push_back({0.1 * t + 0.05, (t % 2 == 0) ? -1.0 : -0.5});
      }
      o.polygon.push_back({3.1, 0.5});
      o.polygon.push_back({0.0, 0.5});
      request.objects.push_back(o);
    }
  } else {
    const double length = name == "lane_20km" ? 2e4 : name == "lane_1e8m" ? 1e8 : 1e7;
    request = shoulder_request(length, name == "lanes64_1e7m" ? 64 : 2);
  }
  const pullout::StartPlanner planner(pullout::VehicleInfo{}, pullout::StartPlannerParameters{},
                                      pullout::RequestLimits{}, map);
  const auto stop = deadline_ms > 0.0 ? pullout::StopCondition::after_ms(deadline_ms) : pullout::StopCondition();
  const PlanningResult r = planner.plan(request, stop);
  std::string detail = r.issues.empty() ? r.stop_reason : r.issues.front().field + ": " + r.issues.front().problem;
  std::printf("%s|%.1f|%s\n", outcome_name(r.outcome), r.planning_time_ms, detail.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> cases = {"lane_20km", "lane_1e7m",  "lane_1e8m",        "lanes64_1e7m",
                                    "map_100km", "map_1000km", "objects512_comb64"};
  double deadline_ms = 0.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--case") == 0) cases = {argv[i + 1]};
    if (std::strcmp(argv[i], "--deadline-ms") == 0) deadline_ms = std::atof(argv[i + 1]);
  }
  std::printf(
      "| case | outcome | planning [ms] | wall [s] | CPU [s] | peak RSS [MB] | detail "
      "|\n|---|---|---|---|---|---|---|\n");
  for (const std::string& name : cases) {
    int fds[2];
    if (pipe(fds) != 0) return 1;
    std::fflush(stdout);
    const auto t0 = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      run_case(name, deadline_ms);
      _exit(0);
    }
    close(fds[1]);
    std::string line;
    char buf[4096];
    for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) line.append(buf, static_cast<std::size_t>(n));
    close(fds[0]);
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                       1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    if (!line.empty() && line.back() == '\n') line.pop_back();
    std::string outcome = "killed";
    std::string planning = "-";
    std::string detail = WIFSIGNALED(status) ? std::string("signal ") + std::to_string(WTERMSIG(status)) : "";
    const auto a = line.find('|');
    const auto b = a == std::string::npos ? a : line.find('|', a + 1);
    if (b != std::string::npos) {
      outcome = line.substr(0, a);
      planning = line.substr(a + 1, b - a - 1);
      for (const char c : line.substr(b + 1)) detail += c == '|' ? std::string("\\|") : std::string(1, c);
    }
    std::printf("| %s | %s | %s | %.2f | %.2f | %.0f | %s |\n", name.c_str(), outcome.c_str(), planning.c_str(), wall,
                cpu, static_cast<double>(usage.ru_maxrss) / 1024.0, detail.c_str());
  }
  return 0;
}
