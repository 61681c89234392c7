#include "config/grid_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "pullout/collision/footprint.hpp"
#include "pullout/freespace/costmap.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {

namespace {

// A PGM header (magic, width, height, maxval and their comments) is read from the file's first
// kMaxHeaderBytes; a P2 raster from at most kMaxP2BytesPerPixel per pixel and kMaxHeaderBytes
// more (a value has up to 5 digits and its whitespace; padded columns fit too). A file is read no
// further: a wrong path naming a large file costs what the image would (a P2 image of
// max_grid_cells, 16 Mi, at most 256 MiB of text).
constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
constexpr std::size_t kMaxP2BytesPerPixel = 16;
constexpr std::size_t kMaxMapYamlBytes = 64 * 1024;  // a map_server YAML file (image, resolution, origin, ...)
constexpr double kDrawBudgetMs = 2000.0;  // [ms] drawing a scenario grid's obstacles (see read_scenario_grid)

bool resolution_ok(double resolution) {
  return resolution >= kMinGridResolution && resolution <= kMaxGridResolution;  // false for NaN
}

std::string resolution_range() {
  std::ostringstream os;
  os << "within [" << kMinGridResolution << ", " << kMaxGridResolution << "] [m]";
  return os.str();
}

std::string cell_limit(std::size_t max_cells) {
  return std::to_string(max_cells) + " cells (service.limits.max_grid_cells)";
}

// The next header token of a PGM file, skipping whitespace and '#' comments. A token is cut after
// kMaxTokenBytes (no number of a PGM file is longer): 256 MiB of NUL bytes where a P2 raster
// should be grew one token of that size, char by char (2.6 s, 810 MB).
constexpr std::size_t kMaxTokenBytes = 16;
bool next_token(const std::string& data, std::size_t& pos, std::string& token) {
  token.clear();
  while (pos < data.size()) {
    const char c = data[pos];
    if (c == '#') {
      while (pos < data.size() && data[pos] != '\n') ++pos;
    } else if (std::isspace(static_cast<unsigned char>(c)) != 0) {
      ++pos;
    } else {
      break;
    }
  }
  while (pos < data.size() && token.size() < kMaxTokenBytes &&
         std::isspace(static_cast<unsigned char>(data[pos])) == 0) {
    token += data[pos++];
  }
  return !token.empty();
}

bool parse_int(const std::string& s, long& v) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s) {
    if (std::isdigit(static_cast<unsigned char>(c)) == 0) return false;
  }
  v = std::stol(s);
  return true;
}

// Up to `count` bytes of `in` from `offset` (fewer at the end of the file).
std::string read_at(std::ifstream& in, std::size_t offset, std::size_t count) {
  std::string bytes(count, '\0');
  in.clear();
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(bytes.data(), static_cast<std::streamsize>(count));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

// |v| within the request limit of coordinates (see RequestLimits::max_coordinate_m): beyond it a
// shape's corners lose its position and width to rounding, or overflow in the grid frame.
void check_extent(double v, const std::string& field, const char* what, const RequestLimits& limits,
                  std::vector<std::string>& problems) {
  if (std::abs(v) <= limits.max_coordinate_m) return;
  std::ostringstream os;
  os << field << ": " << what << std::abs(v) << " exceeds " << limits.max_coordinate_m << " m";
  problems.push_back(os.str());
}

bool parse_pgm(std::ifstream& in, std::size_t file_size, const std::string& file, std::size_t max_cells, PgmImage& out,
               std::vector<std::string>& problems) {
  const std::string head = read_at(in, 0, std::min(file_size, kMaxHeaderBytes));
  std::size_t pos = 0;
  std::string magic, tw, th, tm;
  long w = 0, h = 0, maxval = 0;
  if (!next_token(head, pos, magic) || (magic != "P5" && magic != "P2")) {
    problems.push_back(file + ": not a PGM image (expected P5 or P2)");
    return false;
  }
  // The whitespace after maxval lies within `head`, so no token was cut at its end.
  if (!next_token(head, pos, tw) || !next_token(head, pos, th) || !next_token(head, pos, tm) || !parse_int(tw, w) ||
      !parse_int(th, h) || !parse_int(tm, maxval) || w < 1 || h < 1 || maxval < 1 || maxval > 65535 ||
      pos >= head.size()) {
    problems.push_back(file + ": bad PGM header (width, height, maxval in 1..65535)");
    return false;
  }
  const auto n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);  // < 1e18: 9 digits each
  if (n > max_cells) {
    problems.push_back(file + ": " + tw + " x " + th + " pixels exceed the limit of " + cell_limit(max_cells));
    return false;
  }
  std::string raster;
  if (magic == "P5") {
    const std::size_t start = pos + 1;  // after the single whitespace after maxval
    const std::size_t bytes = maxval > 255 ? 2 : 1;
    if (file_size < start + n * bytes) {
      problems.push_back(file + ": truncated PGM data: " + tw + " x " + th + " pixels need " +
                         std::to_string(n * bytes) + " bytes, the file has " + std::to_string(file_size - start));
      return false;
    }
    raster = read_at(in, start, n * bytes);
    if (raster.size() != n * bytes) {
      problems.push_back(file + ": cannot read file (it ended before its size)");
      return false;
    }
    out.pixels.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const auto b0 = static_cast<unsigned char>(raster[i * bytes]);
      out.pixels[i] =
          bytes == 1 ? b0 : static_cast<std::uint16_t>((b0 << 8) | static_cast<unsigned char>(raster[i * 2 + 1]));
    }
  } else {
    raster = read_at(in, pos, std::min(file_size - pos, n * kMaxP2BytesPerPixel + kMaxHeaderBytes));
    out.pixels.assign(n, 0);
    std::size_t at = 0;
    std::string t;
    for (std::size_t i = 0; i < n; ++i) {
      long v = 0;
      if (!next_token(raster, at, t) || !parse_int(t, v) || v > maxval) {
        problems.push_back(file + ": bad or missing pixel " + std::to_string(i) + " in P2 data");
        return false;
      }
      out.pixels[i] = static_cast<std::uint16_t>(v);
    }
  }
  out.width = static_cast<int>(w);
  out.height = static_cast<int>(h);
  out.max_value = static_cast<int>(maxval);
  return true;
}

}  // namespace

bool read_pgm(const std::string& file, std::size_t max_cells, PgmImage& out, std::vector<std::string>& problems) {
  // Checked before opening: opening a FIFO waits for a writer, reading a directory throws.
  std::error_code ec;
  const bool regular = std::filesystem::is_regular_file(file, ec);
  const std::uintmax_t size = regular ? std::filesystem::file_size(file, ec) : 0;
  if (!regular || ec) {
    problems.push_back(file + ": cannot read file (not a regular file)");
    return false;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    problems.push_back(file + ": cannot read file");
    return false;
  }
  try {
    return parse_pgm(in, static_cast<std::size_t>(size), file, max_cells, out, problems);
  } catch (const std::exception& e) {  // libstdc++ throws std::ios_failure on a read error (EIO)
    problems.push_back(file + ": cannot read file (" + e.what() + ")");
    return false;
  }
}

bool load_map_server_grid(const std::string& yaml_file, const std::string& key_path, const RequestLimits& limits,
                          OccupancyGrid& out, std::vector<std::string>& problems) {
  YAML::Node doc;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(yaml_file, ec)) {  // a directory opens, and reading it throws
    problems.push_back(key_path + ": " + yaml_file + ": cannot read file (not a regular file)");
    return false;
  }
  // Read here, at most kMaxMapYamlBytes (a map_server file is a few lines): a read error inside
  // yaml-cpp's own stream (EIO, /proc/self/mem) leaked its buffer (LeakSanitizer).
  std::string text;
  try {
    std::ifstream in(yaml_file, std::ios::binary);
    text = read_at(in, 0, kMaxMapYamlBytes + 1);
    if (in.bad()) throw std::ios_base::failure("read error");
  } catch (const std::exception& e) {
    problems.push_back(key_path + ": " + yaml_file + ": cannot read file (" + e.what() + ")");
    return false;
  }
  if (text.size() > kMaxMapYamlBytes) {
    problems.push_back(key_path + ": " + yaml_file + ": larger than " + std::to_string(kMaxMapYamlBytes) +
                       " bytes: not a map_server file");
    return false;
  }
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    problems.push_back(key_path + ": " + yaml_file + ": " + e.what());
    return false;
  }
  const std::size_t before = problems.size();
  yaml_fields::MapReader r(doc, key_path, problems);
  if (!r.valid()) return false;
  std::string image;
  double resolution = 0.0, occupied = 0.65, free = 0.196;
  int negate = 0;
  std::string mode = "trinary";
  if (!r.read("image", image)) problems.push_back(r.key_path("image") + ": required");
  if (!r.read("resolution", resolution)) {
    problems.push_back(r.key_path("resolution") + ": required, " + resolution_range());
  } else if (!resolution_ok(resolution)) {
    problems.push_back(r.key_path("resolution") + ": " + resolution_range());
  }
  r.read("occupied_thresh", occupied);
  r.read("free_thresh", free);
  r.read("negate", negate);
  r.read("mode", mode);
  if (mode != "trinary") problems.push_back(r.key_path("mode") + ": only trinary is supported");
  if (!(free >= 0.0 && free < occupied && occupied <= 1.0)) {
    problems.push_back(r.key_path("occupied_thresh") + ": need 0 <= free_thresh < occupied_thresh <= 1");
  }
  Pose2 origin;
  const YAML::Node o = r.get("origin");
  if (!o.IsSequence() || o.size() != 3) {
    problems.push_back(r.key_path("origin") + ": required, [x, y, yaw]");
  } else {
    const auto x = yaml_fields::to_double(o[0], r.key_path("origin") + "[0]", problems);
    const auto y = yaml_fields::to_double(o[1], r.key_path("origin") + "[1]", problems);
    const auto yaw = yaml_fields::to_double(o[2], r.key_path("origin") + "[2]", problems);
    if (x && y && yaw) origin = {*x, *y, *yaw};
  }
  r.finish();
  if (problems.size() != before) return false;
  std::filesystem::path img(image);
  if (img.is_relative()) img = std::filesystem::path(yaml_file).parent_path() / img;
  PgmImage pgm;
  if (!read_pgm(img.string(), limits.max_grid_cells, pgm, problems)) return false;
  out.resolution_m = resolution;
  out.origin = origin;
  out.width = static_cast<std::uint32_t>(pgm.width);
  out.height = static_cast<std::uint32_t>(pgm.height);
  out.data.assign(pgm.pixels.size(), -1);
  for (int row = 0; row < pgm.height; ++row) {
    for (int col = 0; col < pgm.width; ++col) {
      const double v = pgm.pixels[static_cast<std::size_t>(row) * pgm.width + col] / static_cast<double>(pgm.max_value);
      const double p = negate != 0 ? v : 1.0 - v;  // occupancy probability (dark = occupied)
      const std::int8_t cell = p > occupied ? 100 : (p < free ? 0 : -1);
      out.data[static_cast<std::size_t>(pgm.height - 1 - row) * pgm.width + col] = cell;
    }
  }
  return true;
}

bool read_scenario_grid(yaml_fields::MapReader& parent, const std::string& base_dir, const RequestLimits& limits,
                        OccupancyGrid& out) {
  yaml_fields::MapReader r(parent.get("grid"), "grid", parent.problems());
  if (!r.valid()) return false;
  auto& problems = r.problems();
  const std::size_t before = problems.size();
  if (r.has("map")) {
    std::string file;
    r.read("map", file);
    r.finish();
    std::filesystem::path path(file);
    if (path.is_relative()) path = std::filesystem::path(base_dir) / path;
    return load_map_server_grid(path.string(), "grid.map", limits, out, problems);
  }
  double resolution = 0.2;
  r.read("resolution", resolution);
  if (!resolution_ok(resolution)) problems.push_back("grid.resolution: " + resolution_range());
  Pose2 origin;
  {
    yaml_fields::MapReader o(r.get("origin"), "grid.origin", problems);
    if (o.valid()) {
      o.read("x", origin.x);
      o.read("y", origin.y);
      double yaw_deg = 0.0;
      if (o.read("yaw_deg", yaw_deg)) origin.yaw = yaw_deg * kDegToRad;
      o.read("yaw", origin.yaw);
      o.finish();
    }
  }
  const YAML::Node size = r.get("size");
  double w = 0.0, h = 0.0;
  // A missing key gives an invalid node, on which IsSequence() throws: IsDefined() first.
  if (!size.IsDefined() || !size.IsSequence() || size.size() != 2) {
    problems.push_back("grid.size: required, [width, height] [m]");
  } else {
    w = yaml_fields::to_double(size[0], "grid.size[0]", problems).value_or(0.0);
    h = yaml_fields::to_double(size[1], "grid.size[1]", problems).value_or(0.0);
  }
  std::vector<Polygon> shapes;
  std::vector<std::string> shape_paths;  // the key path of each shape, for problems
  const YAML::Node listed = r.get("obstacles");
  const YAML::Node obstacles = listed.IsDefined() ? listed : YAML::Node(YAML::NodeType::Sequence);
  if (!obstacles.IsSequence()) problems.push_back("grid.obstacles: expected a list");
  // As many shapes and points as a request's objects may have (max_objects, max_polygon_points):
  // drawing costs each shape's area in cells, and 50,000 boxes took over a minute and 2.4 GB.
  if (obstacles.IsSequence() && obstacles.size() > limits.max_objects) {
    problems.push_back("grid.obstacles: " + std::to_string(obstacles.size()) + " shapes exceed the limit of " +
                       std::to_string(limits.max_objects) + " (service.limits.max_objects)");
    return false;
  }
  for (std::size_t i = 0; obstacles.IsSequence() && i < obstacles.size(); ++i) {
    const std::string path = yaml_fields::indexed("grid.obstacles", i);
    yaml_fields::MapReader b(obstacles[i], path, problems);
    if (!b.valid()) continue;
    if (b.has("polygon")) {
      Polygon poly;
      const YAML::Node pts = b.get("polygon");
      if (pts.IsSequence() && pts.size() > limits.max_polygon_points) {
        problems.push_back(path + ".polygon: " + std::to_string(pts.size()) + " points exceed the limit of " +
                           std::to_string(limits.max_polygon_points) + " (service.limits.max_polygon_points)");
        continue;
      }
      for (std::size_t k = 0; pts.IsSequence() && k < pts.size(); ++k) {
        if (!pts[k].IsSequence() || pts[k].size() != 2) {
          problems.push_back(yaml_fields::indexed(path + ".polygon", k) + ": expected [x, y]");
          continue;
        }
        const std::string point = yaml_fields::indexed(path + ".polygon", k);
        const auto x = yaml_fields::to_double(pts[k][0], point + ".x", problems);
        const auto y = yaml_fields::to_double(pts[k][1], point + ".y", problems);
        if (x) check_extent(*x, point + ".x", "|x| ", limits, problems);
        if (y) check_extent(*y, point + ".y", "|y| ", limits, problems);
        if (x && y) poly.push_back({*x, *y});
      }
      if (poly.size() < 3) problems.push_back(path + ".polygon: needs at least 3 points");
      shapes.push_back(poly);
      shape_paths.push_back(path + ".polygon");
    } else {
      Object box;
      b.read("x", box.pose.x);
      b.read("y", box.pose.y);
      double yaw_deg = 0.0;
      if (b.read("yaw_deg", yaw_deg)) box.pose.yaw = yaw_deg * kDegToRad;
      b.read("length", box.length_m);
      b.read("width", box.width_m);
      if (!(box.length_m > 0.0 && box.width_m > 0.0)) problems.push_back(path + ": length and width must be > 0");
      check_extent(box.pose.x, path + ".x", "|x| ", limits, problems);
      check_extent(box.pose.y, path + ".y", "|y| ", limits, problems);
      check_extent(box.length_m, path + ".length", "", limits, problems);
      check_extent(box.width_m, path + ".width", "", limits, problems);
      shapes.push_back(object_polygon(box));
      std::ostringstream where;
      where << path << " (at x " << box.pose.x << ", y " << box.pose.y << ")";
      shape_paths.push_back(where.str());
    }
    b.finish();
  }
  r.finish();
  if (problems.size() != before) return false;
  // Cell counts in double: a size of any magnitude is checked before it becomes an int.
  const double cells_x = std::ceil(w / resolution - 1e-9);
  const double cells_y = std::ceil(h / resolution - 1e-9);
  if (!(cells_x >= 1.0 && cells_y >= 1.0 && cells_x * cells_y <= static_cast<double>(limits.max_grid_cells))) {
    std::ostringstream os;
    os << "grid.size: must give 1 to " << cell_limit(limits.max_grid_cells) << ", got " << cells_x << " x " << cells_y;
    const double cells = cells_x * cells_y;  // (NaN, negative or huge for a bad size: no product then)
    if (cells >= 0.0 && cells < 1e15) os << " = " << static_cast<long long>(cells);
    problems.push_back(os.str());
    return false;
  }
  const int cw = static_cast<int>(cells_x);
  const int ch = static_cast<int>(cells_y);
  Costmap raster(origin, resolution, cw, ch, {});
  // An obstacle that does not reach into the grid cannot be meant (a typo, wrong units, a
  // coordinate like 1e300): rejected rather than silently dropped.
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    Aabb box;
    for (const Vec2& p : shapes[k]) box.extend(raster.to_grid(p));
    const bool meets = box.min.x() <= cw && box.max.x() >= 0.0 && box.min.y() <= ch && box.max.y() >= 0.0;
    if (!meets) {
      std::ostringstream os;
      os << shape_paths[k] << ": lies entirely outside the grid (" << w << " x " << h << " m from its origin)";
      problems.push_back(os.str());
    }
  }
  if (problems.size() != before) return false;
  // Drawing costs the shapes' area in cells: within the limits above, 512 polygons zigzagging
  // across 16 Mi cells still took 29 s and 640 MB. The file is refused past kDrawBudgetMs instead.
  raster.add_obstacles(shapes, StopCondition::after_ms(kDrawBudgetMs));
  if (raster.stopped() != StopReason::kNone) {
    std::ostringstream os;
    os << "grid.obstacles: drawing them on " << cw << " x " << ch << " cells took longer than "
       << kDrawBudgetMs / 1000.0 << " s (fewer or smaller shapes, or larger cells)";
    problems.push_back(os.str());
    return false;
  }
  out.resolution_m = resolution;
  out.origin = origin;
  out.width = static_cast<std::uint32_t>(cw);
  out.height = static_cast<std::uint32_t>(ch);
  out.data.assign(static_cast<std::size_t>(cw) * ch, 0);
  for (int j = 0; j < ch; ++j) {
    for (int i = 0; i < cw; ++i) out.data[static_cast<std::size_t>(j) * cw + i] = raster.occupied(i, j) ? 100 : 0;
  }
  return true;
}

}  // namespace pullout
