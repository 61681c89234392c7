// Model <-> DDS message conversion (see convert.hpp for the contract).
//
// from_msg for the two inbound topics (requests, progress) is the first line of defence against
// malformed input: anything a sender can put on the wire that the model cannot represent (a
// non-finite number, a non-unit quaternion, an enumerator outside the IDL's range) becomes a
// RequestIssue naming the field. Semantic checks (lane geometry, sizes against the service's
// limits, ...) belong to the core's validation.
#include "pullout/idl/convert.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

namespace pullout::idl {
namespace {

// A malformed request (say 10,000 NaN points) would otherwise produce an issue list as large as
// the request itself; the first few name the problem well enough.
constexpr std::size_t kMaxIssues = 32;
constexpr double kUnitQuaternionTolerance = 1e-3;

// Appends issues up to kMaxIssues, then counts the rest and summarises them once in finish().
class IssueSink {
 public:
  explicit IssueSink(std::vector<RequestIssue>& issues) : issues_(issues), start_(issues.size()) {}
  IssueSink(const IssueSink&) = delete;
  IssueSink& operator=(const IssueSink&) = delete;
  ~IssueSink() {
    if (dropped_ > 0) {
      issues_.push_back({"request", std::to_string(dropped_) + " more problems not listed"});
    }
  }

  void add(std::string field, std::string problem) {
    if (issues_.size() - start_ < kMaxIssues) {
      issues_.push_back({std::move(field), std::move(problem)});
    } else {
      ++dropped_;
    }
  }

 private:
  std::vector<RequestIssue>& issues_;
  std::size_t start_;
  std::size_t dropped_{0};
};

std::string number_text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string indexed(const std::string& base, std::size_t i) { return base + "[" + std::to_string(i) + "]"; }

// ---- enumerations: the model's enumerators share the IDL's order and values ----

template <typename ModelEnum, typename MsgEnum>
MsgEnum enum_to_msg(ModelEnum v) {
  return static_cast<MsgEnum>(static_cast<std::uint32_t>(v));
}

// The value when it is one of the IDL's enumerators (0..last), else nullopt.
template <typename ModelEnum, typename MsgEnum>
std::optional<ModelEnum> enum_from_msg(MsgEnum v, MsgEnum last) {
  const auto raw = static_cast<std::uint32_t>(v);
  if (raw > static_cast<std::uint32_t>(last)) return std::nullopt;
  return static_cast<ModelEnum>(raw);
}

// The last enumerators agree (the order is the model's comment's promise; a new outcome must be
// added to both).
static_assert(static_cast<std::uint32_t>(msg::OUTCOME_NO_PATH) == static_cast<std::uint32_t>(AttemptOutcome::kNoPath));

template <typename ModelEnum, typename MsgEnum>
ModelEnum checked_enum(MsgEnum v, MsgEnum last, ModelEnum fallback, const std::string& field, IssueSink& sink) {
  if (auto e = enum_from_msg<ModelEnum>(v, last)) return *e;
  sink.add(field, "unknown enumerator " + std::to_string(static_cast<std::uint32_t>(v)));
  return fallback;
}

// ---- geometry ----

msg::Point point_to_msg(const Point2& p) {
  msg::Point out;
  out.x(p.x);
  out.y(p.y);
  out.z(0.0);
  return out;
}

msg::Pose pose_to_msg(const Pose2& p) {
  msg::Pose out;
  out.position().x(p.x);
  out.position().y(p.y);
  out.position().z(0.0);
  // Rotation about +z by yaw: (x, y, z, w) = (0, 0, sin(yaw/2), cos(yaw/2)).
  out.orientation().x(0.0);
  out.orientation().y(0.0);
  out.orientation().z(std::sin(p.yaw / 2.0));
  out.orientation().w(std::cos(p.yaw / 2.0));
  return out;
}

// Yaw of the normalised quaternion; 0 for the zero (or non-finite) quaternion, which the checked
// variant reports as an issue.
double yaw_of(const msg::Quaternion& q) {
  const double norm = std::sqrt(q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w());
  if (!(norm > 0.0) || !std::isfinite(norm)) return 0.0;
  const double x = q.x() / norm;
  const double y = q.y() / norm;
  const double z = q.z() / norm;
  const double w = q.w() / norm;
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

Point2 point_from_msg(const msg::Point& p) { return {p.x(), p.y()}; }

Pose2 pose_from_msg(const msg::Pose& p) { return {p.position().x(), p.position().y(), yaw_of(p.orientation())}; }

Point2 checked_point(const msg::Point& p, const std::string& field, IssueSink& sink) {
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
    sink.add(field, "non-finite coordinate (x " + number_text(p.x()) + ", y " + number_text(p.y()) + ", z " +
                        number_text(p.z()) + ")");
  }
  return point_from_msg(p);
}

Pose2 checked_pose(const msg::Pose& p, const std::string& field, IssueSink& sink) {
  checked_point(p.position(), field + ".position", sink);
  const msg::Quaternion& q = p.orientation();
  if (!std::isfinite(q.x()) || !std::isfinite(q.y()) || !std::isfinite(q.z()) || !std::isfinite(q.w())) {
    sink.add(field + ".orientation", "non-finite component");
  } else {
    const double norm = std::sqrt(q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w());
    if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
      sink.add(field + ".orientation", "not a unit quaternion (norm " + number_text(norm) + ")");
    }
  }
  return pose_from_msg(p);
}

double checked_number(double v, const std::string& field, IssueSink& sink) {
  if (!std::isfinite(v)) sink.add(field, "non-finite value " + number_text(v));
  return v;
}

std::vector<msg::Point> points_to_msg(const std::vector<Point2>& points) {
  std::vector<msg::Point> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(point_to_msg(p));
  return out;
}

std::vector<Point2> checked_points(const std::vector<msg::Point>& points, const std::string& field, IssueSink& sink) {
  std::vector<Point2> out;
  out.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out.push_back(checked_point(points[i], indexed(field, i), sink));
  return out;
}

// ---- request parts ----

msg::Lane lane_to_msg(const Lane& in) {
  msg::Lane out;
  out.id(in.id);
  out.subtype(enum_to_msg<LaneSubtype, msg::LaneSubtype>(in.subtype));
  out.left_bound(points_to_msg(in.left_bound));
  out.right_bound(points_to_msg(in.right_bound));
  out.centerline(points_to_msg(in.centerline));
  out.speed_limit_mps(in.speed_limit_mps);
  return out;
}

Lane checked_lane(const msg::Lane& in, const std::string& field, IssueSink& sink) {
  Lane out;
  out.id = in.id();
  out.subtype = checked_enum(in.subtype(), msg::LANE_ROAD_SHOULDER, LaneSubtype::kRoad, field + ".subtype", sink);
  out.left_bound = checked_points(in.left_bound(), field + ".left_bound", sink);
  out.right_bound = checked_points(in.right_bound(), field + ".right_bound", sink);
  out.centerline = checked_points(in.centerline(), field + ".centerline", sink);
  out.speed_limit_mps = checked_number(in.speed_limit_mps(), field + ".speed_limit_mps", sink);
  return out;
}

msg::DetectedObject object_to_msg(const Object& in) {
  msg::DetectedObject out;
  out.id(in.id);
  out.classification(enum_to_msg<ObjectClass, msg::ObjectClass>(in.object_class));
  out.pose(pose_to_msg(in.pose));
  out.length_m(in.length_m);
  out.width_m(in.width_m);
  out.polygon(points_to_msg(in.polygon));
  out.velocity_mps(in.velocity_mps);
  for (const auto& path : in.predicted_paths) {
    msg::PredictedPath p;
    p.path().reserve(path.poses.size());
    for (const auto& pose : path.poses) p.path().push_back(pose_to_msg(pose));
    p.time_step_s(path.time_step_s);
    p.confidence(path.confidence);
    out.predicted_paths().push_back(std::move(p));
  }
  return out;
}

Object checked_object(const msg::DetectedObject& in, const std::string& field, IssueSink& sink) {
  Object out;
  out.id = in.id();
  out.object_class =
      checked_enum(in.classification(), msg::CLASS_PEDESTRIAN, ObjectClass::kUnknown, field + ".classification", sink);
  out.pose = checked_pose(in.pose(), field + ".pose", sink);
  out.length_m = checked_number(in.length_m(), field + ".length_m", sink);
  out.width_m = checked_number(in.width_m(), field + ".width_m", sink);
  out.polygon = checked_points(in.polygon(), field + ".polygon", sink);
  out.velocity_mps = checked_number(in.velocity_mps(), field + ".velocity_mps", sink);
  out.predicted_paths.reserve(in.predicted_paths().size());
  for (std::size_t k = 0; k < in.predicted_paths().size(); ++k) {
    const msg::PredictedPath& path = in.predicted_paths()[k];
    const std::string path_field = indexed(field + ".predicted_paths", k);
    PredictedPath p;
    p.poses.reserve(path.path().size());
    for (std::size_t m = 0; m < path.path().size(); ++m) {
      p.poses.push_back(checked_pose(path.path()[m], indexed(path_field + ".path", m), sink));
    }
    p.time_step_s = checked_number(path.time_step_s(), path_field + ".time_step_s", sink);
    p.confidence = checked_number(path.confidence(), path_field + ".confidence", sink);
    out.predicted_paths.push_back(std::move(p));
  }
  return out;
}

msg::OccupancyGrid grid_to_msg(const std::optional<OccupancyGrid>& in) {
  msg::OccupancyGrid out;
  out.origin(pose_to_msg(Pose2{}));
  if (!in) {
    out.resolution_m(0.0);  // the IDL's "no grid"
    return out;
  }
  out.resolution_m(in->resolution_m);
  out.origin(pose_to_msg(in->origin));
  out.width(in->width);
  out.height(in->height);
  out.data().assign(in->data.begin(), in->data.end());
  return out;
}

std::optional<OccupancyGrid> checked_grid(const msg::OccupancyGrid& in, IssueSink& sink) {
  const std::string field = "occupancy_grid";
  if (in.resolution_m() == 0.0) return std::nullopt;
  OccupancyGrid out;
  out.resolution_m = checked_number(in.resolution_m(), field + ".resolution_m", sink);
  if (std::isfinite(in.resolution_m()) && in.resolution_m() < 0.0) {
    sink.add(field + ".resolution_m", "must be > 0 (0 = no grid), got " + number_text(in.resolution_m()));
  }
  out.origin = checked_pose(in.origin(), field + ".origin", sink);
  out.width = in.width();
  out.height = in.height();
  const std::uint64_t cells = static_cast<std::uint64_t>(in.width()) * in.height();
  if (in.data().size() != cells) {
    sink.add(field + ".data",
             std::to_string(in.data().size()) + " cells, expected width x height = " + std::to_string(cells));
  }
  out.data.assign(in.data().begin(), in.data().end());
  return out;
}

// A route primitive is a lanelet: Autoware names its type "lane"; empty is taken as a lanelet too.
std::int64_t checked_primitive(const msg::LaneletPrimitive& in, const std::string& field, IssueSink& sink) {
  const std::string& type = in.primitive_type();
  if (!type.empty() && type != "lane") {
    constexpr std::size_t kShown = 32;
    sink.add(field + ".primitive_type", "\"" + type.substr(0, kShown) + (type.size() > kShown ? "..." : "") +
                                            "\" is not a lanelet: expected \"lane\" (or empty)");
  }
  return in.id();
}

RouteSegment checked_segment(const msg::LaneletSegment& in, const std::string& field, IssueSink& sink) {
  RouteSegment out;
  out.preferred_id = checked_primitive(in.preferred_primitive(), field + ".preferred_primitive", sink);
  out.primitive_ids.reserve(in.primitives().size());
  for (std::size_t j = 0; j < in.primitives().size(); ++j) {
    out.primitive_ids.push_back(checked_primitive(in.primitives()[j], indexed(field + ".primitives", j), sink));
  }
  return out;
}

void check_vehicle_id(const std::string& id, IssueSink& sink) {
  if (id.empty()) sink.add("vehicle_id", "must not be empty");
  if (id.size() > kMaxVehicleIdBytes) {
    sink.add("vehicle_id", "longer than " + std::to_string(kMaxVehicleIdBytes) + " bytes");
  }
}

// Unchecked conversions for the outbound topics (the service produced them; the client only
// displays or follows them): an unknown enumerator maps to the neutral value.
template <typename ModelEnum, typename MsgEnum>
ModelEnum lenient_enum(MsgEnum v, MsgEnum last, ModelEnum fallback) {
  return enum_from_msg<ModelEnum>(v, last).value_or(fallback);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// time

msg::Time to_msg_time(std::int64_t stamp_ns) {
  constexpr std::int64_t kNsPerSec = 1'000'000'000;
  // Floor division, so that nanosec stays in [0, 1e9) for stamps before the epoch too.
  std::int64_t sec = stamp_ns / kNsPerSec;
  std::int64_t nsec = stamp_ns % kNsPerSec;
  if (nsec < 0) {
    nsec += kNsPerSec;
    --sec;
  }
  msg::Time out;
  // msg::Time holds a 32-bit second count; stamps outside its range saturate.
  constexpr std::int64_t kMaxSec = std::numeric_limits<std::int32_t>::max();
  constexpr std::int64_t kMinSec = std::numeric_limits<std::int32_t>::min();
  if (sec > kMaxSec) {
    out.sec(static_cast<std::int32_t>(kMaxSec));
    out.nanosec(static_cast<std::uint32_t>(kNsPerSec - 1));
  } else if (sec < kMinSec) {
    out.sec(static_cast<std::int32_t>(kMinSec));
    out.nanosec(0);
  } else {
    out.sec(static_cast<std::int32_t>(sec));
    out.nanosec(static_cast<std::uint32_t>(nsec));
  }
  return out;
}

std::int64_t from_msg_time(const msg::Time& t) {
  // Cannot overflow: |sec| < 2^31 and nanosec < 2^32.
  return static_cast<std::int64_t>(t.sec()) * 1'000'000'000 + static_cast<std::int64_t>(t.nanosec());
}

// ---------------------------------------------------------------------------------------------
// PullOutRequest

msg::PullOutRequest to_msg(const PullOutRequest& in) {
  msg::PullOutRequest out;
  out.vehicle_id(in.vehicle_id);
  out.request_id(in.request_id);
  out.stamp(to_msg_time(in.stamp_ns));
  out.ego_pose(pose_to_msg(in.ego_pose));
  out.ego_velocity_mps(in.ego_velocity_mps);
  out.goal_pose(pose_to_msg(in.goal_pose));
  out.lanes().reserve(in.lanes.size());
  for (const auto& lane : in.lanes) out.lanes().push_back(lane_to_msg(lane));
  out.route_lanelet_ids(in.route_lanelet_ids);
  out.route_segments().reserve(in.route_segments.size());
  for (const auto& segment : in.route_segments) {
    msg::LaneletSegment m;
    m.preferred_primitive().id(segment.preferred_id);
    m.preferred_primitive().primitive_type("lane");
    for (const std::int64_t id : segment.primitive_ids) {
      msg::LaneletPrimitive p;
      p.id(id);
      p.primitive_type("lane");
      m.primitives().push_back(std::move(p));
    }
    out.route_segments().push_back(std::move(m));
  }
  out.objects().reserve(in.objects.size());
  for (const auto& object : in.objects) out.objects().push_back(object_to_msg(object));
  out.occupancy_grid(grid_to_msg(in.occupancy_grid));
  for (const auto planner : in.overrides.search_priority) {
    out.overrides().search_priority().push_back(static_cast<std::uint32_t>(planner));
  }
  if (!in.overrides.search_policy) {
    out.overrides().search_policy(msg::POLICY_DEFAULT);
  } else if (*in.overrides.search_policy == SearchPolicy::kPlannerPriority) {
    out.overrides().search_policy(msg::POLICY_PLANNER_PRIORITY);
  } else {
    out.overrides().search_policy(msg::POLICY_DISTANCE_PRIORITY);
  }
  out.deadline_ms(in.deadline_ms);
  out.vehicle_profile(in.vehicle_profile);
  if (in.vehicle) {
    msg::VehicleDimensions v;
    v.wheel_base(in.vehicle->wheel_base_m);
    v.wheel_tread(in.vehicle->wheel_tread_m);
    v.front_overhang(in.vehicle->front_overhang_m);
    v.rear_overhang(in.vehicle->rear_overhang_m);
    v.left_overhang(in.vehicle->left_overhang_m);
    v.right_overhang(in.vehicle->right_overhang_m);
    v.max_steer_angle(in.vehicle->max_steer_angle_rad);
    out.vehicle().push_back(v);
  }
  return out;
}

PullOutRequest from_msg(const msg::PullOutRequest& in, std::vector<RequestIssue>& issues) {
  IssueSink sink(issues);
  PullOutRequest out;
  check_vehicle_id(in.vehicle_id(), sink);
  out.vehicle_id = in.vehicle_id();
  out.request_id = in.request_id();
  out.stamp_ns = from_msg_time(in.stamp());
  out.ego_pose = checked_pose(in.ego_pose(), "ego_pose", sink);
  out.ego_velocity_mps = checked_number(in.ego_velocity_mps(), "ego_velocity_mps", sink);
  out.goal_pose = checked_pose(in.goal_pose(), "goal_pose", sink);
  out.lanes.reserve(in.lanes().size());
  for (std::size_t i = 0; i < in.lanes().size(); ++i) {
    out.lanes.push_back(checked_lane(in.lanes()[i], indexed("lanes", i), sink));
  }
  out.route_lanelet_ids = in.route_lanelet_ids();
  out.route_segments.reserve(in.route_segments().size());
  for (std::size_t i = 0; i < in.route_segments().size(); ++i) {
    out.route_segments.push_back(checked_segment(in.route_segments()[i], indexed("route_segments", i), sink));
  }
  out.objects.reserve(in.objects().size());
  for (std::size_t i = 0; i < in.objects().size(); ++i) {
    out.objects.push_back(checked_object(in.objects()[i], indexed("objects", i), sink));
  }
  out.occupancy_grid = checked_grid(in.occupancy_grid(), sink);
  const auto& priority = in.overrides().search_priority();
  out.overrides.search_priority.reserve(priority.size());
  for (std::size_t i = 0; i < priority.size(); ++i) {
    out.overrides.search_priority.push_back(checked_enum(static_cast<msg::PlannerType>(priority[i]),
                                                         msg::PLANNER_FREESPACE, PlannerType::kNone,
                                                         indexed("overrides.search_priority", i), sink));
  }
  switch (in.overrides().search_policy()) {
    case msg::POLICY_DEFAULT:
      break;
    case msg::POLICY_PLANNER_PRIORITY:
      out.overrides.search_policy = SearchPolicy::kPlannerPriority;
      break;
    case msg::POLICY_DISTANCE_PRIORITY:
      out.overrides.search_policy = SearchPolicy::kDistancePriority;
      break;
    default:
      sink.add("overrides.search_policy",
               "unknown enumerator " + std::to_string(static_cast<std::uint32_t>(in.overrides().search_policy())));
  }
  out.deadline_ms = checked_number(in.deadline_ms(), "deadline_ms", sink);
  if (std::isfinite(in.deadline_ms()) && in.deadline_ms() < 0.0) {
    sink.add("deadline_ms", "must be >= 0 (0 = the service's default), got " + number_text(in.deadline_ms()));
  }
  out.vehicle_profile = in.vehicle_profile();
  if (in.vehicle().size() > 1) {
    sink.add("vehicle", "at most one vehicle, got " + std::to_string(in.vehicle().size()));
  } else if (in.vehicle().size() == 1) {
    // The ranges (and non-finite values) are checked by the planner's validation, field by field.
    const msg::VehicleDimensions& v = in.vehicle().front();
    VehicleInfo info;
    info.wheel_base_m = v.wheel_base();
    info.wheel_tread_m = v.wheel_tread();
    info.front_overhang_m = v.front_overhang();
    info.rear_overhang_m = v.rear_overhang();
    info.left_overhang_m = v.left_overhang();
    info.right_overhang_m = v.right_overhang();
    info.max_steer_angle_rad = v.max_steer_angle();
    out.vehicle = info;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// PullOutPath

msg::PullOutPath to_msg(const PullOutPath& in) {
  msg::PullOutPath out;
  out.vehicle_id(in.vehicle_id);
  out.request_id(in.request_id);
  out.stamp(to_msg_time(in.stamp_ns));
  out.found(in.found);
  out.planner_type(enum_to_msg<PlannerType, msg::PlannerType>(in.planner_type));
  out.partial_paths().reserve(in.partial_paths.size());
  for (const auto& partial : in.partial_paths) {
    msg::PathWithLaneId path;
    path.points().reserve(partial.points.size());
    for (const auto& point : partial.points) {
      msg::PathPointWithLaneId p;
      p.pose(pose_to_msg(point.pose));
      p.longitudinal_velocity_mps(point.longitudinal_velocity_mps);
      p.lane_ids(point.lane_ids);
      path.points().push_back(std::move(p));
    }
    out.partial_paths().push_back(std::move(path));
  }
  out.pairs_terminal_velocity_and_accel().reserve(in.pairs_terminal_velocity_and_accel.size());
  for (const auto& pair : in.pairs_terminal_velocity_and_accel) {
    msg::TerminalVelocityAccel p;
    p.velocity_mps(pair.velocity_mps);
    p.accel_mps2(pair.accel_mps2);
    out.pairs_terminal_velocity_and_accel().push_back(p);
  }
  out.start_pose(pose_to_msg(in.start_pose));
  out.end_pose(pose_to_msg(in.end_pose));
  out.shift_length().start(0.0);
  out.shift_length().end(in.shift_length_m);
  out.turn_signal(enum_to_msg<TurnSignal, msg::TurnSignal>(in.turn_signal));
  out.reasons(in.reasons);
  return out;
}

PullOutPath from_msg(const msg::PullOutPath& in) {
  PullOutPath out;
  out.vehicle_id = in.vehicle_id();
  out.request_id = in.request_id();
  out.stamp_ns = from_msg_time(in.stamp());
  out.found = in.found();
  out.planner_type = lenient_enum(in.planner_type(), msg::PLANNER_FREESPACE, PlannerType::kNone);
  out.partial_paths.reserve(in.partial_paths().size());
  for (const auto& partial : in.partial_paths()) {
    PathWithLaneId path;
    path.points.reserve(partial.points().size());
    for (const auto& point : partial.points()) {
      PathPoint p;
      p.pose = pose_from_msg(point.pose());
      p.longitudinal_velocity_mps = point.longitudinal_velocity_mps();
      p.lane_ids = point.lane_ids();
      path.points.push_back(std::move(p));
    }
    out.partial_paths.push_back(std::move(path));
  }
  out.pairs_terminal_velocity_and_accel.reserve(in.pairs_terminal_velocity_and_accel().size());
  for (const auto& pair : in.pairs_terminal_velocity_and_accel()) {
    out.pairs_terminal_velocity_and_accel.push_back({pair.velocity_mps(), pair.accel_mps2()});
  }
  out.start_pose = pose_from_msg(in.start_pose());
  out.end_pose = pose_from_msg(in.end_pose());
  out.shift_length_m = in.shift_length().end() - in.shift_length().start();
  out.turn_signal = lenient_enum(in.turn_signal(), msg::TURN_SIGNAL_RIGHT, TurnSignal::kNone);
  out.reasons = in.reasons();
  return out;
}

// ---------------------------------------------------------------------------------------------
// PullOutStatus

msg::PullOutStatus to_msg(const PullOutStatus& in) {
  msg::PullOutStatus out;
  out.vehicle_id(in.vehicle_id);
  out.request_id(in.request_id);
  out.stamp(to_msg_time(in.stamp_ns));
  out.state(enum_to_msg<ExecutionState, msg::ExecutionState>(in.state));
  out.current_path_idx(in.current_path_idx);
  out.segment_count(in.segment_count);
  out.planner_type(enum_to_msg<PlannerType, msg::PlannerType>(in.planner_type));
  out.evaluation_table().reserve(in.evaluation_table.size());
  for (const auto& row : in.evaluation_table) {
    msg::PlannerAttempt a;
    a.planner(enum_to_msg<PlannerType, msg::PlannerType>(row.planner));
    a.margin_m(row.margin_m);
    a.backward_distance_m(row.backward_distance_m);
    a.outcome(enum_to_msg<AttemptOutcome, msg::AttemptOutcome>(row.outcome));
    a.detail(row.detail);
    out.evaluation_table().push_back(std::move(a));
  }
  out.stop_reason(in.stop_reason);
  out.error(in.error);
  out.planning_time_ms(in.planning_time_ms);
  out.safe(in.safe);
  out.unsafe_object_id(in.unsafe_object_id);
  out.departed(in.departed);
  out.turn_signal(enum_to_msg<TurnSignal, msg::TurnSignal>(in.turn_signal));
  out.turn_signal_start(to_msg_time(in.turn_signal_start_ns));
  out.path_end(in.path_end);
  out.waiting_for_vehicle_id(in.waiting_for_vehicle_id);
  return out;
}

PullOutStatus from_msg(const msg::PullOutStatus& in) {
  std::vector<RequestIssue> ignored;
  return from_msg(in, ignored);
}

PullOutStatus from_msg(const msg::PullOutStatus& in, std::vector<RequestIssue>& issues) {
  IssueSink sink(issues);
  PullOutStatus out;
  out.vehicle_id = in.vehicle_id();
  out.request_id = in.request_id();
  out.stamp_ns = from_msg_time(in.stamp());
  out.state = lenient_enum(in.state(), msg::STATE_WAITING_SAFETY, ExecutionState::kIdle);
  out.current_path_idx = in.current_path_idx();
  out.segment_count = in.segment_count();
  out.planner_type = lenient_enum(in.planner_type(), msg::PLANNER_FREESPACE, PlannerType::kNone);
  out.evaluation_table.reserve(in.evaluation_table().size());
  for (std::size_t i = 0; i < in.evaluation_table().size(); ++i) {
    const msg::PlannerAttempt& row = in.evaluation_table()[i];
    PlannerAttempt a;
    a.planner = lenient_enum(row.planner(), msg::PLANNER_FREESPACE, PlannerType::kNone);
    a.margin_m = row.margin_m();
    a.backward_distance_m = row.backward_distance_m();
    // An outcome this build does not know (a newer sender, a corrupt sample) is reported; the row
    // keeps the neutral kNoPath with the raw value in its detail.
    const std::string field = indexed("evaluation_table", i) + ".outcome";
    a.outcome = checked_enum(row.outcome(), msg::OUTCOME_NO_PATH, AttemptOutcome::kNoPath, field, sink);
    a.detail = row.detail();
    if (!enum_from_msg<AttemptOutcome>(row.outcome(), msg::OUTCOME_NO_PATH)) {
      const std::string raw = "unknown outcome " + std::to_string(static_cast<std::uint32_t>(row.outcome()));
      a.detail = a.detail.empty() ? raw : raw + ": " + a.detail;
    }
    out.evaluation_table.push_back(std::move(a));
  }
  out.stop_reason = in.stop_reason();
  out.error = in.error();
  out.planning_time_ms = in.planning_time_ms();
  out.safe = in.safe();
  out.unsafe_object_id = in.unsafe_object_id();
  out.departed = in.departed();
  out.turn_signal = lenient_enum(in.turn_signal(), msg::TURN_SIGNAL_RIGHT, TurnSignal::kNone);
  out.turn_signal_start_ns = from_msg_time(in.turn_signal_start());
  out.path_end = in.path_end();
  out.waiting_for_vehicle_id = in.waiting_for_vehicle_id();
  return out;
}

// ---------------------------------------------------------------------------------------------
// ExecutionProgress

msg::ExecutionProgress to_msg(const ExecutionProgress& in) {
  msg::ExecutionProgress out;
  out.vehicle_id(in.vehicle_id);
  out.request_id(in.request_id);
  out.stamp(to_msg_time(in.stamp_ns));
  out.pose(pose_to_msg(in.pose));
  out.velocity_mps(in.velocity_mps);
  out.approved(in.approved);
  return out;
}

ExecutionProgress from_msg(const msg::ExecutionProgress& in, std::vector<RequestIssue>& issues) {
  IssueSink sink(issues);
  ExecutionProgress out;
  check_vehicle_id(in.vehicle_id(), sink);
  out.vehicle_id = in.vehicle_id();
  out.request_id = in.request_id();
  out.stamp_ns = from_msg_time(in.stamp());
  out.pose = checked_pose(in.pose(), "pose", sink);
  out.velocity_mps = checked_number(in.velocity_mps(), "velocity_mps", sink);
  out.approved = in.approved();
  return out;
}

}  // namespace pullout::idl
