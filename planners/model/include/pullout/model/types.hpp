// The pullout data model: the values exchanged between a vehicle and the planner.
//
// Plain value types with no dependencies beyond the standard library, so that the client library
// can expose them in its public headers. They mirror the DDS topics of idl/pullout.idl; conversion
// to and from the generated DDS types happens in exactly one place (idl/src/convert.cpp).
//
// Frames and units: every pose and point is in the map frame, x/y in metres, yaw in radians
// (counter-clockwise from +x). Velocities in m/s, accelerations in m/s^2, times in seconds unless a
// name says otherwise.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pullout {

// The longest vehicle_id [bytes] the system accepts: the generated DDS type support serializes the
// key (vehicle_id) into a fixed 4 + 255 + 1 byte buffer, so a reply to a longer id cannot be
// written. Client, conversion, service and validation all check against this one value.
inline constexpr std::size_t kMaxVehicleIdBytes = 255;

struct Point2 {
  double x{0.0};  // [m]
  double y{0.0};  // [m]
};

// Pose of a body B in the map frame M (X_MB). yaw [rad] counter-clockwise from the map +x axis.
struct Pose2 {
  double x{0.0};    // [m]
  double y{0.0};    // [m]
  double yaw{0.0};  // [rad]
};

enum class LaneSubtype : std::uint8_t { kRoad = 0, kRoadShoulder = 1 };

// A lane given inline in a request: two bounds (ordered in the driving direction) and an optional
// centerline. When the centerline is empty the planner derives it from the bounds.
struct Lane {
  std::int64_t id{0};
  LaneSubtype subtype{LaneSubtype::kRoad};
  std::vector<Point2> left_bound;
  std::vector<Point2> right_bound;
  std::vector<Point2> centerline;  // optional
  double speed_limit_mps{13.89};   // [m/s]
};

enum class ObjectClass : std::uint8_t {
  kUnknown = 0,
  kCar = 1,
  kTruck = 2,
  kBus = 3,
  kTrailer = 4,
  kMotorcycle = 5,
  kBicycle = 6,
  kPedestrian = 7,
};

// A predicted path of an object: poses at t0, t0 + time_step, ...
struct PredictedPath {
  std::vector<Pose2> poses;
  double time_step_s{1.0};  // [s]
  double confidence{1.0};   // [0, 1]
};

// An object around the vehicle. Its footprint is a box length x width centred on `pose`, unless
// `polygon` is given (a convex polygon in the object frame, counter-clockwise).
struct Object {
  std::int64_t id{0};
  ObjectClass object_class{ObjectClass::kUnknown};
  Pose2 pose;
  double length_m{4.5};
  double width_m{1.9};
  std::vector<Point2> polygon;  // optional, object frame
  double velocity_mps{0.0};     // longitudinal speed along the object's heading [m/s]
  std::vector<PredictedPath> predicted_paths;
};

// An occupancy grid in the ROS convention: row-major from `origin`, cells 0 (free) .. 100
// (occupied), -1 unknown.
// The cell sizes [m] a given occupancy grid may have (a request's, a scenario's): 1 cm to 5 m. Finer
// cells would make the collision checker's cell counts overflow (a 1e-308 m cell is not a grid);
// coarser ones would not show the gaps the planner drives through.
inline constexpr double kMinGridResolution = 0.01;
inline constexpr double kMaxGridResolution = 5.0;

struct OccupancyGrid {
  double resolution_m{0.2};  // [kMinGridResolution, kMaxGridResolution]
  Pose2 origin;
  std::uint32_t width{0};
  std::uint32_t height{0};
  std::vector<std::int8_t> data;
};

enum class PlannerType : std::uint8_t {
  kNone = 0,
  kShift = 1,
  kGeometric = 2,
  kClothoid = 3,
  kStop = 4,
  kFreespace = 5,
};

enum class SearchPolicy : std::uint8_t { kPlannerPriority = 0, kDistancePriority = 1 };

// Per-request overrides of the service's planner configuration. Empty / unset means "use the
// service's configuration".
struct PlannerOverrides {
  std::vector<PlannerType> search_priority;
  std::optional<SearchPolicy> search_policy;
};

// One segment of an Autoware route (autoware_planning_msgs LaneletSegment): the lanelet the route
// prefers there and every lanelet of the segment (its lane-change neighbours, the preferred one
// among them).
struct RouteSegment {
  std::int64_t preferred_id{0};
  std::vector<std::int64_t> primitive_ids;
};

// A vehicle's dimensions and steering limit, in its base_link frame (the rear-axle centre, +x
// forward). Names are Autoware's vehicle_info keys with a unit suffix (wheel_base -> wheel_base_m).
struct VehicleInfo {
  double wheel_base_m{2.79};
  double wheel_tread_m{1.64};
  double front_overhang_m{1.0};
  double rear_overhang_m{1.1};
  double left_overhang_m{0.128};
  double right_overhang_m{0.128};
  double max_steer_angle_rad{0.70};

  double base_to_front_m() const { return wheel_base_m + front_overhang_m; }
  double base_to_rear_m() const { return rear_overhang_m; }
  double length_m() const { return base_to_front_m() + base_to_rear_m(); }  // Autoware's vehicle_length
  double base_to_left_m() const { return wheel_tread_m / 2.0 + left_overhang_m; }
  double base_to_right_m() const { return wheel_tread_m / 2.0 + right_overhang_m; }
  double width_m() const { return base_to_left_m() + base_to_right_m(); }  // Autoware's vehicle_width
  // Minimum turning radius of the rear-axle centre at max steer [m].
  double min_turning_radius_m() const { return wheel_base_m / std::tan(max_steer_angle_rad); }

  bool operator==(const VehicleInfo& o) const {
    return wheel_base_m == o.wheel_base_m && wheel_tread_m == o.wheel_tread_m &&
           front_overhang_m == o.front_overhang_m && rear_overhang_m == o.rear_overhang_m &&
           left_overhang_m == o.left_overhang_m && right_overhang_m == o.right_overhang_m &&
           max_steer_angle_rad == o.max_steer_angle_rad;
  }
  bool operator!=(const VehicleInfo& o) const { return !(*this == o); }
};

// Each VehicleInfo member with its Autoware key, unit and allowed range (closed): the one spelling
// that the config file's `vehicle` and `vehicle_profiles` and a request's own vehicle are checked
// against. max_steer_angle stays below pi/2 so the turning radius is positive and finite.
struct VehicleField {
  const char* key;
  double VehicleInfo::*member;
  const char* unit;
  double min;
  double max;
  const char* comment;
};
inline constexpr std::array<VehicleField, 7> kVehicleFields{{
    {"wheel_base", &VehicleInfo::wheel_base_m, "m", 0.1, 20.0, "front to rear axle"},
    {"wheel_tread", &VehicleInfo::wheel_tread_m, "m", 0.1, 5.0, "distance between the left and right wheels"},
    {"front_overhang", &VehicleInfo::front_overhang_m, "m", 0.0, 10.0, "front axle to the front bumper"},
    {"rear_overhang", &VehicleInfo::rear_overhang_m, "m", 0.0, 10.0, "rear axle to the rear bumper"},
    {"left_overhang", &VehicleInfo::left_overhang_m, "m", 0.0, 2.0,
     "left wheel outer face to the left side of the body"},
    {"right_overhang", &VehicleInfo::right_overhang_m, "m", 0.0, 2.0,
     "right wheel outer face to the right side of the body"},
    {"max_steer_angle", &VehicleInfo::max_steer_angle_rad, "rad", 0.01, 1.5, ""},
}};

struct PullOutRequest {
  std::string vehicle_id;
  std::uint64_t request_id{0};
  std::int64_t stamp_ns{0};  // [ns] since the epoch of the sender's clock
  Pose2 ego_pose;
  double ego_velocity_mps{0.0};
  Pose2 goal_pose;
  std::vector<Lane> lanes;                      // inline lanes, or ...
  std::vector<std::int64_t> route_lanelet_ids;  // ... route lanelets on the service's map, or ...
  std::vector<RouteSegment> route_segments;     // ... an Autoware route (LaneletRoute's segments) on it
  std::vector<Object> objects;
  std::optional<OccupancyGrid> occupancy_grid;
  PlannerOverrides overrides;
  double deadline_ms{0.0};  // [ms] planning budget; 0 = the service's default
  // The vehicle to plan for: a profile of the service's config (vehicle_profiles, e.g. "bus"), or
  // its own dimensions (`vehicle`), not both. Neither: the service's configured vehicle. Checked
  // like the config's vehicle (kVehicleFields); a problem names the field ("vehicle.wheel_base",
  // "vehicle_profile").
  std::string vehicle_profile;
  std::optional<VehicleInfo> vehicle;
};

// Whether the request names a route on the map (ids or segments).
inline bool has_route(const PullOutRequest& r) { return !r.route_lanelet_ids.empty() || !r.route_segments.empty(); }

struct PathPoint {
  Pose2 pose;
  double longitudinal_velocity_mps{0.0};  // signed: negative when reversing
  std::vector<std::int64_t> lane_ids;
};

struct PathWithLaneId {
  std::vector<PathPoint> points;
};

// The velocity and acceleration the vehicle should reach at the end of one partial path.
struct TerminalVelocityAccel {
  double velocity_mps{0.0};
  double accel_mps2{0.0};
};

enum class TurnSignal : std::uint8_t { kNone = 0, kLeft = 1, kRight = 2 };

// What came of one attempt, as a value (names: model/names.hpp). The values are those of the
// IDL's AttemptOutcome, in the same order.
enum class AttemptOutcome : std::uint8_t {
  kSuccess = 0,        // a usable path
  kCollision = 1,      // too close to (or touching) a static obstacle at this margin
  kLaneDeparture = 2,  // the footprint leaves the lanes
  kNoGeometry = 3,     // the planner's geometry has no solution (no two-arc path, road too short)
  kStartInvalid = 4,   // the start pose cannot be used (off the road, heading, occupied, boxed in)
  kGoalInvalid = 5,    // no usable end pose (occupied, none on the road ahead)
  kTimeout = 6,        // the planning deadline or the planner's own time budget ran out
  kCancelled = 7,      // the search was cancelled (newer request, shutdown)
  kNodeLimit = 8,      // the search's node budget ran out (hybrid A* max_nodes)
  kNoPath = 9,         // the search was complete and found nothing
};

// One row of the planner evaluation table: one attempt of one planner at one margin from one start
// candidate (planner kNone: a start candidate that was skipped), what came of it, and a detail for
// people (the object, "4/4 candidates", ...; may be empty).
struct PlannerAttempt {
  PlannerType planner{PlannerType::kNone};
  double margin_m{0.0};
  double backward_distance_m{0.0};
  AttemptOutcome outcome{AttemptOutcome::kNoPath};
  std::string detail;
};

struct PullOutPath {
  std::string vehicle_id;
  std::uint64_t request_id{0};
  std::int64_t stamp_ns{0};
  bool found{false};
  PlannerType planner_type{PlannerType::kNone};
  std::vector<PathWithLaneId> partial_paths;
  std::vector<TerminalVelocityAccel> pairs_terminal_velocity_and_accel;
  Pose2 start_pose;
  Pose2 end_pose;
  double shift_length_m{0.0};  // lateral offset of the start from the road centerline, left positive [m]
  TurnSignal turn_signal{TurnSignal::kNone};
  // found == false: why nothing was found. found == true: notes on how the published path ends
  // (e.g. "stops 2.00 m before object 7, 21.3 m beyond the end pose", or that it is clear).
  std::vector<std::string> reasons;
};

enum class ExecutionState : std::uint8_t {
  kIdle = 0,       // no request yet
  kPlanning = 1,   // request accepted, search running
  kRejected = 2,   // request invalid: see `error`
  kNoPath = 3,     // no path: a stop path was published, see `stop_reason`
  kExecuting = 4,  // approved and safe: the vehicle may drive the path (current_path_idx)
  kCompleted = 5,  // the vehicle passed the end pose of the last segment
  // A path was found (published with found = true) but the vehicle must stand still:
  kWaitingApproval = 6,  // until ExecutionProgress::approved is true
  kWaitingSafety = 7,    // until safe (see `stop_reason`): before departure, or after a stop was
                         // inserted into the published path because traffic became unsafe
};

// A found path exists for the request (waiting, executing or completed).
inline bool has_path(ExecutionState s) {
  return s == ExecutionState::kWaitingApproval || s == ExecutionState::kWaitingSafety ||
         s == ExecutionState::kExecuting || s == ExecutionState::kCompleted;
}

struct PullOutStatus {
  std::string vehicle_id;
  std::uint64_t request_id{0};
  std::int64_t stamp_ns{0};
  ExecutionState state{ExecutionState::kIdle};
  std::uint32_t current_path_idx{0};
  std::uint32_t segment_count{0};
  PlannerType planner_type{PlannerType::kNone};
  std::vector<PlannerAttempt> evaluation_table;
  std::string stop_reason;  // kNoPath, kWaitingApproval, kWaitingSafety: why the vehicle must stand
  // kRejected: the request's "<field>: <problem>" lines. In any state, on the status answering a
  // refused progress sample (out of limits): its "progress.<field>: <problem>" lines.
  std::string error;
  double planning_time_ms{0.0};
  // Dynamic safety of the path at the last progress sample.
  bool safe{true};
  std::int64_t unsafe_object_id{0};  // the object that made it unsafe (safe == false)
  bool departed{false};              // the vehicle has been released (kExecuting) on this path
  // The turn signal the vehicle shows for this path, and the time (progress-sample clock, ns) from
  // which it is on; departure waits prepare_time_before_start after it. 0 = not on yet.
  TurnSignal turn_signal{TurnSignal::kNone};
  std::int64_t turn_signal_start_ns{0};
  // A found path: how the published path ends, e.g. "stops 2.01 m before object 7, 20.9 m beyond
  // the end pose" (the path's velocity is 0 there), or where it ends when nothing is in the way.
  std::string path_end;
  // Vehicles that see each other: the vehicle (its id) whose executing path crosses this one, so
  // that this vehicle waits (kWaitingSafety before departure, a stop after); empty otherwise.
  std::string waiting_for_vehicle_id;
};

// A problem with a request: the field (e.g. "lanes[2].left_bound[5].x", "ego_pose.orientation")
// and what is wrong with it.
struct RequestIssue {
  std::string field;
  std::string problem;
};

struct ExecutionProgress {
  std::string vehicle_id;
  std::uint64_t request_id{0};
  std::int64_t stamp_ns{0};  // [ns] time of the odometry sample
  Pose2 pose;
  double velocity_mps{0.0};
  // The vehicle (its driver or its supervisor) approves departure on this path. Never the
  // default: a vehicle that does not say so explicitly waits in kWaitingApproval.
  bool approved{false};
};

}  // namespace pullout
