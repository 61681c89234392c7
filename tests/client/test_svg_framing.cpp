// The CLI's SVG pictures framed on the manoeuvre: the main view holds the footprints from the
// start to the end pose within a margin (not the whole road), an inset draws the whole scene with
// the main view marked, segments are numbered at their start poses, a footprint at every cusp.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include "svg_test_support.hpp"
#include "svg_writer.hpp"

namespace pullout::cli {
namespace {

using namespace svg_testing;  // the picture-reading helpers (svg_test_support.hpp)

// Boxed in on a 150 m shoulder (cars 1.2 m ahead and behind): forward 0.6 m, reverse 1 m, then
// forward out onto the road, the end pose at x = 30 and the path on along the road to x = 150.
PullOutRequest long_road_scene() {
  PullOutRequest request;
  Lane road;
  road.id = 1;
  road.left_bound = {{0.0, 1.75}, {150.0, 1.75}};
  road.right_bound = {{0.0, -1.75}, {150.0, -1.75}};
  Lane shoulder;
  shoulder.id = 2;
  shoulder.subtype = LaneSubtype::kRoadShoulder;
  shoulder.left_bound = {{0.0, 4.75}, {150.0, 4.75}};
  shoulder.right_bound = {{0.0, 1.75}, {150.0, 1.75}};
  request.lanes = {road, shoulder};
  Object ahead;
  ahead.id = 7;
  ahead.pose = {17.24, 3.25, 0.0};
  Object behind = ahead;
  behind.id = 8;
  behind.pose = {5.45, 3.25, 0.0};
  Object far = ahead;  // 100 m on: only in the inset
  far.id = 9;
  far.pose = {110.0, 3.25, 0.0};
  request.objects = {ahead, behind, far};
  request.ego_pose = {10.0, 3.25, 0.0};
  request.goal_pose = {140.0, 0.0, 0.0};
  return request;
}

PullOutPath wiggle_out() {
  PullOutPath p;
  p.found = true;
  p.planner_type = PlannerType::kFreespace;
  PathWithLaneId f1;
  for (int i = 0; i <= 3; ++i) f1.points.push_back({{10.0 + 0.2 * i, 3.25, 0.0}, i == 3 ? 0.0 : 1.0, {}});
  PathWithLaneId r;
  for (int i = 0; i <= 5; ++i) r.points.push_back({{10.6 - 0.2 * i, 3.25, 0.0}, i == 5 ? 0.0 : -1.0, {}});
  PathWithLaneId f2;
  const double yaw = std::atan2(-3.25, 30.0 - 9.6);
  for (int i = 0; i <= 20; ++i) {
    f2.points.push_back({{9.6 + (30.0 - 9.6) * i / 20.0, 3.25 - 3.25 * i / 20.0, i == 20 ? 0.0 : yaw}, 2.0, {}});
  }
  for (int i = 1; i <= 120; ++i) f2.points.push_back({{30.0 + i, 0.0, 0.0}, i == 120 ? 0.0 : 2.0, {}});
  p.partial_paths = {f1, r, f2};
  p.pairs_terminal_velocity_and_accel = {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}};
  p.start_pose = {10.0, 3.25, 0.0};
  p.end_pose = {30.0, 0.0, 0.0};
  return p;
}

struct Rect {
  double x{0}, y{0}, w{0}, h{0};
  bool holds(const Point2& p, double tol = 0.011) const {
    return p.x >= x - tol && p.x <= x + w + tol && p.y >= y - tol && p.y <= y + h + tol;
  }
};

Rect rect_of(const tinyxml2::XMLElement* e) {
  return {e->DoubleAttribute("x"), e->DoubleAttribute("y"), e->DoubleAttribute("width"), e->DoubleAttribute("height")};
}

// World <-> picture of one view, found from two world points and where they were drawn.
struct Transform {
  double scale{1};  // [px/m]
  Point2 world0, px0;
  Point2 px(const Point2& w) const { return {px0.x + (w.x - world0.x) * scale, px0.y - (w.y - world0.y) * scale}; }
  Point2 world(const Point2& p) const { return {world0.x + (p.x - px0.x) / scale, world0.y - (p.y - px0.y) / scale}; }
};

Transform transform_from(const Point2& w0, const Point2& p0, const Point2& w1, const Point2& p1) {
  Transform t{(p1.x - p0.x) / (w1.x - w0.x), w0, p0};
  // Uniform scale, y up: the other axis agrees (2-decimal rounding of px).
  if (std::abs(w1.y - w0.y) > 1.0) {
    EXPECT_NEAR((p0.y - p1.y) / (w1.y - w0.y), t.scale, 0.01 * t.scale);
  }
  return t;
}

// The main view's transform: the heading ticks of the start and end footprints start at the
// base_link of the request's ego pose and of the path's end pose.
Transform main_transform(const Parsed& parsed, const Pose2& start, const Pose2& end) {
  const auto s = with_class(parsed, "footprint-start-heading");
  const auto e = with_class(parsed, "footprint-end-heading");
  EXPECT_EQ(s.size(), 1u);
  EXPECT_EQ(e.size(), 1u);
  if (s.empty() || e.empty()) return {};
  return transform_from({start.x, start.y}, points_of(s[0])[0], {end.x, end.y}, points_of(e[0])[0]);
}

std::vector<Point2> corners(const Rect& r) { return {{r.x, r.y}, {r.x + r.w, r.y + r.h}}; }

TEST(RenderSvg, ShortManoeuvreOnALongRoadIsFramedWithTheWholeSceneInAnInset) {
  const PullOutRequest request = long_road_scene();
  const PullOutPath p = wiggle_out();
  const VehicleInfo vehicle;
  Parsed parsed;
  parse(render_svg(request, vehicle, &p), parsed);
  const Transform main = main_transform(parsed, request.ego_pose, p.end_pose);
  ASSERT_GT(main.scale, 0.0);
  const auto frames = with_class(parsed, "frame");
  ASSERT_EQ(frames.size(), 1u);
  const Rect frame = rect_of(frames[0]);
  const Point2 view_min = main.world({frame.x, frame.y + frame.h});
  const Point2 view_max = main.world({frame.x + frame.w, frame.y});

  // The main view holds every footprint from the start to the end pose and the cars boxing the
  // vehicle in, within the margin; it is nowhere near the 150 m of the road.
  Box footprints;
  for (const Pose2& pose : manoeuvre_poses(p)) footprints.add_all(vehicle_footprint(vehicle, pose));
  footprints.add_all(object_footprint(request.objects[0]));
  footprints.add_all(object_footprint(request.objects[1]));
  const double tol = 0.05;  // [m] px rounding
  EXPECT_LE(view_min.x, footprints.min_x + tol);
  EXPECT_LE(view_min.y, footprints.min_y + tol);
  EXPECT_GE(view_max.x, footprints.max_x - tol);
  EXPECT_GE(view_max.y, footprints.max_y - tol);
  EXPECT_GE(view_min.x, footprints.min_x - kViewMarginM - tol);
  EXPECT_GE(view_min.y, footprints.min_y - kViewMarginM - tol);
  EXPECT_LE(view_max.x, footprints.max_x + kViewMarginM + tol);
  EXPECT_LE(view_max.y, footprints.max_y + kViewMarginM + tol);
  EXPECT_LT(view_max.x - view_min.x, 50.0);
  // The car 100 m on is not in the main view.
  std::vector<std::string> ids;
  for (const auto* o : with_class(parsed, "object")) ids.push_back(o->Attribute("data-id"));
  EXPECT_EQ(ids, (std::vector<std::string>{"7", "8"}));
  // Nothing is drawn beyond the main view but the inset (and the legend and scale bar, which
  // draw no polygons).
  for (const auto* e : parsed.elements) {
    const char* c = e->Attribute("class");
    if (e->Attribute("points") == nullptr || (c != nullptr && std::string(c).rfind("inset", 0) == 0)) continue;
    for (const auto& q : points_of(e)) EXPECT_TRUE(frame.holds(q)) << c << " " << q.x << "," << q.y;
  }

  // The lanes are cut at the view's left and right edges: filled there without an outline, their
  // outlines drawn along their own bounds only (a cut is not a lane edge).
  const auto roads = with_class(parsed, "lane-road");
  ASSERT_EQ(roads.size(), 1u);
  EXPECT_STREQ(roads[0]->Attribute("stroke"), "none");
  const auto outlines = with_class(parsed, "cut-outline");
  EXPECT_GE(outlines.size(), 2u);
  for (const auto* e : outlines) {
    const auto q = points_of(e);
    for (std::size_t k = 0; k + 1 < q.size(); ++k) {
      for (double edge : {frame.x, frame.x + frame.w}) {
        EXPECT_FALSE(std::abs(q[k].x - edge) < 0.02 && std::abs(q[k + 1].x - edge) < 0.02) << "along the cut";
      }
    }
  }

  // The inset: the whole scene inside its frame, the main view marked on it.
  const auto inset_frames = with_class(parsed, "inset-frame");
  ASSERT_EQ(inset_frames.size(), 1u);
  const Rect inset = rect_of(inset_frames[0]);
  for (const auto& q : corners(inset)) EXPECT_TRUE(frame.holds(q));
  const auto inset_lanes = with_class(parsed, "inset-lane");
  ASSERT_EQ(inset_lanes.size(), 2u);
  EXPECT_EQ(with_class(parsed, "inset-object").size(), 3u);
  const auto inset_segments = with_class(parsed, "inset-segment");
  ASSERT_EQ(inset_segments.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(points_of(inset_segments[i]).size(), p.partial_paths[i].points.size()) << "segment " << i;
  }
  for (const auto* e : parsed.elements) {
    if (e->Attribute("points") == nullptr) continue;
    const std::string c = e->Attribute("class");
    if (c.rfind("inset", 0) != 0) continue;
    for (const auto& q : points_of(e)) EXPECT_TRUE(inset.holds(q)) << c << " " << q.x << "," << q.y;
  }
  ASSERT_EQ(with_class(parsed, "inset-goal").size(), 1u);
  // The inset's transform from the road outline (left bound first: (0, 1.75), (150, 1.75), then
  // the right bound reversed: (150, -1.75)).
  const auto road = points_of(inset_lanes[0]);
  const Transform small = transform_from({0.0, 1.75}, road[0], {150.0, -1.75}, road[2]);
  const auto marks = with_class(parsed, "inset-view");
  ASSERT_EQ(marks.size(), 1u);
  const Rect mark = rect_of(marks[0]);
  for (const auto& q : corners(mark)) EXPECT_TRUE(inset.holds(q));
  const double small_tol = 0.02 / small.scale + 0.01;  // [m] px rounding at the inset's scale
  EXPECT_NEAR(small.world({mark.x, mark.y + mark.h}).x, view_min.x, small_tol);
  EXPECT_NEAR(small.world({mark.x, mark.y + mark.h}).y, view_min.y, small_tol);
  EXPECT_NEAR(small.world({mark.x + mark.w, mark.y}).x, view_max.x, small_tol);
  EXPECT_NEAR(small.world({mark.x + mark.w, mark.y}).y, view_max.y, small_tol);
  // The inset covers no footprint of the manoeuvre.
  for (const char* c : {"footprint-start", "footprint-cusp", "footprint-end"}) {
    for (const auto* e : with_class(parsed, c)) {
      for (const auto& q : points_of(e)) EXPECT_FALSE(inset.holds(q, 0.0)) << c;
    }
  }
  EXPECT_NE(all_text(parsed).find("inset: this view in the whole"), std::string::npos);

  // One number per segment, 1..n, anchored on its start pose (a dot there; the number on it, or
  // beside it on a leader when an earlier number is in the way); no two numbers overlap.
  const auto starts = with_class(parsed, "segment-start");
  const auto labels = with_class(parsed, "segment-label");
  const auto discs = with_class(parsed, "segment-label-disc");
  ASSERT_EQ(starts.size(), 3u);
  ASSERT_EQ(labels.size(), 3u);
  ASSERT_EQ(discs.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(starts[i]->IntAttribute("data-index", -1), static_cast<int>(i));
    EXPECT_EQ(labels[i]->IntAttribute("data-index", -1), static_cast<int>(i));
    EXPECT_STREQ(labels[i]->GetText(), std::to_string(i + 1).c_str());
    const Pose2& s = p.partial_paths[i].points.front().pose;
    const Point2 at = main.px({s.x, s.y});
    EXPECT_NEAR(starts[i]->DoubleAttribute("cx"), at.x, 0.05) << "segment " << i;
    EXPECT_NEAR(starts[i]->DoubleAttribute("cy"), at.y, 0.05) << "segment " << i;
    const Point2 label{labels[i]->DoubleAttribute("x"), labels[i]->DoubleAttribute("y")};
    EXPECT_DOUBLE_EQ(discs[i]->DoubleAttribute("cx"), label.x);
    EXPECT_DOUBLE_EQ(discs[i]->DoubleAttribute("cy"), label.y);
    const double r = discs[i]->DoubleAttribute("r");
    const double away = std::hypot(label.x - at.x, label.y - at.y);
    EXPECT_LE(away, 8.0 * r) << "segment " << i;
    if (away > 0.05) {  // a leader from the start pose to the number
      bool leader = false;
      for (const auto* l : with_class(parsed, "segment-label-leader")) {
        leader = leader || (l->IntAttribute("data-index", -1) == static_cast<int>(i) &&
                            std::abs(l->DoubleAttribute("x1") - at.x) < 0.05 &&
                            std::abs(l->DoubleAttribute("y1") - at.y) < 0.05 &&
                            std::abs(l->DoubleAttribute("x2") - label.x) < 0.01 &&
                            std::abs(l->DoubleAttribute("y2") - label.y) < 0.01);
      }
      EXPECT_TRUE(leader) << "segment " << i;
    }
    for (std::size_t j = 0; j < i; ++j) {
      const double d = std::hypot(label.x - labels[j]->DoubleAttribute("x"), label.y - labels[j]->DoubleAttribute("y"));
      EXPECT_GE(d, 2.0 * r) << "labels " << j + 1 << " and " << i + 1 << " overlap";
    }
  }
  // The first number sits on its start pose (nothing in the way); the second start is 0.6 m on
  // (at this scale closer than a disc): moved.
  EXPECT_NEAR(labels[0]->DoubleAttribute("x"), starts[0]->DoubleAttribute("cx"), 0.01);
  EXPECT_GT(std::abs(labels[1]->DoubleAttribute("y") - starts[1]->DoubleAttribute("cy")) +
                std::abs(labels[1]->DoubleAttribute("x") - starts[1]->DoubleAttribute("cx")),
            1.0);
  EXPECT_EQ(with_class(parsed, "footprint-cusp").size(), 2u);
}

TEST(RenderSvg, DirectionIsDashAndArrowAndCuspsAreTheDirectionChanges) {
  // Forward, forward, reverse, reverse, forward: two changes of direction, after segments 2 and 4.
  PullOutRequest request = long_road_scene();
  PullOutPath p;
  p.found = true;
  const double v[5] = {1.0, 1.0, -1.0, -1.0, 1.0};
  double x = 10.0;
  for (double vi : v) {
    PathWithLaneId seg;
    for (int i = 0; i <= 2; ++i) seg.points.push_back({{x + 0.5 * i * vi, 3.25, 0.0}, i == 2 ? 0.0 : vi, {}});
    x += vi;
    p.partial_paths.push_back(seg);
  }
  p.end_pose = p.partial_paths.back().points.back().pose;
  Parsed parsed;
  parse(render_svg(request, VehicleInfo{}, &p), parsed);
  const auto cusps = with_class(parsed, "footprint-cusp");
  ASSERT_EQ(cusps.size(), 2u);
  EXPECT_STREQ(cusps[0]->Attribute("data-after"), "2");
  EXPECT_STREQ(cusps[1]->Attribute("data-after"), "4");
  EXPECT_EQ(with_class(parsed, "segment-label").size(), 5u);
  const auto segments = with_class(parsed, "segment");
  ASSERT_EQ(segments.size(), 5u);
  std::vector<std::string> markers;
  for (const auto* e : parsed.elements) {
    if (std::string(e->Name()) == "marker") markers.push_back(std::string("url(#") + e->Attribute("id") + ")");
  }
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(segments[i]->Attribute("stroke-dasharray") != nullptr, v[i] < 0.0) << "segment " << i;
    ASSERT_NE(segments[i]->Attribute("marker-end"), nullptr);
    EXPECT_NE(std::find(markers.begin(), markers.end(), segments[i]->Attribute("marker-end")), markers.end());
  }
  const std::string text = all_text(parsed);
  for (const char* label : {"segment 1: forward", "segment 3: reverse (dashed)", "segment 5: forward"}) {
    EXPECT_NE(text.find(label), std::string::npos) << label;
  }
}

TEST(RenderSvg, NoInsetWhenTheManoeuvreSpansTheSceneOrWhenAskedForTheWhole) {
  // A shift from x = 10 to x = 55 on a 60 m road: the manoeuvre is most of the scene.
  PullOutRequest request = scene();
  request.objects.clear();
  PullOutPath p;
  p.found = true;
  PathWithLaneId shift;
  for (int i = 0; i <= 45; ++i) shift.points.push_back({{10.0 + i, 3.25 - 3.25 * i / 45.0, 0.0}, 2.0, {}});
  p.partial_paths = {shift};
  p.end_pose = shift.points.back().pose;
  Parsed spanning;
  parse(render_svg(request, VehicleInfo{}, &p), spanning);
  EXPECT_TRUE(with_class(spanning, "inset-frame").empty());
  // The boxed-in picture with frame_manoeuvre off: the whole 150 m, no inset.
  SvgOptions whole;
  whole.frame_manoeuvre = false;
  const PullOutPath wiggle = wiggle_out();
  Parsed parsed;
  parse(render_svg(long_road_scene(), VehicleInfo{}, &wiggle, whole), parsed);
  EXPECT_TRUE(with_class(parsed, "inset-frame").empty());
  const Transform t = main_transform(parsed, long_road_scene().ego_pose, wiggle.end_pose);
  const Rect frame = rect_of(with_class(parsed, "frame")[0]);
  EXPECT_GE(frame.w / t.scale, 150.0);
}

TEST(RenderSvg, WithoutAPathTheViewIsAroundTheStart) {
  const PullOutRequest request = long_road_scene();
  Parsed parsed;
  parse(render_svg(request, VehicleInfo{}, nullptr), parsed);
  ASSERT_EQ(with_class(parsed, "inset-frame").size(), 1u);
  // The transform from the start tick and the road's near end (x = 0 is inside the view: the car
  // behind reaches x = 3.2, the margin 10 m more).
  const auto tick = points_of(with_class(parsed, "footprint-start-heading")[0]);
  const VehicleInfo vehicle;
  const Transform t = transform_from({10.0, 3.25}, tick[0], {10.0 + vehicle.base_to_front_m(), 3.25}, tick[1]);
  const Rect frame = rect_of(with_class(parsed, "frame")[0]);
  const double width_m = frame.w / t.scale;
  // Start footprint 4.89 m long, the car behind 1.2 m back, the car ahead: about 16 m, plus 10 m
  // on each side, cut at the scene's near end.
  EXPECT_GT(width_m, 2.0 * kNoPathViewMarginM);
  EXPECT_LT(width_m, 50.0);
  EXPECT_TRUE(with_class(parsed, "segment-label").empty());
  EXPECT_TRUE(with_class(parsed, "footprint-cusp").empty());
}

}  // namespace
}  // namespace pullout::cli
