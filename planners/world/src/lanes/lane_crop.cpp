#include "pullout/lanes/lane_crop.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "pullout/geometry/polyline.hpp"

namespace pullout {

namespace {

// Bisection depth cap: 2^-64 of the lane is below any double's resolution of t anyway.
constexpr int kMaxDepth = 64;

// A bound with its cumulative arc length, evaluated by normalised arc length t in [0, 1].
class Bound {
 public:
  explicit Bound(const std::vector<Point2>& points) : points_(points), s_(points.size(), 0.0) {
    for (std::size_t i = 1; i < points_.size(); ++i) {
      s_[i] = s_[i - 1] + std::hypot(points_[i].x - points_[i - 1].x, points_[i].y - points_[i - 1].y);
    }
  }
  double length() const { return s_.empty() ? 0.0 : s_.back(); }
  std::size_t size() const { return points_.size(); }
  double t(std::size_t i) const { return length() > 0.0 ? s_[i] / length() : 0.0; }

  Vec2 at(double t) const {
    if (t <= 0.0 || length() <= 0.0) return to_vec(points_.front());
    if (t >= 1.0) return to_vec(points_.back());
    const double s = t * length();
    const std::size_t i = static_cast<std::size_t>(std::upper_bound(s_.begin(), s_.end(), s) - s_.begin()) - 1;
    const double seg = s_[i + 1] - s_[i];
    const double u = seg > 0.0 ? (s - s_[i]) / seg : 0.0;
    return to_vec(points_[i]) + u * (to_vec(points_[i + 1]) - to_vec(points_[i]));
  }

  // The bound between t0 and t1: the points there, every vertex strictly between kept.
  std::vector<Point2> between(double t0, double t1) const {
    std::vector<Point2> out;
    out.push_back(t0 <= 0.0 ? points_.front() : to_point(at(t0)));
    for (std::size_t i = 0; i < points_.size(); ++i) {
      if (t(i) > t0 && t(i) < t1) out.push_back(points_[i]);
    }
    out.push_back(t1 >= 1.0 ? points_.back() : to_point(at(t1)));
    return out;
  }

 private:
  const std::vector<Point2>& points_;
  std::vector<double> s_;
};

// The cross-sections of a lane between t0 and t1 sweep a region inside the convex hull of the
// four end points (both bounds are straight between consecutive breakpoints), so the box of those
// four points is a conservative test of whether any of them meets the square.
class CrossSections {
 public:
  CrossSections(const Bound& left, const Bound& right, const Aabb& square)
      : left_(left), right_(right), square_(square) {}

  bool may_meet(double t0, double t1) const {
    Aabb box;
    for (const Vec2& p : {left_.at(t0), left_.at(t1), right_.at(t0), right_.at(t1)}) box.extend(p);
    return box.overlaps(square_);
  }
  // Longest distance a bound travels between t0 and t1 (both are straight there or shorter).
  double span(double t0, double t1) const {
    return std::max((left_.at(t1) - left_.at(t0)).norm(), (right_.at(t1) - right_.at(t0)).norm());
  }

  // The start of the first piece of [t0, t1] no longer than kCropResolutionM that may meet the
  // square (from_end: the end of the last one); nullopt when none does.
  std::optional<double> extreme(double t0, double t1, bool from_end, int depth = 0) const {
    if (!may_meet(t0, t1)) return std::nullopt;
    if (depth >= kMaxDepth || span(t0, t1) <= kCropResolutionM) return from_end ? t1 : t0;
    const double mid = 0.5 * (t0 + t1);
    if (from_end) {
      if (auto r = extreme(mid, t1, true, depth + 1)) return r;
      return extreme(t0, mid, true, depth + 1);
    }
    if (auto r = extreme(t0, mid, false, depth + 1)) return r;
    return extreme(mid, t1, false, depth + 1);
  }

 private:
  const Bound& left_;
  const Bound& right_;
  const Aabb& square_;
};

bool inside(const std::vector<Point2>& points, const Aabb& square) {
  return std::all_of(points.begin(), points.end(), [&](const Point2& p) { return square.contains(to_vec(p)); });
}

}  // namespace

Aabb horizon_square(double x, double y, double half_side) { return Aabb{Vec2{x, y}, Vec2{x, y}}.inflated(half_side); }

bool object_near(const Object& object, const Aabb& square) {
  double radius = 0.5 * std::hypot(object.length_m, object.width_m);
  if (!object.polygon.empty()) {
    radius = 0.0;
    for (const Point2& p : object.polygon) radius = std::max(radius, std::hypot(p.x, p.y));
  }
  if (!std::isfinite(radius)) return true;  // keep what cannot be placed: validation rejects it
  return Aabb{to_vec(object.pose), to_vec(object.pose)}.inflated(radius).overlaps(square);
}

CroppedLanes crop_lanes(const std::vector<Lane>& lanes, const Aabb& square) {
  CroppedLanes out;
  for (std::size_t k = 0; k < lanes.size(); ++k) {
    const Lane& lane = lanes[k];
    if (inside(lane.left_bound, square) && inside(lane.right_bound, square) && inside(lane.centerline, square)) {
      out.lanes.push_back(lane);
      out.source.push_back(k);
      continue;
    }
    if (lane.left_bound.size() < 2 || lane.right_bound.size() < 2) {
      ++out.dropped;
      continue;
    }
    const Bound left(lane.left_bound);
    const Bound right(lane.right_bound);
    // Breakpoints: where either bound has a vertex; both bounds are straight in between.
    std::vector<double> ts;
    ts.reserve(left.size() + right.size());
    for (std::size_t i = 0; i < left.size(); ++i) ts.push_back(left.t(i));
    for (std::size_t i = 0; i < right.size(); ++i) ts.push_back(right.t(i));
    std::sort(ts.begin(), ts.end());
    ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
    const CrossSections sections(left, right, square);
    std::optional<double> first;
    for (std::size_t i = 0; i + 1 < ts.size() && !first; ++i) first = sections.extreme(ts[i], ts[i + 1], false);
    std::optional<double> last;
    for (std::size_t i = ts.size() - 1; i > 0 && !last; --i) last = sections.extreme(ts[i - 1], ts[i], true);
    if (!first || !last || !(*last > *first)) {
      ++out.dropped;
      continue;
    }
    Lane cut = lane;
    cut.left_bound = left.between(*first, *last);
    cut.right_bound = right.between(*first, *last);
    if (lane.centerline.size() >= 2) cut.centerline = Bound(lane.centerline).between(*first, *last);
    out.lanes.push_back(std::move(cut));
    out.source.push_back(k);
    ++out.cropped;
  }
  return out;
}

}  // namespace pullout
