// Vehicles that see each other: the other vehicles of the fleet as obstacles of one vehicle.
//
// The service knows the paths it handed out. A vehicle that departed on its path and has not
// completed it (approved, executing, or stopped on it for safety) is an ExecutingPath. For another
// vehicle it becomes a FleetObstacle: an ordinary Object (its own footprint at its last odometry
// pose, its speed, and one predicted path along its remaining segments, timed by the path's
// velocity profile) for planning and the safety monitor, plus the footprints swept along its
// remaining path for the departure check (first_fleet_conflict).
//
// The departure check is spatial on purpose: a vehicle may stop on its path at any time (a safety
// stop, its driver), so a time gap on the predicted motion is no guarantee; a vehicle whose path
// crosses the remaining path of one that drives waits until that one's progress has passed the
// crossing (its remaining path no longer reaches ours) or it has completed.
//
// Precedence, so that two vehicles never wait for each other: a vehicle yields to every vehicle
// that departed before it (their remaining paths count); of a vehicle that departed after it only
// the body counts. A vehicle that has not departed yields to every executing vehicle.
//
// No DDS, no clock: the registry keeps a FleetBoard under its own lock and hands each session the
// obstacles for its vehicle with every odometry sample.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

// One vehicle driving its path, as its session knows it.
struct ExecutingPath {
  std::string vehicle_id;
  VehicleInfo vehicle;
  PullOutPath path;  // as planned (the one it resumes after a safety stop)
  std::uint32_t current_path_idx{0};
  Pose2 pose;  // last accepted odometry (the path's start before the first sample)
  double velocity_mps{0.0};
};

struct FleetObstacle {
  std::string vehicle_id;
  // Its body at its pose (polygon: the vehicle's footprint in its base_link frame), |velocity|, and
  // one predicted path (base_link poses) along the remaining segments every kFleetTimeStep.
  Object object;
  // Its footprint at every remaining path point from its pose on; empty when only its body counts.
  std::vector<Polygon> swept;
};

// [s] Time step of a fleet obstacle's predicted path.
inline constexpr double kFleetTimeStep = 0.5;
// [m/s] Slowest speed assumed on a path stretch when timing it (where the profile says 0, at the
// direction changes and the start, the vehicle still gets through in finite time).
inline constexpr double kFleetMinTimingSpeed = 0.5;
// Longest predicted path of a fleet obstacle [samples] (bounded work whatever the path's length).
inline constexpr std::size_t kFleetMaxPredictedSamples = 240;

// The index of the path point nearest to `pose` within segment `segment_idx` (clamped).
std::size_t nearest_point(const PullOutPath& path, std::uint32_t segment_idx, const Pose2& pose);

// `other` as an obstacle with id `object_id`; `with_path`: its remaining path counts (swept and
// predicted), else its body only (no predicted path beyond its pose).
FleetObstacle fleet_obstacle(const ExecutingPath& other, bool with_path, std::int64_t object_id);

struct FleetConflict {
  std::string vehicle_id;
  std::int64_t object_id{0};
};

// The first obstacle whose body or swept footprints the ego's footprint, pushed out by
// `clearance` [m] on each side and swept along its own remaining path (from segment `segment_idx`
// at the point nearest `ego`), overlaps. nullopt: clear.
std::optional<FleetConflict> first_fleet_conflict(const PullOutPath& path, std::uint32_t segment_idx, const Pose2& ego,
                                                  const VehicleInfo& vehicle, double clearance,
                                                  const std::vector<FleetObstacle>& fleet);

// The executing vehicles, in departure order. Not thread-safe (the registry guards it).
class FleetBoard {
 public:
  // A vehicle that drives (departed, not completed): added (departing now, after every vehicle
  // on the board) or updated (its order kept).
  void update(ExecutingPath entry);
  // The vehicle no longer drives a path (completed, re-planned, evicted). Unknown ids are ignored.
  void remove(const std::string& vehicle_id);

  // The obstacles for `vehicle_id` standing at `ego`: every other vehicle on the board whose
  // remaining path comes within `radius` [m] of `ego`; its remaining path counts when it departed
  // before `vehicle_id` (or `vehicle_id` is not on the board), else its body only. Object ids are
  // -1, -2, ... in board order (negative, apart from the ids vehicles give their objects).
  std::vector<FleetObstacle> obstacles_for(const std::string& vehicle_id, const Pose2& ego, double radius) const;

  std::size_t size() const { return entries_.size(); }
  bool holds(const std::string& vehicle_id) const { return entries_.count(vehicle_id) != 0; }

 private:
  struct Entry {
    ExecutingPath path;
    std::uint64_t order{0};
    Aabb bounds;  // of the remaining path and the pose, pushed out by the footprint's bounding radius
  };
  std::map<std::string, Entry> entries_;
  std::uint64_t next_order_{1};
};

}  // namespace pullout
