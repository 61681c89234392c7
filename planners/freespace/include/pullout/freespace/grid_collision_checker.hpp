// Exact collision test of the vehicle rectangle against the occupied cells of a Costmap.
//
// "Collision" means the closed footprint rectangle and some closed occupied cell square share a
// point (touching counts), or the footprint leaves the grid. The test is exact up to floating
// point. It narrows down where to look with the costmap's summed-area table: no occupied cell in
// the rectangle's axis-aligned bounding box means no collision; otherwise the rectangle is cut
// into a few pieces, and only the pieces whose bounding box holds an occupied cell are cut into
// the grid's row strips, each strip's exact column extent counted in the same table. A
// bound from the distance transform (the rectangle covered by a few discs) answers most queries
// of collides(pose, bound) without the exact test.
//
// Thread safety: const methods may be called concurrently. The checker keeps a reference to the
// costmap, which must outlive it.
#pragma once

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

  // True when the convex hull of the footprints at `a` and `b`, grown by `margin` [m] on every
  // side, touches an occupied cell or leaves the grid (exact, as collides()). A body point moving
  // on a circular arc (or a line) from its place at a to its place at b stays within the arc's
  // sagitta of its chord, and the chord lies in the hull: with margin >= the largest sagitta
  // (sweep_margin), a false answer proves the whole motion between a and b free.
  bool sweep_collides(const Pose2& a, const Pose2& b, double margin) const;
  // The same with the cos and sin of both headings given (callers that already have them).
  bool sweep_collides(const Pose2& a, double cos_a, double sin_a, const Pose2& b, double cos_b, double sin_b,
                      double margin) const;
  // The largest sagitta [m] of a footprint point's path while the vehicle turns by `turn` [rad]
  // on an arc of curvature `curvature` [1/m] (0 on a straight line).
  double sweep_margin(double curvature, double turn) const;

  // A lower bound [m] of the distance from the footprint at `pose` to the nearest occupied cell
  // (0 when it may touch one). Cheap: a few distance-transform lookups.
  double clearance_lower_bound(const Pose2& pose) const;

  const Footprint& footprint() const { return footprint_; }
  const Costmap& costmap() const { return costmap_; }

  // How far [m] any point of the footprint moves at most per metre of rear-axle travel on an arc
  // of curvature `curvature` [1/m] (the farthest corner's lever arm).
  double sweep_factor(double curvature) const;

 private:
  // The pose in the grid frame: the rear axle (cells) and the vehicle's +x axis (cells per metre).
  struct GridPose {
    double x, y, ux, uy;
  };
  GridPose grid_pose(const Pose2& pose, double c, double s) const;
  double clearance_bound(const GridPose& g) const;
  bool collides_exact(const GridPose& g) const;

  const Costmap& costmap_;
  Footprint footprint_;
  // The costmap's frame and size, kept here for the hot paths.
  double origin_x_{0.0};
  double origin_y_{0.0};
  double origin_cos_{1.0};
  double origin_sin_{0.0};
  double inv_resolution_{1.0};
  double grid_width_{0.0};
  double grid_height_{0.0};
  // Discs covering the rectangle: centres on the vehicle axis (base_link frame), first_x +
  // k * step for k < count, offset sideways by offset_y; one radius. bound_margin is what a disc
  // centre's cell distance loses (radius, the cell half-diagonal, float safety).
  int disc_count_{1};
  double disc_first_x_{0.0};
  double disc_step_{0.0};
  double disc_offset_y_{0.0};
  double disc_radius_{0.0};
  double bound_margin_{0.0};
  // The exact test splits the rectangle into pieces_x_ x pieces_y_ equal pieces (see
  // collides_exact).
  int pieces_x_{1};
  int pieces_y_{1};
  int sweep_pieces_{1};  // pieces along the body of sweep_collides
};

}  // namespace pullout
