// Lanelet2 map loading and queries on the project's own maps: tests/maps/straight_shoulder.osm
// (see tests/maps/make_test_maps.py) and small maps written here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "pullout/geometry/angle.hpp"
#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/osm_loader.hpp"

namespace pullout {
namespace {

const std::string kOwnMap = std::string(PULLOUT_SOURCE_DIR) + "/tests/maps/straight_shoulder.osm";

std::vector<std::int64_t> ids_of(const LaneletMap& map, const std::vector<std::size_t>& indices) {
  std::vector<std::int64_t> ids;
  for (std::size_t i : indices) ids.push_back(map.lanelet(i).id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

const Lanelet& by_id(const LaneletMap& map, std::int64_t id) {
  const auto i = map.find(id);
  EXPECT_TRUE(i.has_value()) << "lanelet " << id;
  return map.lanelet(i.value_or(0));
}

// A minimal OSM document: `body` holds the nodes, ways and relations.
std::string osm(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<osm generator=\"test\">\n" + body + "</osm>\n";
}

std::string node(std::int64_t id, double x, double y) {
  std::ostringstream os;
  os << "<node id=\"" << id << "\" lat=\"35\" lon=\"139\"><tag k=\"local_x\" v=\"" << x << "\"/><tag k=\"local_y\" v=\""
     << y << "\"/></node>\n";
  return os.str();
}

std::string way(std::int64_t id, const std::vector<std::int64_t>& nodes) {
  std::string out = "<way id=\"" + std::to_string(id) + "\">";
  for (std::int64_t n : nodes) out += "<nd ref=\"" + std::to_string(n) + "\"/>";
  return out + "</way>\n";
}

std::string lanelet(std::int64_t id, std::int64_t left, std::int64_t right, const std::string& tags = "") {
  return "<relation id=\"" + std::to_string(id) + "\"><member type=\"way\" role=\"left\" ref=\"" +
         std::to_string(left) + "\"/><member type=\"way\" role=\"right\" ref=\"" + std::to_string(right) +
         "\"/><tag k=\"type\" v=\"lanelet\"/>" + tags + "</relation>\n";
}

// One 10 m x 3 m lanelet along +x: nodes 1..4, ways 10 (left) and 11 (right).
std::string one_lanelet(const std::string& tags = "") {
  return node(1, 0, 1.5) + node(2, 10, 1.5) + node(3, 0, -1.5) + node(4, 10, -1.5) + way(10, {1, 2}) + way(11, {3, 4}) +
         lanelet(7, 10, 11, tags);
}

std::string load_error(const std::string& xml) {
  try {
    parse_lanelet_map(xml, "test.osm");
  } catch (const MapLoadError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no MapLoadError";
  return "";
}

TEST(LaneletMap, LoadsTheOwnMap) {
  const auto map = load_lanelet_map(kOwnMap);
  EXPECT_EQ(map->lanelets().size(), 7u);
  EXPECT_EQ(map->count(LaneletSubtype::kRoad), 4u);
  EXPECT_EQ(map->count(LaneletSubtype::kRoadShoulder), 2u);
  EXPECT_EQ(map->count(LaneletSubtype::kOther), 1u);
  EXPECT_EQ(by_id(*map, 401).subtype_name, "crosswalk");
  // speed_limit 50 (km/h) -> m/s; shoulders 10 km/h.
  EXPECT_NEAR(by_id(*map, 101).speed_limit_mps, 50.0 / 3.6, 1e-12);
  EXPECT_NEAR(by_id(*map, 201).speed_limit_mps, 10.0 / 3.6, 1e-12);
  EXPECT_EQ(by_id(*map, 103).turn_direction, TurnDirection::kStraight);
  EXPECT_EQ(by_id(*map, 101).turn_direction, TurnDirection::kNone);
  EXPECT_NEAR(by_id(*map, 101).length_m, 60.0, 1e-9);
}

TEST(LaneletMap, BoundsAreAlignedWithTheDrivingDirection) {
  const auto map = load_lanelet_map(kOwnMap);
  // 103's right bound is drawn backwards in the file.
  const Lanelet& l103 = by_id(*map, 103);
  EXPECT_DOUBLE_EQ(l103.right.points.front().x, 120.0);
  EXPECT_DOUBLE_EQ(l103.right.points.back().x, 200.0);
  // 301 drives -x: its left bound (y = -5.25) is drawn that way, its right bound (y = -1.75) the
  // other way.
  const Lanelet& l301 = by_id(*map, 301);
  EXPECT_DOUBLE_EQ(l301.left.points.front().x, 200.0);
  EXPECT_DOUBLE_EQ(l301.right.points.front().x, 200.0);
  EXPECT_DOUBLE_EQ(l301.right.points.front().y, -1.75);
  // Both bounds drawn against the lanes' direction: the lanelet drives the other way.
  const auto both = parse_lanelet_map(osm(node(1, 0, 1.5) + node(2, 10, 1.5) + node(3, 0, -1.5) + node(4, 10, -1.5) +
                                          way(10, {4, 3}) + way(11, {2, 1}) + lanelet(7, 10, 11)));
  EXPECT_DOUBLE_EQ(both->lanelet(0).left.points.front().x, 10.0);  // drives -x, left bound at y = -1.5
  EXPECT_DOUBLE_EQ(both->lanelet(0).left.points.front().y, -1.5);
}

TEST(LaneletMap, TopologyFromSharedNodesAndWays) {
  const auto map = load_lanelet_map(kOwnMap);
  EXPECT_EQ(ids_of(*map, by_id(*map, 101).successors), std::vector<std::int64_t>{102});
  EXPECT_EQ(ids_of(*map, by_id(*map, 102).successors), std::vector<std::int64_t>{103});
  EXPECT_EQ(ids_of(*map, by_id(*map, 103).predecessors), std::vector<std::int64_t>{102});
  EXPECT_TRUE(by_id(*map, 101).predecessors.empty());
  EXPECT_TRUE(by_id(*map, 103).successors.empty());
  EXPECT_EQ(ids_of(*map, by_id(*map, 201).successors), std::vector<std::int64_t>{202});
  // The shoulder's right bound is the road's left bound.
  EXPECT_EQ(ids_of(*map, by_id(*map, 201).right_neighbours), std::vector<std::int64_t>{101});
  EXPECT_EQ(ids_of(*map, by_id(*map, 101).left_neighbours), std::vector<std::int64_t>{201});
  EXPECT_EQ(ids_of(*map, by_id(*map, 202).right_neighbours), std::vector<std::int64_t>{102});
  EXPECT_TRUE(by_id(*map, 101).right_neighbours.empty());  // 301 runs the other way
  EXPECT_TRUE(by_id(*map, 301).successors.empty());
}

TEST(LaneletMap, SpatialQueriesMatchBruteForce) {
  const auto map = load_lanelet_map(kOwnMap);
  EXPECT_EQ(ids_of(*map, map->lanelets_containing({20.0, 3.25})), std::vector<std::int64_t>{201});
  EXPECT_EQ(ids_of(*map, map->lanelets_containing({20.0, 0.0})), std::vector<std::int64_t>{101});
  EXPECT_TRUE(map->lanelets_containing({20.0, 30.0}).empty());
  EXPECT_EQ(ids_of(*map, map->lanelets_near({20.0, 2.0}, 0.5)), (std::vector<std::int64_t>{101, 201}));
  EXPECT_TRUE(map->lanelets_near({20.0, 2.0}, -1.0).empty());
  EXPECT_TRUE(map->lanelets_near({NAN, 2.0}, 1.0).empty());
  EXPECT_EQ(map->lanelets_near({20.0, 2.0}, 1e9).size(), map->lanelets().size());  // no cell walk of 1e17 cells
  // Brute force over every lanelet, on a grid covering the map and beyond.
  for (double x = -30.0; x <= 230.0; x += 3.7) {
    for (double y = -12.0; y <= 12.0; y += 0.9) {
      for (double radius : {0.0, 1.0, 7.5, 60.0}) {
        std::vector<std::size_t> expected;
        for (std::size_t i = 0; i < map->lanelets().size(); ++i) {
          if (map->distance_to(i, {x, y}) <= radius) expected.push_back(i);
        }
        ASSERT_EQ(map->lanelets_near({x, y}, radius), expected) << x << ", " << y << " r " << radius;
      }
    }
  }
}

TEST(LaneletMap, SpatialQueriesAtAnyCoordinates) {
  // A lanelet x in [-10, 0] (negative cell indices), queried near and very far away.
  const auto map = parse_lanelet_map(osm(node(1, -10, 1.5) + node(2, 0, 1.5) + node(3, -10, -1.5) + node(4, 0, -1.5) +
                                         way(10, {1, 2}) + way(11, {3, 4}) + lanelet(7, 10, 11)),
                                     "test.osm");
  EXPECT_EQ(ids_of(*map, map->lanelets_containing({-5.0, 0.0})), std::vector<std::int64_t>{7});
  EXPECT_TRUE(map->lanelets_containing({5.0, 0.0}).empty());
  EXPECT_EQ(ids_of(*map, map->lanelets_near({-12.0, 0.0}, 2.5)), std::vector<std::int64_t>{7});
  for (const Point2& p : {Point2{1e300, 0.0}, Point2{-1e300, 0.0}, Point2{-5.0, 1e300}, Point2{-1e300, -1e300}}) {
    EXPECT_TRUE(map->lanelets_containing(p).empty()) << p.x << ", " << p.y;
    EXPECT_TRUE(map->lanelets_near(p, 10.0).empty()) << p.x << ", " << p.y;
  }
}

TEST(LaneletMap, ConvertsRoadAndShoulderLanelets) {
  const auto map = load_lanelet_map(kOwnMap);
  const auto lane = to_lane(by_id(*map, 201));
  ASSERT_TRUE(lane);
  EXPECT_EQ(lane->id, 201);
  EXPECT_EQ(lane->subtype, LaneSubtype::kRoadShoulder);
  EXPECT_EQ(lane->left_bound.size(), by_id(*map, 201).left.points.size());
  EXPECT_TRUE(lane->centerline.empty());    // derived by the lane world
  EXPECT_FALSE(to_lane(by_id(*map, 401)));  // a crosswalk is no lane to drive on
}

// WGS84 radii of curvature at latitude phi: an independent check of the projection for small
// offsets (east: N cos(phi) per radian of longitude; north: M per radian of latitude).
TEST(LaneletMap, ProjectsLatLonWhenNodesHaveNoLocalCoordinates) {
  const double a = 6378137.0;
  const double f = 1.0 / 298.257223563;
  const double e2 = f * (2.0 - f);
  const double phi = 35.0 * kDegToRad;
  const double w = 1.0 - e2 * std::sin(phi) * std::sin(phi);
  const double n_radius = a / std::sqrt(w);
  const double m_radius = a * (1.0 - e2) / std::pow(w, 1.5);
  const double dlon = 100.0 / (n_radius * std::cos(phi)) * kRadToDeg;  // 100 m east
  const double dlat = 3.0 / m_radius * kRadToDeg;                      // 3 m north
  const auto geo = [](std::int64_t id, double lat, double lon) {
    std::ostringstream os;
    os.precision(15);
    os << "<node id=\"" << id << "\" lat=\"" << lat << "\" lon=\"" << lon << "\"/>\n";
    return os.str();
  };
  const auto map =
      parse_lanelet_map(osm(geo(1, 35.0 + dlat, 139.0) + geo(2, 35.0 + dlat, 139.0 + dlon) + geo(3, 35.0, 139.0) +
                            geo(4, 35.0, 139.0 + dlon) + way(10, {1, 2}) + way(11, {3, 4}) + lanelet(7, 10, 11)));
  const Lanelet& ll = map->lanelet(0);
  EXPECT_NEAR(ll.left.points.front().x, 0.0, 1e-6);
  EXPECT_NEAR(ll.left.points.front().y, 0.0, 1e-6);
  // 1 cm over 100 m: the tangent plane's curvature terms are ~ d^2 / 2R, well below that.
  EXPECT_NEAR(ll.left.points.back().x, 100.0, 0.01);
  EXPECT_NEAR(ll.right.points.front().y, -3.0, 0.01);
  EXPECT_NEAR(ll.right.points.back().x, 100.0, 0.01);
}

TEST(LaneletMap, SkipsWhatItDoesNotUse) {
  // A regulatory element, an area, unknown tags, a way with a dangling node: all ignored.
  const auto map = parse_lanelet_map(
      osm("<MetaInfo format_version=\"1\"/>\n" +
          one_lanelet("<tag k=\"one_way\" v=\"yes\"/><tag k=\"foo\" v=\"bar\"/>") + way(12, {1, 424242}) +
          "<relation id=\"50\"><member type=\"way\" role=\"refers\" ref=\"12\"/><tag k=\"type\" "
          "v=\"regulatory_element\"/><tag k=\"subtype\" v=\"traffic_light\"/></relation>\n"
          "<relation id=\"51\"><member type=\"way\" role=\"outer\" ref=\"10\"/><tag k=\"type\" "
          "v=\"multipolygon\"/></relation>\n"));
  EXPECT_EQ(map->lanelets().size(), 1u);
  EXPECT_EQ(map->lanelet(0).subtype, LaneletSubtype::kRoad);        // no subtype tag: road
  EXPECT_NEAR(map->lanelet(0).speed_limit_mps, 50.0 / 3.6, 1e-12);  // default
}

TEST(LaneletMap, SpeedLimitUnits) {
  const auto speed = [](const std::string& v) {
    return parse_lanelet_map(osm(one_lanelet("<tag k=\"speed_limit\" v=\"" + v + "\"/>")))->lanelet(0).speed_limit_mps;
  };
  EXPECT_NEAR(speed("36"), 10.0, 1e-12);
  EXPECT_NEAR(speed("36 km/h"), 10.0, 1e-12);
  EXPECT_NEAR(speed("10 mph"), 4.4704, 1e-12);
  EXPECT_NEAR(speed("7.5 m/s"), 7.5, 1e-12);
}

TEST(LaneletMap, CenterlineMemberIsAlignedToo) {
  const auto map = parse_lanelet_map(osm(
      node(1, 0, 1.5) + node(2, 10, 1.5) + node(3, 0, -1.5) + node(4, 10, -1.5) + node(5, 10, 0) + node(6, 0, 0) +
      way(10, {1, 2}) + way(11, {3, 4}) + way(12, {5, 6}) +
      "<relation id=\"7\"><member type=\"way\" role=\"left\" ref=\"10\"/><member type=\"way\" role=\"right\" "
      "ref=\"11\"/><member type=\"way\" role=\"centerline\" ref=\"12\"/><tag k=\"type\" v=\"lanelet\"/></relation>"));
  ASSERT_EQ(map->lanelet(0).centerline.size(), 2u);
  EXPECT_DOUBLE_EQ(map->lanelet(0).centerline.front().x, 0.0);
}

TEST(LaneletMap, MalformedMapsAreErrorsNamingTheProblem) {
  EXPECT_NE(load_error(osm(one_lanelet()).substr(0, 150)).find("not valid XML"), std::string::npos);
  EXPECT_NE(load_error("<?xml version=\"1.0\"?>\n<svg/>\n").find("no <osm> root"), std::string::npos);
  EXPECT_NE(load_error(osm(node(1, 0, 0))).find("no lanelet"), std::string::npos);
  const std::string missing_way =
      load_error(osm(node(1, 0, 1.5) + node(2, 10, 1.5) + way(10, {1, 2}) + lanelet(7, 10, 99)));
  EXPECT_NE(missing_way.find("lanelet 7: right way 99 is not in the file"), std::string::npos) << missing_way;
  const std::string missing_node = load_error(osm(node(1, 0, 1.5) + node(2, 10, 1.5) + node(3, 0, -1.5) +
                                                  way(10, {1, 2}) + way(11, {3, 5}) + lanelet(7, 10, 11)));
  EXPECT_NE(missing_node.find("node 5 is not in the file"), std::string::npos) << missing_node;
  const std::string no_right =
      load_error(osm(node(1, 0, 1.5) + node(2, 10, 1.5) + way(10, {1, 2}) +
                     "<relation id=\"7\"><member type=\"way\" role=\"left\" ref=\"10\"/><tag k=\"type\" "
                     "v=\"lanelet\"/></relation>"));
  EXPECT_NE(no_right.find("needs exactly one 'right' way member, has 0"), std::string::npos) << no_right;
  const std::string short_bound = load_error(osm(node(1, 0, 1.5) + node(3, 0, -1.5) + node(4, 10, -1.5) +
                                                 way(10, {1, 1}) + way(11, {3, 4}) + lanelet(7, 10, 11)));
  EXPECT_NE(short_bound.find("fewer than 2 distinct points"), std::string::npos) << short_bound;
  EXPECT_NE(load_error(osm(one_lanelet("<tag k=\"speed_limit\" v=\"fast\"/>"))).find("speed_limit 'fast'"),
            std::string::npos);
  EXPECT_NE(load_error(osm(one_lanelet("<tag k=\"speed_limit\" v=\"0\"/>"))).find("speed_limit '0'"),
            std::string::npos);
  EXPECT_NE(load_error(osm(one_lanelet("<tag k=\"turn_direction\" v=\"up\"/>"))).find("turn_direction 'up'"),
            std::string::npos);
  EXPECT_NE(load_error(osm(node(1, 0, 0) + one_lanelet())).find("duplicate node id"), std::string::npos);
  const std::string bad_x =
      load_error(osm("<node id=\"1\"><tag k=\"local_x\" v=\"abc\"/><tag k=\"local_y\" v=\"0\"/></node>\n" +
                     one_lanelet().substr(one_lanelet().find("<node id=\"2\""))));
  EXPECT_NE(bad_x.find("local_x 'abc' is not a number"), std::string::npos) << bad_x;
  // Several problems: the first, and how many more.
  const std::string several = load_error(osm(one_lanelet() + lanelet(8, 10, 98) + lanelet(9, 10, 97)));
  EXPECT_NE(several.find("(and 1 more problems)"), std::string::npos) << several;
  EXPECT_EQ(several.rfind("test.osm: ", 0), 0u) << several;
}

TEST(LaneletMap, UnreadableFiles) {
  try {
    load_lanelet_map("/nonexistent/map.osm");
    FAIL();
  } catch (const MapLoadError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/map.osm: cannot read file");
  }
  EXPECT_THROW(load_lanelet_map(PULLOUT_SOURCE_DIR), MapLoadError);
}

}  // namespace
}  // namespace pullout
