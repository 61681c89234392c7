// Static-object clearance of the vehicle footprint, with FCL (exact convex distance, GJK).
//
// The vehicle is a box (its Footprint) swept along poses; each obstacle is a convex prism built
// from its polygon. "Collision at margin m" means that the distance between the vehicle footprint
// and some obstacle is below m (touching or overlapping counts as distance 0). A cheap
// bounding-circle test skips the exact query for obstacles that are clearly far.
//
// Thread safety: const methods may be called concurrently (each call uses its own FCL objects).
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "pullout/collision/footprint.hpp"

namespace pullout {

struct Obstacle {
  std::int64_t id{0};
  // Map frame. A non-convex one is checked exactly (as convex pieces whose union it is), unless
  // its edges cross: then its convex hull, which covers every reading of it.
  Polygon polygon;
};

class ObjectChecker {
 public:
  ObjectChecker(const Footprint& vehicle, std::vector<Obstacle> obstacles);
  ~ObjectChecker();
  ObjectChecker(ObjectChecker&&) noexcept;
  ObjectChecker& operator=(ObjectChecker&&) noexcept;

  struct Clearance {
    double distance{std::numeric_limits<double>::infinity()};  // [m], 0 when overlapping
    std::int64_t obstacle_id{0};                               // the nearest one
  };
  // Smallest distance from the footprint at X_MV = `pose` to any obstacle, considering only
  // obstacles closer than `horizon` (others report +inf).
  Clearance clearance(const Pose2& pose, double horizon = std::numeric_limits<double>::infinity()) const;

  // The same, over the obstacles whose centre lies ahead of the vehicle's front (a car parked
  // beside the vehicle is not ahead of it).
  Clearance clearance_ahead(const Pose2& pose, double horizon = std::numeric_limits<double>::infinity()) const;

  // First pose whose clearance is below `margin`, with the obstacle it hits; nullopt if none.
  struct Hit {
    std::size_t pose_index{0};
    std::int64_t obstacle_id{0};
    double distance{0.0};
  };
  std::optional<Hit> first_hit(const std::vector<Pose2>& poses, double margin) const;

  const Footprint& footprint() const;

 private:
  template <typename Filter>
  Clearance clearance_if(const Pose2& pose, double horizon, Filter&& keep) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pullout
