// Lanelet2 OSM reading (see osm_loader.hpp). pugixml and GeographicLib stay inside this file.
#include "pullout/maps/osm_loader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <GeographicLib/LocalCartesian.hpp>
#include <pugixml.hpp>

namespace pullout {

namespace {

constexpr double kKmhToMps = 1.0 / 3.6;
constexpr double kMphToMps = 0.44704;
constexpr double kDefaultSpeedLimitMps = 50.0 * kKmhToMps;  // Lanelet2's urban default
constexpr std::size_t kMaxProblemsListed = 100;             // a broken file can have thousands

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::optional<double> parse_double(std::string_view s) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_id(std::string_view s) {
  s = trim(s);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

// "30" (km/h), "30 km/h", "20 mph", "8.3 m/s" -> m/s.
std::optional<double> parse_speed_limit(std::string_view text) {
  std::string_view s = trim(text);
  std::size_t n = 0;
  while (n < s.size() && (std::isdigit(static_cast<unsigned char>(s[n])) || s[n] == '.' || s[n] == '-' || s[n] == '+' ||
                          s[n] == 'e' || s[n] == 'E')) {
    ++n;
  }
  const auto value = parse_double(s.substr(0, n));
  if (!value) return std::nullopt;
  const std::string_view unit = trim(s.substr(n));
  double mps = 0.0;
  if (unit.empty() || unit == "km/h" || unit == "kmh" || unit == "kph") {
    mps = *value * kKmhToMps;
  } else if (unit == "mph") {
    mps = *value * kMphToMps;
  } else if (unit == "m/s" || unit == "mps") {
    mps = *value;
  } else {
    return std::nullopt;
  }
  if (!(mps > 0.0)) return std::nullopt;
  return mps;
}

struct RawNode {
  double local_x{0.0};
  double local_y{0.0};
  double lat{0.0};
  double lon{0.0};
  bool has_local{false};
  bool has_geo{false};
  Point2 xy;  // in the map frame, set once the frame is decided
};

struct RawWay {
  std::vector<std::int64_t> nodes;
};

// Line numbers of byte offsets, for messages.
class LineIndex {
 public:
  explicit LineIndex(const std::string& text) {
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] == '\n') newlines_.push_back(i);
    }
  }
  std::size_t line_of(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    return static_cast<std::size_t>(
               std::lower_bound(newlines_.begin(), newlines_.end(), static_cast<std::size_t>(offset)) -
               newlines_.begin()) +
           1;
  }

 private:
  std::vector<std::size_t> newlines_;
};

class Loader {
 public:
  Loader(const std::string& xml, std::string source) : xml_(xml), source_(std::move(source)), lines_(xml) {}

  std::shared_ptr<const LaneletMap> load() {
    pugi::xml_document doc;
    const pugi::xml_parse_result parsed = doc.load_buffer(xml_.data(), xml_.size(), pugi::parse_default);
    if (!parsed) {
      fail({"line " + std::to_string(lines_.line_of(parsed.offset)) + ": not valid XML: " + parsed.description()});
    }
    const pugi::xml_node root = doc.child("osm");
    if (!root) fail({"no <osm> root element: not an OSM file"});

    read_nodes(root);
    read_ways(root);
    decide_frame();
    std::vector<Lanelet> lanelets = read_lanelets(root);
    if (lanelets.empty() && problems_.empty()) problems_.push_back("no lanelet (a relation with type=lanelet)");
    if (!problems_.empty()) fail(std::move(problems_));
    return std::make_shared<const LaneletMap>(std::move(lanelets));
  }

 private:
  [[noreturn]] void fail(std::vector<std::string> problems) const { throw MapLoadError(source_, std::move(problems)); }

  std::string where(const pugi::xml_node& n) const {
    return " (line " + std::to_string(lines_.line_of(n.offset_debug())) + ")";
  }

  void problem(std::string text) {
    if (problems_.size() < kMaxProblemsListed)
      problems_.push_back(std::move(text));
    else
      ++problems_beyond_;
  }

  void read_nodes(const pugi::xml_node& root) {
    for (const pugi::xml_node& n : root.children("node")) {
      const auto id = parse_id(n.attribute("id").value());
      if (!id) {
        problem(std::string("node") + where(n) + ": id '" + n.attribute("id").value() + "' is not an integer");
        continue;
      }
      RawNode node;
      const pugi::xml_attribute lat = n.attribute("lat");
      const pugi::xml_attribute lon = n.attribute("lon");
      if (lat && lon) {
        const auto la = parse_double(lat.value());
        const auto lo = parse_double(lon.value());
        if (la && lo && std::abs(*la) <= 90.0 && std::abs(*lo) <= 180.0) {
          node.lat = *la;
          node.lon = *lo;
          node.has_geo = true;
        }
      }
      std::optional<double> x;
      std::optional<double> y;
      for (const pugi::xml_node& tag : n.children("tag")) {
        const std::string_view k = tag.attribute("k").value();
        if (k != "local_x" && k != "local_y") continue;
        const auto v = parse_double(tag.attribute("v").value());
        if (!v) {
          problem("node " + std::to_string(*id) + where(n) + ": " + std::string(k) + " '" + tag.attribute("v").value() +
                  "' is not a number");
          continue;
        }
        if (std::abs(*v) > kMaxMapCoordinateM) {
          std::ostringstream os;
          os << "node " << *id << where(n) << ": " << k << " " << *v << " exceeds " << kMaxMapCoordinateM << " m";
          problem(os.str());
          continue;
        }
        (k == "local_x" ? x : y) = v;
      }
      if (x && y) {
        node.local_x = *x;
        node.local_y = *y;
        node.has_local = true;
      }
      if (!nodes_.emplace(*id, node).second) {
        problem("node " + std::to_string(*id) + where(n) + ": duplicate node id");
        continue;
      }
      if (!first_geo_node_ && node.has_geo) first_geo_node_ = *id;
      all_local_ = all_local_ && node.has_local;
    }
  }

  void read_ways(const pugi::xml_node& root) {
    for (const pugi::xml_node& w : root.children("way")) {
      const auto id = parse_id(w.attribute("id").value());
      if (!id) {
        problem(std::string("way") + where(w) + ": id '" + w.attribute("id").value() + "' is not an integer");
        continue;
      }
      RawWay way;
      bool ok = true;
      for (const pugi::xml_node& nd : w.children("nd")) {
        const auto ref = parse_id(nd.attribute("ref").value());
        if (!ref) {
          ok = false;
          continue;
        }
        way.nodes.push_back(*ref);
      }
      if (!ok) bad_ways_.insert(*id);
      if (!ways_.emplace(*id, std::move(way)).second)
        problem("way " + std::to_string(*id) + where(w) + ": duplicate way id");
    }
  }

  // local_x/local_y when every node has them; otherwise lat/lon projected around the first node.
  void decide_frame() {
    if (all_local_ && !nodes_.empty()) {
      for (auto& [id, node] : nodes_) node.xy = {node.local_x, node.local_y};
      return;
    }
    projected_ = true;
    if (!first_geo_node_) return;  // every lanelet's bounds will report their nodes
    const RawNode& origin = nodes_.at(*first_geo_node_);
    const GeographicLib::LocalCartesian projection(origin.lat, origin.lon, 0.0);
    for (auto& [id, node] : nodes_) {
      if (!node.has_geo) continue;
      double x = 0.0;
      double y = 0.0;
      double z = 0.0;
      projection.Forward(node.lat, node.lon, 0.0, x, y, z);
      if (std::abs(x) > kMaxMapCoordinateM || std::abs(y) > kMaxMapCoordinateM) {
        std::ostringstream os;
        os << "node " << id << ": lat/lon projects to (" << x << ", " << y << ") m, beyond " << kMaxMapCoordinateM
           << " m of the first node";
        problem(os.str());
        continue;
      }
      node.xy = {x, y};
    }
  }

  // The points of way `way_id` as one bound of lanelet `ll`, or nullopt after recording a problem.
  std::optional<LaneletBound> read_bound(std::int64_t ll, const char* role, std::int64_t way_id) {
    const std::string what = "lanelet " + std::to_string(ll) + ": " + role + " way " + std::to_string(way_id);
    const auto it = ways_.find(way_id);
    if (it == ways_.end()) {
      problem(what + " is not in the file");
      return std::nullopt;
    }
    if (bad_ways_.count(way_id) != 0) {
      problem(what + " has a node reference that is not an integer");
      return std::nullopt;
    }
    LaneletBound bound;
    bound.way_id = way_id;
    for (std::int64_t ref : it->second.nodes) {
      const auto n = nodes_.find(ref);
      if (n == nodes_.end()) {
        problem(what + ": node " + std::to_string(ref) + " is not in the file");
        return std::nullopt;
      }
      if (projected_ && !n->second.has_geo) {
        problem(what + ": node " + std::to_string(ref) + " has neither local_x/local_y nor lat/lon");
        return std::nullopt;
      }
      const Point2 p = n->second.xy;
      // Repeated points carry no direction: keep the first.
      if (!bound.points.empty() && bound.points.back().x == p.x && bound.points.back().y == p.y) continue;
      if (bound.points.empty()) bound.front_node = ref;
      bound.back_node = ref;
      bound.points.push_back(p);
    }
    if (bound.points.size() < 2) {
      problem(what + " has fewer than 2 distinct points");
      return std::nullopt;
    }
    return bound;
  }

  std::vector<Lanelet> read_lanelets(const pugi::xml_node& root) {
    std::vector<Lanelet> out;
    std::unordered_set<std::int64_t> relation_ids;
    for (const pugi::xml_node& r : root.children("relation")) {
      const auto id = parse_id(r.attribute("id").value());
      if (!id) {
        problem(std::string("relation") + where(r) + ": id '" + r.attribute("id").value() + "' is not an integer");
        continue;
      }
      if (!relation_ids.insert(*id).second) {
        problem("relation " + std::to_string(*id) + where(r) + ": duplicate relation id");
        continue;
      }
      std::unordered_map<std::string, std::string> tags;
      for (const pugi::xml_node& tag : r.children("tag")) tags[tag.attribute("k").value()] = tag.attribute("v").value();
      const auto type = tags.find("type");
      if (type == tags.end() || type->second != "lanelet") continue;
      if (auto ll = read_lanelet(*id, r, tags)) out.push_back(std::move(*ll));
    }
    if (problems_beyond_ > 0) problems_.push_back("... " + std::to_string(problems_beyond_) + " more not listed");
    return out;
  }

  std::optional<Lanelet> read_lanelet(std::int64_t id, const pugi::xml_node& r,
                                      const std::unordered_map<std::string, std::string>& tags) {
    const std::string name = "lanelet " + std::to_string(id);
    const std::size_t before = problems_.size() + problems_beyond_;
    Lanelet ll;
    ll.id = id;
    std::vector<std::int64_t> left;
    std::vector<std::int64_t> right;
    std::vector<std::int64_t> center;
    for (const pugi::xml_node& m : r.children("member")) {
      const std::string_view role = m.attribute("role").value();
      std::vector<std::int64_t>* slot = role == "left"         ? &left
                                        : role == "right"      ? &right
                                        : role == "centerline" ? &center
                                                               : nullptr;
      if (slot == nullptr) continue;  // regulatory elements and other members
      if (std::string_view(m.attribute("type").value()) != "way") {
        problem(name + where(r) + ": member '" + std::string(role) + "' must be a way, is a " +
                m.attribute("type").value());
        continue;
      }
      const auto ref = parse_id(m.attribute("ref").value());
      if (!ref) {
        problem(name + where(r) + ": member '" + std::string(role) + "' ref '" + m.attribute("ref").value() +
                "' is not an integer");
        continue;
      }
      slot->push_back(*ref);
    }
    for (const auto& [role, refs] :
         {std::pair<const char*, const std::vector<std::int64_t>*>{"left", &left}, {"right", &right}}) {
      if (refs->size() != 1) {
        problem(name + where(r) + ": needs exactly one '" + role + "' way member, has " + std::to_string(refs->size()));
      }
    }
    if (center.size() > 1) problem(name + where(r) + ": more than one 'centerline' member");
    if (left.size() == 1 && right.size() == 1) {
      auto l = read_bound(id, "left", left.front());
      auto rb = read_bound(id, "right", right.front());
      if (l && rb) {
        ll.left = std::move(*l);
        ll.right = std::move(*rb);
      }
    }
    if (center.size() == 1) {
      if (auto c = read_bound(id, "centerline", center.front())) ll.centerline = std::move(c->points);
    }

    const auto subtype = tags.find("subtype");
    ll.subtype_name = subtype == tags.end() ? "road" : subtype->second;
    ll.subtype = ll.subtype_name == "road"            ? LaneletSubtype::kRoad
                 : ll.subtype_name == "road_shoulder" ? LaneletSubtype::kRoadShoulder
                                                      : LaneletSubtype::kOther;
    ll.speed_limit_mps = kDefaultSpeedLimitMps;
    if (const auto it = tags.find("speed_limit"); it != tags.end()) {
      if (const auto v = parse_speed_limit(it->second)) {
        ll.speed_limit_mps = *v;
      } else {
        problem(name + where(r) + ": speed_limit '" + it->second +
                "' is not a positive speed (a number in km/h, or with km/h, mph or m/s)");
      }
    }
    if (const auto it = tags.find("turn_direction"); it != tags.end()) {
      if (it->second == "straight") {
        ll.turn_direction = TurnDirection::kStraight;
      } else if (it->second == "left") {
        ll.turn_direction = TurnDirection::kLeft;
      } else if (it->second == "right") {
        ll.turn_direction = TurnDirection::kRight;
      } else {
        problem(name + where(r) + ": turn_direction '" + it->second + "' (expected straight, left or right)");
      }
    }
    if (problems_.size() + problems_beyond_ != before) return std::nullopt;
    return ll;
  }

  const std::string& xml_;
  std::string source_;
  LineIndex lines_;
  std::unordered_map<std::int64_t, RawNode> nodes_;
  std::unordered_map<std::int64_t, RawWay> ways_;
  std::unordered_set<std::int64_t> bad_ways_;
  std::optional<std::int64_t> first_geo_node_;
  bool all_local_{true};
  bool projected_{false};  // the nodes had no local_x/local_y: lat/lon were projected
  std::vector<std::string> problems_;
  std::size_t problems_beyond_{0};
};

std::string one_line(const std::string& source, const std::vector<std::string>& problems) {
  std::string out = source + ": " + (problems.empty() ? std::string("invalid map") : problems.front());
  if (problems.size() > 1) out += " (and " + std::to_string(problems.size() - 1) + " more problems)";
  return out;
}

}  // namespace

MapLoadError::MapLoadError(const std::string& source, std::vector<std::string> problems)
    : std::runtime_error(one_line(source, problems)), problems_(std::move(problems)) {}

std::shared_ptr<const LaneletMap> parse_lanelet_map(const std::string& xml, const std::string& source) {
  return Loader(xml, source).load();
}

std::shared_ptr<const LaneletMap> load_lanelet_map(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw MapLoadError(path, {"is a directory, not an OSM file"});
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MapLoadError(path, {"cannot read file"});
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw MapLoadError(path, {"cannot read file"});
  return parse_lanelet_map(content.str(), path);
}

}  // namespace pullout
