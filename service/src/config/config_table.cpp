// Allowed values, value encoding and rendering of the config tables (see config_table.hpp).
#include "config/config_table.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string_view>

#include "config/config_detail.hpp"
#include "pullout/model/names.hpp"

namespace pullout::config_table {
namespace {

// Bounds in messages: up to 15 significant digits, so that 16777216 is not "1.67772e+07".
std::string bound_text(double v) {
  std::ostringstream out;
  out << std::setprecision(15) << v;
  return out.str();
}

bool inside(const Range& r, double v) {
  if (r.lo && (r.lo_open ? !(v > *r.lo) : v < *r.lo)) return false;
  if (r.hi && (r.hi_open ? !(v < *r.hi) : v > *r.hi)) return false;
  return true;
}

void check_number(const Range& r, double v, const std::string& shown, const std::string& path, const std::string& at,
                  Problems& out) {
  if (!std::isfinite(v)) {
    out.push_back(path + ": must be a finite number, got " + shown + at);
    return;
  }
  if (inside(r, v)) return;
  out.push_back(path + ": must be " + describe(r) + ", got " + shown + at);
}

// "SHIFT, GEOMETRIC, CLOTHOID or FREESPACE"
std::string search_planner_names() {
  std::string names;
  for (std::size_t i = 0; i < kSearchPlanners.size(); ++i) {
    if (i > 0) names += i + 1 == kSearchPlanners.size() ? " or " : ", ";
    names += encode(std::vector<PlannerType>{kSearchPlanners[i]}).substr(1);
    names.pop_back();
  }
  return names;
}

constexpr std::array<std::pair<ExtendedPolygonPolicy, const char*>, 2> kPolygonPolicyNames{{
    {ExtendedPolygonPolicy::kAlongPath, "along_path"},
    {ExtendedPolygonPolicy::kRectangle, "rectangle"},
}};

// A YAML plain scalar that reads back as this string (not a number, boolean or null).
bool plain_safe(const std::string& s) {
  if (s.empty()) return false;
  for (const char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '.' || c == '/' || c == '-';
    if (!ok) return false;
  }
  double d = 0.0;
  bool b = false;
  const YAML::Node n(s);
  return !(YAML::convert<double>::decode(n, d) || YAML::convert<bool>::decode(n, b) || s == "null" || s == "~");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// allowed values

std::string describe(const Range& r) {
  if (r.lo && r.hi) {
    return std::string("in ") + (r.lo_open ? "(" : "[") + bound_text(*r.lo) + ", " + bound_text(*r.hi) +
           (r.hi_open ? ")" : "]");
  }
  if (r.lo) return (r.lo_open ? "> " : ">= ") + bound_text(*r.lo);
  if (r.hi) return (r.hi_open ? "< " : "<= ") + bound_text(*r.hi);
  return "";
}

std::string describe(const NumberList& l) {
  std::string items = std::to_string(l.min_items) + " to " + std::to_string(l.max_items) + " values";
  const std::string each = describe(l.each);
  return each.empty() ? items : items + ", each " + each;
}

std::string describe(const Choices& c) {
  std::string s = "one of ";
  for (std::size_t i = 0; i < c.names.size(); ++i) s += (i > 0 ? ", " : "") + c.names[i];
  return s;
}

std::string describe(const NonEmpty&) { return "not empty"; }
std::string describe(const AnyValue&) { return ""; }
std::string describe(const PlannerList&) { return "each once, of " + search_planner_names(); }

void check_value(const Range& r, double v, const std::string& path, const std::string& at, Problems& out) {
  check_number(r, v, format_number(v), path, at, out);
}

void check_value(const Range& r, int v, const std::string& path, const std::string& at, Problems& out) {
  check_number(r, static_cast<double>(v), std::to_string(v), path, at, out);
}

void check_value(const Range& r, std::size_t v, const std::string& path, const std::string& at, Problems& out) {
  check_number(r, static_cast<double>(v), std::to_string(v), path, at, out);
}

void check_value(const NumberList& l, const std::vector<double>& v, const std::string& path, const std::string& at,
                 Problems& out) {
  if (v.size() < l.min_items || v.size() > l.max_items) {
    out.push_back(path + ": must list " + std::to_string(l.min_items) + " to " + std::to_string(l.max_items) +
                  " values, got " + std::to_string(v.size()) + at);
  }
  for (std::size_t i = 0; i < v.size(); ++i) check_value(l.each, v[i], yaml_fields::indexed(path, i), at, out);
}

void check_value(const Choices& c, const std::string& v, const std::string& path, const std::string& at,
                 Problems& out) {
  if (std::find(c.names.begin(), c.names.end(), v) != c.names.end()) return;
  out.push_back(path + ": unknown value '" + v + "' (expected " + describe(c).substr(7) + ")" + at);
}

void check_value(const NonEmpty&, const std::string& v, const std::string& path, const std::string& at, Problems& out) {
  if (v.empty()) out.push_back(path + ": must not be empty" + at);
}

void check_value(const PlannerList&, const std::vector<PlannerType>& v, const std::string& path, const std::string& at,
                 Problems& out) {
  if (v.empty()) out.push_back(path + ": must list at least one planner" + at);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string item = yaml_fields::indexed(path, i);
    if (!is_search_planner(v[i])) {
      out.push_back(item + ": '" + to_string(v[i]) + "' is not a planner that can be searched (expected " +
                    search_planner_names() + ")" + at);
    } else if (std::find(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v[i]) !=
               v.begin() + static_cast<std::ptrdiff_t>(i)) {
      out.push_back(item + ": planner '" + to_string(v[i]) + "' is listed twice" + at);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// reading

bool read_into(MapReader& r, const std::string& key, std::vector<double>& out) {
  const YAML::Node n = r.get(key);
  if (!n.IsDefined()) return false;
  const std::string path = r.key_path(key);
  if (!n.IsSequence()) {
    r.problems().push_back(path + ": expected a list of numbers, e.g. [1.0, 0.5]" + yaml_fields::where(n));
    return false;
  }
  std::vector<double> values;
  bool ok = true;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const auto v = yaml_fields::to_double(n[i], yaml_fields::indexed(path, i), r.problems());
    ok = ok && v.has_value();
    if (v) values.push_back(*v);
  }
  if (ok) out = std::move(values);
  return ok;
}

bool read_into(MapReader& r, const std::string& key, std::vector<PlannerType>& out) {
  const YAML::Node n = r.get(key);
  if (!n.IsDefined()) return false;
  const std::string path = r.key_path(key);
  if (!n.IsSequence()) {
    r.problems().push_back(path + ": expected a list of planner names, e.g. [SHIFT]" + yaml_fields::where(n));
    return false;
  }
  std::vector<PlannerType> planners;
  bool ok = true;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string item = yaml_fields::indexed(path, i);
    const auto name = yaml_fields::to_string(n[i], item, r.problems());
    if (!name) {
      ok = false;
      continue;
    }
    const auto planner = parse_planner_name(*name);
    if (!planner) {
      r.problems().push_back(item + ": unknown planner '" + *name + "' (expected " + search_planner_names() + ")" +
                             yaml_fields::where(n[i]));
      ok = false;
      continue;
    }
    planners.push_back(*planner);
  }
  if (ok) out = std::move(planners);
  return ok;
}

bool read_into(MapReader& r, const std::string& key, SearchPolicy& out) {
  std::string name;
  if (!r.read(key, name)) return false;
  if (const auto policy = search_policy_from_string(name)) {
    out = *policy;
    return true;
  }
  r.problems().push_back(r.key_path(key) + ": unknown policy '" + name + "' (expected " +
                         to_string(SearchPolicy::kPlannerPriority) + " or " +
                         to_string(SearchPolicy::kDistancePriority) + ")" + yaml_fields::where(r.get(key)));
  return false;
}

bool read_into(MapReader& r, const std::string& key, ExtendedPolygonPolicy& out) {
  std::string name;
  if (!r.read(key, name)) return false;
  for (const auto& [value, text] : kPolygonPolicyNames) {
    if (name == text) {
      out = value;
      return true;
    }
  }
  r.problems().push_back(r.key_path(key) + ": expected along_path or rectangle, got '" + name + "'" +
                         yaml_fields::where(r.get(key)));
  return false;
}

// ---------------------------------------------------------------------------------------------
// writing

std::string encode(double v) {
  // The shortest text that reads back as v; "1.0" rather than "1" so that it reads as a number
  // of the same kind a user would write.
  std::array<char, 32> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  std::string s(buf.data(), ec == std::errc() ? end : buf.data());
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

std::string encode(int v) { return std::to_string(v); }
std::string encode(std::size_t v) { return std::to_string(v); }
std::string encode(bool v) { return v ? "true" : "false"; }

std::string encode(const std::string& v) {
  if (plain_safe(v)) return v;
  std::string s = "\"";
  for (const char c : v) {
    if (c == '"' || c == '\\') s += '\\';
    s += c;
  }
  return s + "\"";
}

std::string encode(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i > 0 ? ", " : "") + encode(v[i]);
  return s + "]";
}

std::string encode(const std::vector<PlannerType>& v) {
  // Autoware's spelling (upper case); the model's lower-case names are accepted too.
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::string name = to_string(v[i]);
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    s += (i > 0 ? ", " : "") + name;
  }
  return s + "]";
}

std::string encode(SearchPolicy v) { return to_string(v); }

std::string encode(ExtendedPolygonPolicy v) {
  for (const auto& [value, text] : kPolygonPolicyNames) {
    if (value == v) return text;
  }
  return "invalid";
}

std::string field_comment(const std::string& unit, const std::string& comment, const std::string& allowed) {
  std::string s = unit.empty() ? "" : "[" + unit + "]";
  if (!comment.empty()) s += (s.empty() ? "" : " ") + comment;
  if (!allowed.empty()) s += (s.empty() ? "" : " ") + ("(" + allowed + ")");
  return s;
}

std::string render(const Doc& doc) {
  // Comments of a run of key lines at the same indentation start in one column (at most
  // kMaxColumn; a longer line gets its comment two spaces after it).
  constexpr std::size_t kMaxColumn = 48;
  std::string out;
  std::size_t i = 0;
  while (i < doc.size()) {
    std::size_t j = i;
    std::size_t width = 0;
    while (j < doc.size() && !doc[j].note && !doc[j].text.empty() && doc[j].indent == doc[i].indent) {
      const std::size_t w = static_cast<std::size_t>(doc[j].indent) + doc[j].text.size();
      if (w <= kMaxColumn) width = std::max(width, w);
      ++j;
    }
    if (j == i) j = i + 1;  // a note or a blank line
    for (std::size_t k = i; k < j; ++k) {
      const DocLine& l = doc[k];
      std::string line(static_cast<std::size_t>(l.indent), ' ');
      if (l.note) {
        line += l.text.empty() ? "#" : "# " + l.text;
      } else {
        line += l.text;
        if (!l.comment.empty()) {
          line.append(line.size() < width ? width - line.size() : 0, ' ');
          line += "  # " + l.comment;
        }
      }
      out += line + "\n";
    }
    i = j;
  }
  return out;
}

}  // namespace pullout::config_table
