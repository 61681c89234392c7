#include "config/yaml_fields.hpp"

#include <cmath>
#include <limits>
#include <utility>

namespace pullout::yaml_fields {
namespace {

// A short rendering of a node for messages: the scalar itself, or its kind.
std::string describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Undefined:
      return "nothing";
    case YAML::NodeType::Null:
      return "null";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Scalar:
      break;
  }
  constexpr std::size_t kMaxShown = 40;
  const std::string& s = node.Scalar();
  return "'" + (s.size() > kMaxShown ? s.substr(0, kMaxShown) + "..." : s) + "'";
}

void expected(const YAML::Node& node, const std::string& path, const std::string& what, Problems& problems) {
  problems.push_back(path + ": expected " + what + ", got " + describe(node) + where(node));
}

}  // namespace

std::string where(const YAML::Node& node) {
  if (!node.IsDefined()) return "";
  const YAML::Mark mark = node.Mark();
  if (mark.is_null() || mark.line < 0) return "";
  return " (line " + std::to_string(mark.line + 1) + ")";
}

std::string indexed(const std::string& base, std::size_t i) { return base + "[" + std::to_string(i) + "]"; }

std::optional<double> to_double(const YAML::Node& node, const std::string& path, Problems& problems) {
  double v = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v)) {
    expected(node, path, "a number", problems);
    return std::nullopt;
  }
  if (!std::isfinite(v)) {
    problems.push_back(path + ": must be a finite number, got " + describe(node) + where(node));
    return std::nullopt;
  }
  return v;
}

std::optional<std::int64_t> to_int(const YAML::Node& node, const std::string& path, Problems& problems) {
  long long v = 0;
  if (!node.IsScalar() || !YAML::convert<long long>::decode(node, v)) {
    expected(node, path, "an integer", problems);
    return std::nullopt;
  }
  return static_cast<std::int64_t>(v);
}

std::optional<bool> to_bool(const YAML::Node& node, const std::string& path, Problems& problems) {
  bool v = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, v)) {
    expected(node, path, "true or false", problems);
    return std::nullopt;
  }
  return v;
}

std::optional<std::string> to_string(const YAML::Node& node, const std::string& path, Problems& problems) {
  if (!node.IsScalar()) {
    expected(node, path, "a string", problems);
    return std::nullopt;
  }
  return node.Scalar();
}

namespace {
bool absent(const YAML::Node& node) { return !node.IsDefined() || node.IsNull(); }
}  // namespace

// Note: YAML::Node's assignment writes through to the referenced node, so node_ is only ever
// initialised, never assigned.
MapReader::MapReader(const YAML::Node& node, std::string path, Problems& problems)
    : node_(absent(node) ? YAML::Node(YAML::NodeType::Map) : node), path_(std::move(path)), problems_(problems) {
  if (!node_.IsMap()) {
    expected(node_, path_.empty() ? std::string("document") : path_, "a mapping", problems_);
    valid_ = false;
    return;
  }
  // yaml-cpp keeps both entries of a repeated key and lookups see the first: say so rather than
  // silently ignoring the second.
  std::set<std::string> seen;
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) {
      problems_.push_back(key_path("?") + ": keys must be plain names" + where(entry.first));
      continue;
    }
    if (!seen.insert(entry.first.Scalar()).second) {
      problems_.push_back(key_path(entry.first.Scalar()) + ": duplicate key" + where(entry.first));
    }
  }
}

std::string MapReader::key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

bool MapReader::has(const std::string& key) const {
  if (!valid_) return false;
  const YAML::Node& map = node_;
  return map[key].IsDefined();
}

YAML::Node MapReader::get(const std::string& key) {
  known_.insert(key);
  if (!valid_) return YAML::Node();
  const YAML::Node& map = node_;
  return map[key];
}

bool MapReader::read(const std::string& key, double& out) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return false;
  const auto v = to_double(n, key_path(key), problems_);
  if (v) out = *v;
  return v.has_value();
}

bool MapReader::read(const std::string& key, std::int64_t& out) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return false;
  const auto v = to_int(n, key_path(key), problems_);
  if (v) out = *v;
  return v.has_value();
}

bool MapReader::read(const std::string& key, int& out) {
  std::int64_t v = out;
  if (!read(key, v)) return false;
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    problems_.push_back(key_path(key) + ": out of range, got " + std::to_string(v) + where(get(key)));
    return false;
  }
  out = static_cast<int>(v);
  return true;
}

bool MapReader::read(const std::string& key, std::size_t& out) {
  std::int64_t v = 0;
  if (!read(key, v)) return false;
  if (v < 0) {
    problems_.push_back(key_path(key) + ": must be >= 0, got " + std::to_string(v) + where(get(key)));
    return false;
  }
  out = static_cast<std::size_t>(v);
  return true;
}

bool MapReader::read(const std::string& key, bool& out) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return false;
  const auto v = to_bool(n, key_path(key), problems_);
  if (v) out = *v;
  return v.has_value();
}

bool MapReader::read(const std::string& key, std::string& out) {
  const YAML::Node n = get(key);
  if (!n.IsDefined()) return false;
  const auto v = yaml_fields::to_string(n, key_path(key), problems_);
  if (v) out = *v;
  return v.has_value();
}

void MapReader::finish(const char* (*hint)(const std::string& key)) {
  if (!valid_) return;
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) continue;  // reported by the constructor
    const std::string& key = entry.first.Scalar();
    if (known_.count(key) != 0) continue;
    const char* extra = hint != nullptr ? hint(key) : nullptr;
    problems_.push_back(key_path(key) + ": " + (extra != nullptr ? extra : "unknown key") + where(entry.first));
  }
}

}  // namespace pullout::yaml_fields
