// Geometry for the CLI's pictures (svg_writer.hpp): footprints in the map frame, an axis-aligned
// box, clipping to a box, and where a pull-out manoeuvre happens (what the main view frames).
//
// Frames: everything here is in the map frame of pullout/model/types.hpp (metres, y up).
#pragma once

#include <array>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout::cli {

// An axis-aligned box [min_x, max_x] x [min_y, max_y] [m]; empty until a finite point is added.
struct Box {
  double min_x;
  double min_y;
  double max_x;
  double max_y;

  Box();
  Box(double x0, double y0, double x1, double y1) : min_x(x0), min_y(y0), max_x(x1), max_y(y1) {}

  // Grows the box to hold p; non-finite points are skipped.
  void add(const Point2& p);
  template <typename Points>
  void add_all(const Points& points) {
    for (const auto& p : points) add(p);
  }
  void add_box(const Box& other);
  bool empty() const { return !(min_x <= max_x && min_y <= max_y); }
  double width() const { return max_x - min_x; }
  double height() const { return max_y - min_y; }
  // Grown by `margin` [m] on every side.
  Box inflated(double margin) const;
  // Grown about its centre to at least `min_width` x `min_height` [m].
  Box at_least(double min_width, double min_height) const;
  // The common part (empty when they do not meet).
  Box intersection(const Box& other) const;
  bool contains(const Point2& p) const { return p.x >= min_x && p.x <= max_x && p.y >= min_y && p.y <= max_y; }
  bool contains(const Box& other) const;
  bool meets(const Box& other) const;
};

template <typename Points>
Box box_of(const Points& points) {
  Box b;
  b.add_all(points);
  return b;
}

// Corners of the vehicle's footprint at `pose` (base_link = rear-axle centre), counter-clockwise
// from front-left: front-left, rear-left, rear-right, front-right. front = wheel_base +
// front_overhang, rear = rear_overhang, left = tread/2 + left_overhang, right = tread/2 +
// right_overhang.
std::array<Point2, 4> vehicle_footprint(const VehicleInfo& vehicle, const Pose2& pose);

// Footprint of an object in the map frame: its polygon when given, else its length x width box
// centred on its pose.
std::vector<Point2> object_footprint(const Object& object);

// The part of a polygon inside `box` (Sutherland-Hodgman): a polygon again (a concave polygon
// cut into pieces keeps them joined along the box edge), empty when nothing is inside.
// Non-finite points are dropped first.
std::vector<Point2> clip_polygon(const std::vector<Point2>& polygon, const Box& box);

// The parts of a polyline inside `box`, in order: one run per stretch inside, each with at least
// two points (a run that only touches the box in one point is dropped). Non-finite points split
// the polyline.
std::vector<std::vector<Point2>> clip_polyline(const std::vector<Point2>& polyline, const Box& box);

// The poses the vehicle drives through on the manoeuvre: every point of the partial paths, the
// last one only up to its point nearest to path.end_pose (the published path goes on along the
// lane beyond the end pose; that is not the manoeuvre). Non-finite poses are dropped.
std::vector<Pose2> manoeuvre_poses(const PullOutPath& path);

// What the main view of a picture frames: the union of the vehicle's footprints at the start,
// on every manoeuvre pose and at the end pose (the start alone when `path` is null or not found),
// grown by `margin` [m], then grown to hold every object footprint that meets that box and spans
// at most kWholeObjectMaxM a side (a car, a truck: drawn whole; a larger polygon is cut at the
// view's edge instead).
constexpr double kWholeObjectMaxM = 15.0;
Box manoeuvre_view(const PullOutRequest& request, const VehicleInfo& vehicle, const PullOutPath* path, double margin);

// True when the partial path is driven in reverse (most of its points have a negative velocity).
bool segment_is_reverse(const PathWithLaneId& segment);

}  // namespace pullout::cli
