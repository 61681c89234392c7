// Occupancy grids of scenario files: a ROS map_server map (a YAML file beside a PGM image) or
// obstacle shapes on a given extent. Not part of the public API.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "config/yaml_fields.hpp"
#include "pullout/model/types.hpp"
#include "pullout/pipeline/parameters.hpp"

namespace pullout {

// A PGM image (P5 binary or P2 plain, maxval up to 65535): `pixels` row-major from the top row.
struct PgmImage {
  int width{0};
  int height{0};
  int max_value{255};
  std::vector<std::uint16_t> pixels;
};

// Reads a PGM file of at most `max_cells` pixels; on failure returns false and appends "<path>:
// <problem>" to problems. Reads the header and then only the raster it declares.
bool read_pgm(const std::string& file, std::size_t max_cells, PgmImage& out, std::vector<std::string>& problems);

// Loads a map_server YAML (image, resolution, origin [x, y, yaw], occupied_thresh, free_thresh,
// negate, optional mode: trinary) and its image into a ROS grid (100 occupied, 0 free, -1
// unknown; row 0 of the grid is the image's bottom row). `key_path` prefixes the problems. The
// image holds at most limits.max_grid_cells pixels, as a request's grid.
bool load_map_server_grid(const std::string& yaml_file, const std::string& key_path, const RequestLimits& limits,
                          OccupancyGrid& out, std::vector<std::string>& problems);

// The scenario's `grid:` mapping: {map: file.yaml} (relative to `base_dir`) or {resolution,
// origin: {x, y, yaw|yaw_deg}, size: [width_m, height_m], obstacles: [{x, y, yaw_deg, length,
// width} | {polygon: [[x, y], ...]}]} (map frame; obstacle cells 100, the rest 0). Bounded as a
// request is: at most limits.max_grid_cells cells, obstacle coordinates and sizes within
// limits.max_coordinate_m.
bool read_scenario_grid(yaml_fields::MapReader& reader, const std::string& base_dir, const RequestLimits& limits,
                        OccupancyGrid& out);

}  // namespace pullout
