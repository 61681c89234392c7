// Reading Lanelet2 maps in Autoware's OSM (XML) format.
//
// What is read:
//   - nodes: `id`, and the `local_x` / `local_y` tags (metres in the map frame, as Autoware's
//     maps carry them). When any node lacks them, every node's `lat` / `lon` is projected instead
//     onto the plane tangent to the WGS84 ellipsoid at the first node of the file (a local
//     east-north-up frame, GeographicLib::LocalCartesian with height 0): x east, y north, metres.
//     Good to a few millimetres over a few kilometres around the origin.
//   - ways: `id` and their `nd` node references.
//   - relations with `type=lanelet`: exactly one `left` and one `right` way member, an optional
//     `centerline` way member, and the tags `subtype` (road | road_shoulder | anything else, kept as
//     "other"; road when absent, the Lanelet2 default), `speed_limit` (km/h when a plain number, as
//     in Autoware's maps; "km/h", "mph" and "m/s" suffixes are understood; 50 km/h when absent)
//     and `turn_direction` (straight | left | right).
// Everything else (regulatory elements, areas, other tags, ways and nodes no lanelet uses) is
// skipped; a dangling reference outside the lanelets is not an error.
//
// Failure modes: MapLoadError (never a crash) for an unreadable file, XML that does not parse
// (with the line), and for each lanelet that cannot be built: a missing or doubled bound, a bound
// referring to a way or node that is not in the file, a bound of fewer than 2 distinct points, a
// malformed number or tag value; also duplicate ids and a file with no lanelet at all; and a node
// farther than kMaxMapCoordinateM from the origin (local_x / local_y, or lat/lon projected).
//
// Size: loading is linear in the file (the spatial index files a lanelet covering more than 4096
// cells of 16 m in a list of its own, see grid_index.hpp), and a lanelet of any length is planned
// on in bounded work: the pipeline crops it to the planning horizon (lanes/lane_crop.hpp). A
// 1,000 km lanelet loads and plans like a 100 m one.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pullout/maps/lanelet_map.hpp"

namespace pullout {

// [m] |x| and |y| of every node in the map frame: the request limit of the same name
// (RequestLimits::max_coordinate_m), so that what the map yields is what a request may carry.
constexpr double kMaxMapCoordinateM = 1e7;

// what() is one line: "<source>: <first problem>" plus "(and N more problems)" when there are
// more; problems() lists them all.
class MapLoadError : public std::runtime_error {
 public:
  MapLoadError(const std::string& source, std::vector<std::string> problems);
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// Loads an OSM file. Throws MapLoadError.
std::shared_ptr<const LaneletMap> load_lanelet_map(const std::string& path);

// Parses OSM XML held in memory; `source` names it in errors. Throws MapLoadError.
std::shared_ptr<const LaneletMap> parse_lanelet_map(const std::string& xml, const std::string& source = "<memory>");

}  // namespace pullout
