// Exact collision test of the vehicle rectangle against the occupied cells of a Costmap.
//
// "Collision" means the closed footprint rectangle and some closed occupied cell square share a
// point (touching counts), or the footprint leaves the grid. The test is exact up to floating
// point: the rectangle is cut into the grid's row strips, each strip's exact column extent is
// looked up in the costmap's row prefix sums (one lookup per row). A bound from the distance
// transform (the rectangle covered by a few discs) answers most queries without that walk.
//
// Thread safety: const methods may be called concurrently. The checker keeps a reference to the
// costmap, which must outlive it.
#pragma once

#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/freespace/costmap.hpp"

namespace pullout {

class GridCollisionChecker {
 public:
  GridCollisionChecker(const Costmap& costmap, const Footprint& footprint);

  // True when the footprint at X_MV = pose touches an occupied cell or leaves the grid.
  bool collides(const Pose2& pose) const;
  // The same, also giving clearance_lower_bound(pose) (0 when the exact test had to run).
  bool collides(const Pose2& pose, double& clearance_bound) const;
  // The same with cos(pose.yaw) and sin(pose.yaw) given (callers that already have them).
  bool collides(const Pose2& pose, double cos_yaw, double sin_yaw, double& clearance_bound) const;

  // A lower bound [m] of the distance from the footprint at `pose` to the nearest occupied cell
  // (0 when it may touch one). Cheap: a few distance-transform lookups.
  double clearance_lower_bound(const Pose2& pose) const;

  const Footprint& footprint() const { return footprint_; }
  const Costmap& costmap() const { return costmap_; }

  // How far [m] any point of the footprint moves at most per metre of rear-axle travel on an arc
  // of curvature `curvature` [1/m] (the farthest corner's lever arm).
  double sweep_factor(double curvature) const;

 private:
  double clearance_bound(const Pose2& pose, double c, double s) const;
  bool collides_exact(const Pose2& pose, double c, double s) const;

  const Costmap& costmap_;
  Footprint footprint_;
  // Discs covering the rectangle: centres on the vehicle axis (base_link frame) and one radius.
  std::vector<double> disc_x_;
  double disc_offset_y_{0.0};
  double disc_radius_{0.0};
};

}  // namespace pullout
