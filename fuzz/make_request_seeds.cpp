// Writes the seed corpus of fuzz_request: one pullout/request sample per file, encoded exactly as
// a DataWriter puts it on the wire (the guarded type support's serialize: the 4-byte CDR
// encapsulation header, then the CDR body).
//
//   make_request_seeds <output dir> <scenario files...>
//
// Each scenario gives <stem>.cdr (its request, as `pullout request` sends it); a scenario with a
// route of lanelet ids also gives <stem>_route_segments.cdr (the same route as an Autoware route's
// segments). The newer request fields get seeds of their own: vehicle_profile_bus.cdr (a profile of
// the shipped config) and vehicle_own_dimensions.cdr (the vehicle's own dimensions). A few bad requests
// follow, named bad_*.cdr: lanes 20 km across and 1e7 m long, coordinates of 1e20, the objects
// limit reached and exceeded, a lane of 2,000 points, NaN and non-unit orientations, a grid whose
// cell count disagrees with its size, a huge deadline, a vehicle with a negative wheel base and one
// named by a profile and given dimensions at once, and two hand-made CDR streams (a sequence
// length of 2^31 - 1 with nothing behind it, and a truncated encoding). The seeds are committed
// (fuzz/corpus/request/); scripts/fuzz --seeds regenerates them.
//
//   make_request_seeds --progress <output dir> <scenario file>
//
// writes fuzz_progress's seeds instead (fuzz/corpus/progress/): pullout/progress samples of the
// scenario's vehicle at its start (write_progress_seeds).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

namespace {

namespace fs = std::filesystem;
using pullout::Lane;
using pullout::LaneSubtype;
using pullout::Object;
using pullout::Point2;
using pullout::Pose2;
using pullout::PullOutRequest;

template <typename PubSubType, typename Message>
std::string encode_as(const Message& message) {
  pullout::idl::GuardedType<PubSubType> type;
  auto copy = message;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&copy)());
  if (!type.serialize(&copy, &payload)) throw std::runtime_error("serialize failed");
  return std::string(reinterpret_cast<const char*>(payload.data), payload.length);
}

std::string encode(const pullout::msg::PullOutRequest& message) {
  return encode_as<pullout::msg::PullOutRequestPubSubType>(message);
}

void write(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + file.string());
  std::cout << file.string() << ": " << bytes.size() << " bytes\n";
}

Lane straight_lane(std::int64_t id, LaneSubtype subtype, double x0, double x1, double y_right, double y_left) {
  Lane lane;
  lane.id = id;
  lane.subtype = subtype;
  lane.left_bound = {{x0, y_left}, {x1, y_left}};
  lane.right_bound = {{x0, y_right}, {x1, y_right}};
  return lane;
}

// The straight_shoulder situation: a road and a shoulder, the ego on the shoulder.
PullOutRequest base_request(const std::string& vehicle_id) {
  PullOutRequest r;
  r.vehicle_id = vehicle_id;
  r.request_id = 1;
  r.ego_pose = Pose2{10.0, 3.25, 0.0};
  r.goal_pose = Pose2{90.0, 0.0, 0.0};
  r.lanes = {straight_lane(1, LaneSubtype::kRoad, 0.0, 100.0, -1.75, 1.75),
             straight_lane(2, LaneSubtype::kRoadShoulder, 0.0, 100.0, 1.75, 4.75)};
  return r;
}

Object car(std::int64_t id, double x, double y) {
  Object o;
  o.id = id;
  o.object_class = pullout::ObjectClass::kCar;
  o.pose = Pose2{x, y, 0.0};
  o.length_m = 4.5;
  o.width_m = 1.9;
  return o;
}

// The requests of the newer fields that no scenario carries: a vehicle by profile, and by its own
// dimensions (the bus's: planned with a longer and wider footprint than the default car).
void write_vehicle_requests(const fs::path& dir) {
  PullOutRequest by_profile = base_request("vehicle-profile");
  by_profile.vehicle_profile = "bus";
  write(dir / "vehicle_profile_bus.cdr", encode(pullout::idl::to_msg(by_profile)));
  PullOutRequest own = base_request("vehicle-own");
  own.vehicle = pullout::default_vehicle_profiles().at("bus");
  write(dir / "vehicle_own_dimensions.cdr", encode(pullout::idl::to_msg(own)));
}

void write_bad_requests(const fs::path& dir) {
  {  // two 2-point bounds 20 km across: a 20 km x 20 km road with the ego in it
    PullOutRequest r = base_request("bad-lane-20km");
    r.lanes = {straight_lane(1, LaneSubtype::kRoad, -10000.0, 10000.0, -10000.0, 10000.0)};
    r.ego_pose = Pose2{0.0, 0.0, 0.0};
    r.goal_pose = Pose2{80.0, 0.0, 0.0};
    write(dir / "bad_lane_20km_across.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // a road and a shoulder 1e7 m long
    PullOutRequest r = base_request("bad-lane-1e7m");
    r.lanes = {straight_lane(1, LaneSubtype::kRoad, 0.0, 1e7, -1.75, 1.75),
               straight_lane(2, LaneSubtype::kRoadShoulder, 0.0, 1e7, 1.75, 4.75)};
    write(dir / "bad_lane_1e7m_long.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // every coordinate near 1e20
    PullOutRequest r = base_request("bad-1e20");
    const double o = 1e20;
    r.lanes = {straight_lane(1, LaneSubtype::kRoad, o, o + 100.0, o - 1.75, o + 1.75),
               straight_lane(2, LaneSubtype::kRoadShoulder, o, o + 100.0, o + 1.75, o + 4.75)};
    r.ego_pose = Pose2{o + 10.0, o + 3.25, 0.0};
    r.goal_pose = Pose2{o + 90.0, o, 0.0};
    r.objects = {car(7, o + 24.0, o + 3.25)};
    write(dir / "bad_coordinates_1e20.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // a lane 1e20 m long, the ego at its start
    PullOutRequest r = base_request("bad-lane-1e20m");
    r.lanes = {straight_lane(1, LaneSubtype::kRoad, 0.0, 1e20, -1.75, 1.75),
               straight_lane(2, LaneSubtype::kRoadShoulder, 0.0, 1e20, 1.75, 4.75)};
    write(dir / "bad_lane_1e20m_long.cdr", encode(pullout::idl::to_msg(r)));
  }
  for (const std::size_t count : {std::size_t{512}, std::size_t{513}}) {  // the limit, and one more
    PullOutRequest r = base_request("bad-objects-" + std::to_string(count));
    for (std::size_t i = 0; i < count; ++i) {
      r.objects.push_back(car(static_cast<std::int64_t>(i), 20.0 + 6.0 * static_cast<double>(i % 16),
                              -20.0 - 3.0 * static_cast<double>(i / 16)));
    }
    r.objects.front().pose = Pose2{24.0, 3.25, 0.0};  // one in the way
    write(dir / ("bad_objects_" + std::to_string(count) + ".cdr"), encode(pullout::idl::to_msg(r)));
  }
  {  // a road bound of 2,000 points
    PullOutRequest r = base_request("bad-points");
    Lane& road = r.lanes.front();
    road.left_bound.clear();
    for (int i = 0; i < 2000; ++i) road.left_bound.push_back(Point2{0.05 * i, 1.75});
    write(dir / "bad_lane_2000_points.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // NaN and a non-unit quaternion
    PullOutRequest r = base_request("bad-nan");
    auto message = pullout::idl::to_msg(r);
    message.ego_pose().position().x(std::numeric_limits<double>::quiet_NaN());
    message.goal_pose().orientation().w(2.0);
    write(dir / "bad_nan_and_quaternion.cdr", encode(message));
  }
  {  // a grid of 4096 x 4096 cells with 16 bytes of data, and no lanes
    PullOutRequest r = base_request("bad-grid");
    r.lanes.clear();
    pullout::OccupancyGrid grid;
    grid.resolution_m = 0.2;
    grid.width = 4096;
    grid.height = 4096;
    grid.data.assign(16, 0);
    r.occupancy_grid = grid;
    write(dir / "bad_grid_size.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // a deadline of 1e300 ms
    PullOutRequest r = base_request("bad-deadline");
    r.deadline_ms = 1e300;
    write(dir / "bad_deadline_huge.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // own dimensions with a negative wheel base
    PullOutRequest r = base_request("bad-vehicle");
    pullout::VehicleInfo vehicle = pullout::default_vehicle_profiles().at("van");
    vehicle.wheel_base_m = -3.0;
    r.vehicle = vehicle;
    write(dir / "bad_vehicle_dimensions.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // a profile and own dimensions at once (one or the other)
    PullOutRequest r = base_request("bad-vehicle-both");
    r.vehicle_profile = "bus";
    r.vehicle = pullout::default_vehicle_profiles().at("bus");
    write(dir / "bad_vehicle_profile_and_dimensions.cdr", encode(pullout::idl::to_msg(r)));
  }
  {  // a header and vehicle id, then a lanes sequence length of 2^31 - 1 with no elements behind it
    std::vector<char> buffer(256, 0);
    eprosima::fastcdr::FastBuffer fast(buffer.data(), buffer.size());
    eprosima::fastcdr::Cdr cdr(fast, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    cdr.serialize_encapsulation();
    cdr << std::string("bad-sequence-length") << std::uint64_t{1} << std::int32_t{0} << std::uint32_t{0};
    for (double v : {10.0, 3.25, 0.0, 0.0, 0.0, 0.0, 1.0}) cdr << v;  // ego pose
    cdr << 0.0;                                                       // ego velocity
    for (double v : {90.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0}) cdr << v;   // goal pose
    cdr << std::uint32_t{0x7fffffff};                                 // lanes
    write(dir / "bad_sequence_length.cdr", std::string(buffer.data(), cdr.getSerializedDataLength()));
  }
  {  // the first 100 bytes of a valid request
    const std::string whole = encode(pullout::idl::to_msg(base_request("bad-truncated")));
    write(dir / "bad_truncated.cdr", whole.substr(0, 100));
  }
}

}  // namespace

// fuzz_progress's seeds: progress samples of the scenario's vehicle standing at its start (the
// start of the path fuzz_progress plans there), for its request (request id 0), not approved,
// approved, moving, for another request, and the speeds the validation refuses.
void write_progress_seeds(const fs::path& dir, const pullout::Scenario& scenario) {
  pullout::ExecutionProgress p;
  p.vehicle_id = "fuzz";
  p.request_id = 0;
  p.stamp_ns = 5'000'000'000;
  p.pose = scenario.request.ego_pose;
  const auto put = [&dir](const std::string& name, const pullout::ExecutionProgress& progress) {
    write(dir / name, encode_as<pullout::msg::ExecutionProgressPubSubType>(pullout::idl::to_msg(progress)));
  };
  put("standing.cdr", p);
  pullout::ExecutionProgress approved = p;
  approved.approved = true;
  put("standing_approved.cdr", approved);
  pullout::ExecutionProgress moving = approved;
  moving.velocity_mps = 1.5;
  moving.pose.x += 2.0;
  put("moving_approved.cdr", moving);
  pullout::ExecutionProgress other = p;
  other.request_id = 99;
  put("other_request.cdr", other);
  pullout::ExecutionProgress fast = p;
  fast.velocity_mps = std::numeric_limits<double>::infinity();
  put("bad_velocity_infinite.cdr", fast);
  fast.velocity_mps = 1e300;
  put("bad_velocity_1e300.cdr", fast);
  pullout::ExecutionProgress far = p;
  far.pose.x = 1e20;
  put("bad_pose_1e20.cdr", far);
}

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "--progress") {
    try {
      const fs::path dir(argv[2]);
      fs::create_directories(dir);
      write_progress_seeds(dir, pullout::load_scenario(argv[3]));
    } catch (const std::exception& e) {
      std::cerr << "make_request_seeds: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  if (argc < 2) {
    std::cerr << "usage: make_request_seeds <output dir> <scenario files...>\n"
                 "       make_request_seeds --progress <output dir> <scenario file>\n";
    return 2;
  }
  try {
    const fs::path dir(argv[1]);
    fs::create_directories(dir);
    for (int i = 2; i < argc; ++i) {
      const pullout::Scenario scenario = pullout::load_scenario(argv[i]);
      const std::string stem = fs::path(argv[i]).stem().string();
      write(dir / (stem + ".cdr"), encode(pullout::idl::to_msg(scenario.request)));
      if (!scenario.request.route_lanelet_ids.empty()) {
        PullOutRequest segments = scenario.request;
        for (const std::int64_t id : segments.route_lanelet_ids) segments.route_segments.push_back({id, {id}});
        segments.route_lanelet_ids.clear();
        write(dir / (stem + "_route_segments.cdr"), encode(pullout::idl::to_msg(segments)));
      }
    }
    write_vehicle_requests(dir);
    write_bad_requests(dir);
  } catch (const std::exception& e) {
    std::cerr << "make_request_seeds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
