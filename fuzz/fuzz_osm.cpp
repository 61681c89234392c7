// Fuzz target: a Lanelet2 map in Autoware's OSM format (pullout/maps/osm_loader.hpp), parsed from
// memory with parse_lanelet_map (load_lanelet_map reads the file and does the same), then queried
// the way map requests use it: the lanelets around the first point of each lanelet, and each
// lanelet as an inline lane. A MapLoadError is the expected answer to a bad map; anything else
// escaping, a crash or a sanitizer report is a defect.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/osm_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::shared_ptr<const pullout::LaneletMap> map;
  try {
    map = pullout::parse_lanelet_map(std::string(reinterpret_cast<const char*>(data), size), "<fuzz>");
  } catch (const pullout::MapLoadError&) {
    return 0;  // the expected answer to a bad map
  }
  for (std::size_t i = 0; i < map->lanelets().size(); ++i) {
    const pullout::Lanelet& lanelet = map->lanelet(i);
    (void)map->find(lanelet.id);
    (void)pullout::to_lane(lanelet);
    if (lanelet.left.points.empty()) continue;
    const pullout::Point2& p = lanelet.left.points.front();
    (void)map->lanelets_containing(p);
    for (std::size_t near : map->lanelets_near(p, 5.0)) (void)map->distance_to(near, p);
  }
  return 0;
}
