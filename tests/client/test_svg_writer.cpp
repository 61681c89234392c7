// The CLI's SVG writer: well-formed XML, one element per lane/object/segment, footprints from the
// vehicle dimensions, y pointing up, a viewBox that holds everything, a legend and a scale bar.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include "pullout/geometry/angle.hpp"
#include "svg_test_support.hpp"
#include "svg_writer.hpp"

namespace pullout::cli {
namespace {

using namespace svg_testing;  // the picture-reading helpers (svg_test_support.hpp)

PullOutPath path() {
  PullOutPath p;
  p.found = true;
  p.planner_type = PlannerType::kGeometric;
  PathWithLaneId back;
  for (int i = 0; i <= 3; ++i) back.points.push_back({{10.0 - i, 3.25, 0.0}, -1.0, {2}});
  PathWithLaneId forward;
  for (int i = 0; i <= 30; ++i) forward.points.push_back({{7.0 + i, 3.25 - 0.1 * i, 0.0}, 2.0, {1}});
  p.partial_paths = {back, forward};
  p.pairs_terminal_velocity_and_accel = {{0.0, 0.0}, {2.0, 0.0}};
  p.start_pose = {7.0, 3.25, 0.0};
  p.end_pose = {37.0, 0.25, 0.0};
  return p;
}

TEST(VehicleFootprint, CornersFromVehicleInfo) {
  VehicleInfo v;  // wheel_base 2.79, front 1.0, rear 1.1, tread 1.64, overhangs 0.128
  const auto c = vehicle_footprint(v, {0.0, 0.0, 0.0});
  EXPECT_NEAR(c[0].x, 3.79, 1e-12);  // front-left
  EXPECT_NEAR(c[0].y, 0.948, 1e-12);
  EXPECT_NEAR(c[1].x, -1.1, 1e-12);    // rear-left
  EXPECT_NEAR(c[2].y, -0.948, 1e-12);  // rear-right
  // Rotated by 90 deg about base_link at (1, 2): the front points to +y.
  const auto r = vehicle_footprint(v, {1.0, 2.0, kPi / 2});
  EXPECT_NEAR(r[0].x, 1.0 - 0.948, 1e-9);
  EXPECT_NEAR(r[0].y, 2.0 + 3.79, 1e-9);
}

TEST(ObjectFootprint, BoxOrPolygon) {
  Object box;
  box.pose = {10.0, 0.0, kPi};
  box.length_m = 4.0;
  box.width_m = 2.0;
  const auto b = object_footprint(box);
  ASSERT_EQ(b.size(), 4u);
  EXPECT_NEAR(b[0].x, 8.0, 1e-9);  // (+2, +1) rotated by pi
  EXPECT_NEAR(b[0].y, -1.0, 1e-9);
  Object tri;
  tri.pose = {1.0, 1.0, 0.0};
  tri.polygon = {{1.0, 0.0}, {0.0, 1.0}, {0.0, 0.0}};
  const auto t = object_footprint(tri);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_NEAR(t[1].y, 2.0, 1e-12);
}

TEST(NiceScaleLength, OneTwoFiveSeries) {
  EXPECT_DOUBLE_EQ(nice_scale_length(7.0), 5.0);
  EXPECT_DOUBLE_EQ(nice_scale_length(19.0), 10.0);
  EXPECT_DOUBLE_EQ(nice_scale_length(20.0), 20.0);
  EXPECT_DOUBLE_EQ(nice_scale_length(0.3), 0.2);
  EXPECT_DOUBLE_EQ(nice_scale_length(0.0), 1.0);
}

TEST(RenderSvg, ElementsForEveryPart) {
  const PullOutRequest request = scene();
  const PullOutPath p = path();
  Parsed parsed;
  SvgOptions options;
  options.title = "demo & test";
  parse(render_svg(request, VehicleInfo{}, &p, options), parsed);
  EXPECT_STREQ(parsed.root->Name(), "svg");
  EXPECT_EQ(with_class(parsed, "lane-road").size(), 1u);
  EXPECT_EQ(with_class(parsed, "lane-shoulder").size(), 1u);
  EXPECT_STRNE(with_class(parsed, "lane-road")[0]->Attribute("fill"),
               with_class(parsed, "lane-shoulder")[0]->Attribute("fill"));
  EXPECT_EQ(with_class(parsed, "centerline").size(), 1u);
  EXPECT_EQ(with_class(parsed, "object").size(), 2u);
  EXPECT_EQ(points_of(with_class(parsed, "object")[1]).size(), 3u);  // the polygon object
  EXPECT_EQ(with_class(parsed, "footprint-start").size(), 1u);
  EXPECT_EQ(with_class(parsed, "footprint-end").size(), 1u);
  const auto segments = with_class(parsed, "segment");
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_STRNE(segments[0]->Attribute("stroke"), segments[1]->Attribute("stroke"));
  EXPECT_NE(segments[0]->Attribute("stroke-dasharray"), nullptr);  // the reverse segment
  EXPECT_EQ(segments[1]->Attribute("stroke-dasharray"), nullptr);
  EXPECT_EQ(points_of(segments[1]).size(), 31u);

  const std::string text = all_text(parsed);
  for (const char* label : {"road lane", "road shoulder", "object", "vehicle at start", "vehicle at end",
                            "segment 1: reverse (dashed)", "segment 2: forward", "goal", "demo & test", " m"}) {
    EXPECT_NE(text.find(label), std::string::npos) << label << " in\n" << text;
  }
}

TEST(RenderSvg, YAxisPointsUpAndScaleIsUniform) {
  const PullOutRequest request = scene();
  Parsed parsed;
  SvgOptions whole;  // the whole scene: lane outlines are not cut at a view's edge
  whole.frame_manoeuvre = false;
  parse(render_svg(request, VehicleInfo{}, nullptr, whole), parsed);
  // The shoulder (world y 1.75..4.75) is above the road (world y -1.75..1.75): smaller picture y.
  const auto road = points_of(with_class(parsed, "lane-road")[0]);
  const auto shoulder = points_of(with_class(parsed, "lane-shoulder")[0]);
  // Outline = left bound then reversed right bound: road[0] = (0, 1.75), road[2] = (60, -1.75).
  EXPECT_LT(shoulder[0].y, road[0].y);
  EXPECT_GT(road[2].y, road[0].y);
  const double sx = (road[1].x - road[0].x) / 60.0;
  const double sy = (road[2].y - road[1].y) / 3.5;
  EXPECT_NEAR(sx, sy, 0.01 * sx);  // 2-decimal rounding of px coordinates
  // No path: no end footprint, no segments.
  EXPECT_TRUE(with_class(parsed, "footprint-end").empty());
  EXPECT_TRUE(with_class(parsed, "segment").empty());
}

TEST(RenderSvg, ViewBoxHoldsEverything) {
  const PullOutRequest request = scene();
  const PullOutPath p = path();
  Parsed parsed;
  parse(render_svg(request, VehicleInfo{}, &p), parsed);
  double x0 = 0, y0 = 0, w = 0, h = 0;
  ASSERT_EQ(std::sscanf(parsed.root->Attribute("viewBox"), "%lf %lf %lf %lf", &x0, &y0, &w, &h), 4);
  EXPECT_DOUBLE_EQ(w, parsed.root->DoubleAttribute("width"));
  EXPECT_DOUBLE_EQ(h, parsed.root->DoubleAttribute("height"));
  for (const auto* e : parsed.elements) {
    if (e->Attribute("points") == nullptr) continue;
    for (const auto& q : points_of(e)) {
      EXPECT_GE(q.x, x0);
      EXPECT_LE(q.x, x0 + w);
      EXPECT_GE(q.y, y0);
      EXPECT_LE(q.y, y0 + h);
    }
  }
}

TEST(RenderSvg, SkipsNonFiniteAndHandlesEmptyScene) {
  PullOutRequest request;  // nothing but the ego pose at the origin
  PullOutPath p = path();
  p.partial_paths[1].points[3].pose.x = std::nan("");
  Parsed parsed;
  parse(render_svg(request, VehicleInfo{}, &p), parsed);
  EXPECT_EQ(points_of(with_class(parsed, "segment")[1]).size(), 30u);
  const std::string svg = render_svg(request, VehicleInfo{}, nullptr);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

TEST(WriteTextFile, WritesAndReportsFailures) {
  const auto file = std::filesystem::temp_directory_path() / "pullout_test_svg_writer.svg";
  write_text_file(file.string(), "<svg/>");
  std::ifstream in(file);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(content, "<svg/>");
  std::filesystem::remove(file);
  EXPECT_THROW(write_text_file("/nonexistent-dir/x.svg", "<svg/>"), std::runtime_error);
}

TEST(SvgWriter, DrawsMapLaneletsAndOutlinesTheRoute) {
  // A route request: no inline lanes; the map's lanelets around the vehicle come in the options.
  PullOutRequest request = scene();
  SvgOptions options;
  options.map_lanes = request.lanes;
  options.map_lanes.push_back(request.lanes[0]);
  options.map_lanes.back().id = 3;
  for (auto& p : options.map_lanes.back().left_bound) p.x += 60.0;
  for (auto& p : options.map_lanes.back().right_bound) p.x += 60.0;
  request.lanes.clear();
  request.route_lanelet_ids = {1, 3};
  options.frame_manoeuvre = false;
  Parsed parsed;
  parse(render_svg(request, VehicleInfo{}, nullptr, options), parsed);
  EXPECT_EQ(with_class(parsed, "map-road route").size(), 2u);
  EXPECT_EQ(with_class(parsed, "map-shoulder").size(), 1u);
  EXPECT_NE(all_text(parsed).find("route"), std::string::npos);
  EXPECT_NE(all_text(parsed).find("road shoulder"), std::string::npos);
  // The picture spans the map lanelets (120 m at most 1000 px wide): lane 3 ends inside it.
  const auto far = points_of(with_class(parsed, "map-road route")[1]);
  const double width = std::stod(parsed.root->Attribute("width"));
  for (const Point2& p : far) EXPECT_LT(p.x, width);
}

TEST(RenderSvg, FreespaceShowsTheGridAndAFootprintAtEveryCusp) {
  // A 4 x 2 cell grid with two occupied runs (row 0: cells 1-2; row 1: cell 3 unknown) and a
  // path forward, reverse, forward: two cusps, three segments.
  PullOutRequest request = scene();
  OccupancyGrid g;
  g.resolution_m = 1.0;
  g.width = 4;
  g.height = 2;
  g.data = {0, 100, 100, 0, 0, 0, 0, -1};
  request.occupancy_grid = g;
  PullOutPath p;
  p.found = true;
  p.planner_type = PlannerType::kFreespace;
  const double v[3] = {1.0, -1.0, 1.0};
  for (int s = 0; s < 3; ++s) {
    PathWithLaneId seg;
    for (int i = 0; i <= 4; ++i) seg.points.push_back({{5.0 + i * v[s], 1.0 + s, 0.0}, i == 4 ? 0.0 : v[s], {}});
    p.partial_paths.push_back(seg);
    p.pairs_terminal_velocity_and_accel.push_back({v[s], 0.0});
  }
  p.start_pose = p.partial_paths[0].points[0].pose;
  p.end_pose = p.partial_paths[2].points.back().pose;
  Parsed parsed;
  parse(render_svg(request, VehicleInfo{}, &p, {}), parsed);
  EXPECT_EQ(with_class(parsed, "grid-occupied").size(), 2u);
  EXPECT_EQ(with_class(parsed, "footprint-cusp").size(), 2u);
  EXPECT_EQ(with_class(parsed, "segment-label").size(), 3u);
  EXPECT_NE(all_text(parsed).find("vehicle at a cusp"), std::string::npos);
  EXPECT_NE(all_text(parsed).find("occupied grid cell"), std::string::npos);
  // Without cusps (one direction) and without a grid: none.
  p.partial_paths.resize(1);
  p.pairs_terminal_velocity_and_accel.resize(1);
  request.occupancy_grid.reset();
  Parsed plain;
  parse(render_svg(request, VehicleInfo{}, &p, {}), plain);
  EXPECT_TRUE(with_class(plain, "grid-occupied").empty());
  EXPECT_TRUE(with_class(plain, "footprint-cusp").empty());
  // A grid whose data is shorter than width x height (the request validation rejects it; the
  // CLI still draws the request): no cell is read beyond the data, none is drawn.
  OccupancyGrid short_grid = g;
  short_grid.width = 400;
  short_grid.height = 300;
  request.occupancy_grid = short_grid;
  Parsed bad;
  parse(render_svg(request, VehicleInfo{}, &p, {}), bad);
  EXPECT_TRUE(with_class(bad, "grid-occupied").empty());
}

}  // namespace
}  // namespace pullout::cli
