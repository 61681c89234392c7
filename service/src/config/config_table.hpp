// The machinery of the config tables (the tables themselves are in config_tables.cpp).
//
// A Table<S> lists the keys of one YAML mapping that fills the plain struct S, in file order. An
// entry is a field (key, pointer to the member, unit, allowed values, comment), a group (a nested
// mapping filling a member struct, or more members of S itself), a note (comment lines of the
// documented file), an accepted-but-ignored key, or a reader with its own rule. The default of a
// key is never written in a table: it is the member's initialiser, read from a default-constructed
// struct when the documented file is written.
//
// One table drives:
//   read_table   YAML -> struct: wrong types, out-of-range values and unknown keys are reported,
//                one "<key path>: <problem> (line N)" each; a bad value leaves the member unchanged;
//   check_table  the allowed values of every member of a struct built in code;
//   write_table  the documented file (config/pullout.yaml is the output for Config{}).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "config/yaml_fields.hpp"
#include "pullout/model/types.hpp"
#include "pullout/safety/safety_parameters.hpp"

namespace pullout::config_table {

using yaml_fields::MapReader;
using yaml_fields::Problems;

// ---------------------------------------------------------------------------------------------
// Allowed values

// A number in [lo, hi]; either end may be open or absent. No ends: any finite number.
struct Range {
  std::optional<double> lo;
  std::optional<double> hi;
  bool lo_open{false};
  bool hi_open{false};
};
inline Range any_number() { return {}; }
inline Range at_least(double lo) { return {lo, std::nullopt, false, false}; }        // >= lo
inline Range above(double lo) { return {lo, std::nullopt, true, false}; }            // > lo
inline Range in(double lo, double hi) { return {lo, hi, false, false}; }             // [lo, hi]
inline Range in_open_closed(double lo, double hi) { return {lo, hi, true, false}; }  // (lo, hi]
inline Range in_closed_open(double lo, double hi) { return {lo, hi, false, true}; }  // [lo, hi)

// A list of numbers: min_items..max_items entries, each in `each`.
struct NumberList {
  std::size_t min_items;
  std::size_t max_items;
  Range each;
};

// One of the names (strings).
struct Choices {
  std::vector<std::string> names;
};

// A string that must not be empty.
struct NonEmpty {};

// Any value of the type (booleans, enumerations read by name).
struct AnyValue {};

// search_priority: at least one planner, each searchable (kSearchPlanners) and listed once.
struct PlannerList {};

// A message fragment for the documented file: "in [0.05, 10]", "> 0", "one of a, b", ...
std::string describe(const Range& r);
std::string describe(const NumberList& l);
std::string describe(const Choices& c);
std::string describe(const NonEmpty&);
std::string describe(const AnyValue&);
std::string describe(const PlannerList&);

// Appends "<path>: <problem><at>" for each value outside the allowed ones (`at` is " (line N)"
// when the value came from a file, or "").
void check_value(const Range& r, double v, const std::string& path, const std::string& at, Problems& out);
void check_value(const Range& r, int v, const std::string& path, const std::string& at, Problems& out);
void check_value(const Range& r, std::size_t v, const std::string& path, const std::string& at, Problems& out);
void check_value(const NumberList& l, const std::vector<double>& v, const std::string& path, const std::string& at,
                 Problems& out);
void check_value(const Choices& c, const std::string& v, const std::string& path, const std::string& at, Problems& out);
void check_value(const NonEmpty&, const std::string& v, const std::string& path, const std::string& at, Problems& out);
void check_value(const PlannerList&, const std::vector<PlannerType>& v, const std::string& path, const std::string& at,
                 Problems& out);
template <typename T>
void check_value(const AnyValue&, const T&, const std::string&, const std::string&, Problems&) {}

// ---------------------------------------------------------------------------------------------
// Values <-> YAML

// Reads `key` of `r` into `out` when present: true if present and of the right type (otherwise
// the problem is recorded and `out` is unchanged).
template <typename T>
bool read_into(MapReader& r, const std::string& key, T& out) {
  return r.read(key, out);  // the scalars: double, int, std::size_t, bool, std::string
}
bool read_into(MapReader& r, const std::string& key, std::vector<double>& out);
bool read_into(MapReader& r, const std::string& key, std::vector<PlannerType>& out);
bool read_into(MapReader& r, const std::string& key, SearchPolicy& out);
bool read_into(MapReader& r, const std::string& key, ExtendedPolygonPolicy& out);

// The value as written in the documented file (reads back to the same value).
std::string encode(double v);
std::string encode(int v);
std::string encode(std::size_t v);
std::string encode(bool v);
std::string encode(const std::string& v);
std::string encode(const std::vector<double>& v);
std::string encode(const std::vector<PlannerType>& v);
std::string encode(SearchPolicy v);
std::string encode(ExtendedPolygonPolicy v);

// ---------------------------------------------------------------------------------------------
// Tables

// One line of the documented file: "<indent><text>  # <comment>", or "<indent># <text>" for a note.
struct DocLine {
  int indent;
  std::string text;
  std::string comment;
  bool note;
};
using Doc = std::vector<DocLine>;

// Renders the lines, comments of neighbouring keys aligned.
std::string render(const Doc& doc);

// "<prefix>.<key>", or "<key>" when prefix is empty.
inline std::string join_path(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

using Hint = const char* (*)(const std::string& key);

template <typename S>
struct Entry {
  Entry() = default;
  // An entry of a base struct B of S (a member S inherits, e.g. StartPlannerParameters'
  // ExecutionParameters): &S::member names a member of B, so field() deduces Entry<B>.
  template <typename B, typename = std::enable_if_t<std::is_base_of_v<B, S> && !std::is_same_v<B, S>>>
  Entry(Entry<B> base) : key(std::move(base.key)), documented(base.documented) {  // NOLINT(google-explicit-constructor)
    if (base.read) read = [f = std::move(base.read)](MapReader& r, S& s) { f(r, s); };
    if (base.check)
      check = [f = std::move(base.check)](const S& s, const std::string& prefix, Problems& out) { f(s, prefix, out); };
    if (base.write) write = [f = std::move(base.write)](const S& s, int indent, Doc& out) { f(s, indent, out); };
  }

  std::string key;  // empty for a note
  bool documented{true};
  std::function<void(MapReader&, S&)> read;
  std::function<void(const S&, const std::string& prefix, Problems&)> check;
  std::function<void(const S&, int indent, Doc&)> write;
};

template <typename S>
struct Table {
  std::vector<Entry<S>> entries;
  Hint hint{nullptr};  // a clearer message than "unknown key" for some keys (Autoware's)
};

template <typename S>
void read_table(const Table<S>& table, MapReader& r, S& s) {
  for (const Entry<S>& e : table.entries) {
    if (e.read) e.read(r, s);
  }
  r.finish(table.hint);
}

template <typename S>
void check_table(const Table<S>& table, const S& s, const std::string& prefix, Problems& out) {
  for (const Entry<S>& e : table.entries) {
    if (e.check) e.check(s, prefix, out);
  }
}

template <typename S>
void write_table(const Table<S>& table, const S& s, int indent, Doc& out) {
  for (const Entry<S>& e : table.entries) {
    if (e.write) e.write(s, indent, out);
  }
}

// The comment of a field: "[unit] comment (allowed values)".
std::string field_comment(const std::string& unit, const std::string& comment, const std::string& allowed);

// A key of S: its YAML name, the member, the unit ("" for none), the allowed values, a comment.
template <typename S, typename T, typename C>
Entry<S> field(std::string key, T S::*member, const std::string& unit, C allowed, const std::string& comment) {
  Entry<S> e;
  e.key = key;
  e.read = [key, member, allowed](MapReader& r, S& s) {
    T v = s.*member;
    if (!read_into(r, key, v)) return;
    const std::size_t before = r.problems().size();
    check_value(allowed, v, r.key_path(key), yaml_fields::where(r.get(key)), r.problems());
    if (r.problems().size() == before) s.*member = std::move(v);
  };
  e.check = [key, member, allowed](const S& s, const std::string& prefix, Problems& out) {
    check_value(allowed, s.*member, join_path(prefix, key), "", out);
  };
  const std::string doc = field_comment(unit, comment, describe(allowed));
  e.write = [key, member, doc](const S& s, int indent, Doc& out) {
    out.push_back({indent, key + ": " + encode(s.*member), doc, false});
  };
  return e;
}

// A nested mapping `key` that fills the member struct `member` with its own table.
template <typename S, typename G>
Entry<S> group(std::string key, G S::*member, const Table<G>& (*table)(), const std::string& comment) {
  Entry<S> e;
  e.key = key;
  e.read = [key, member, table](MapReader& r, S& s) {
    MapReader sub(r.get(key), r.key_path(key), r.problems());
    if (sub.valid()) read_table(table(), sub, s.*member);
  };
  e.check = [key, member, table](const S& s, const std::string& prefix, Problems& out) {
    check_table(table(), s.*member, join_path(prefix, key), out);
  };
  e.write = [key, member, table, comment](const S& s, int indent, Doc& out) {
    out.push_back({indent, key + ":", comment, false});
    write_table(table(), s.*member, indent + 2, out);
  };
  return e;
}

// A nested mapping `key` whose keys are more members of S itself (YAML nests what the struct
// keeps flat, e.g. object_lane_configuration).
template <typename S>
Entry<S> group(std::string key, const Table<S>& (*table)(), const std::string& comment) {
  Entry<S> e;
  e.key = key;
  e.read = [key, table](MapReader& r, S& s) {
    MapReader sub(r.get(key), r.key_path(key), r.problems());
    if (sub.valid()) read_table(table(), sub, s);
  };
  e.check = [key, table](const S& s, const std::string& prefix, Problems& out) {
    check_table(table(), s, join_path(prefix, key), out);
  };
  e.write = [key, table, comment](const S& s, int indent, Doc& out) {
    out.push_back({indent, key + ":", comment, false});
    write_table(table(), s, indent + 2, out);
  };
  return e;
}

// Comment lines in the documented file ('\n' separates lines); `blank_before` adds an empty line.
template <typename S>
Entry<S> note(const std::string& text, bool blank_before = false) {
  Entry<S> e;
  e.write = [text, blank_before](const S&, int indent, Doc& out) {
    if (blank_before) out.push_back({0, "", "", false});
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t end = text.find('\n', start);
      const std::size_t stop = end == std::string::npos ? text.size() : end;
      out.push_back({indent, text.substr(start, stop - start), "", true});
      if (end == std::string::npos) break;
      start = end + 1;
    }
  };
  return e;
}

// A key that is accepted (type-checked as T) and has no effect: Autoware keys with no meaning
// here. Not in the documented file.
template <typename S, typename T>
Entry<S> ignored(std::string key) {
  Entry<S> e;
  e.key = key;
  e.documented = false;
  e.read = [key](MapReader& r, S&) {
    T v{};
    read_into(r, key, v);
  };
  return e;
}

// A key read by its own rule (an older Autoware name of another key). Not in the documented file.
template <typename S>
Entry<S> reader(std::string key, std::function<void(MapReader&, S&)> read) {
  Entry<S> e;
  e.key = std::move(key);
  e.documented = false;
  e.read = std::move(read);
  return e;
}

}  // namespace pullout::config_table

#include "pullout/config/config.hpp"

namespace pullout::config_table {

// The table of the whole config file (config_tables.cpp): the sections vehicle, start_planner,
// service, dds and map.
const Table<Config>& config_file_table();
// The sections that scenario files reuse (`vehicle:` and `planner:`).
const Table<VehicleInfo>& vehicle_table();
const Table<StartPlannerParameters>& start_planner_table();

}  // namespace pullout::config_table
