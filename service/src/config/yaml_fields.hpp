// Typed reading of YAML mappings with every problem collected, shared by the config and scenario
// loaders. A problem is one line "<key path>: <problem>"; the loaders prefix the file name.
//
// Values that fail to convert leave the destination unchanged (the struct default), so that one
// bad value produces exactly one problem and the rest of the file is still checked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace pullout::yaml_fields {

using Problems = std::vector<std::string>;

// " (line N)" for a node that came from a file, "" otherwise.
std::string where(const YAML::Node& node);

// "<base>[<i>]"
std::string indexed(const std::string& base, std::size_t i);

// Scalar conversions: the value, or nullopt after appending "<path>: expected ..." to problems.
// Numbers must be finite.
std::optional<double> to_double(const YAML::Node& node, const std::string& path, Problems& problems);
std::optional<std::int64_t> to_int(const YAML::Node& node, const std::string& path, Problems& problems);
std::optional<bool> to_bool(const YAML::Node& node, const std::string& path, Problems& problems);
std::optional<std::string> to_string(const YAML::Node& node, const std::string& path, Problems& problems);

// Reads the entries of one mapping. Every key that is read (or looked at with get()) counts as
// known; finish() reports the others as unknown. A mapping given more than once is a problem too.
class MapReader {
 public:
  // `path` is the key path of the mapping itself ("" for the document root). A null node is an
  // empty mapping; any other non-mapping is a problem and valid() returns false.
  MapReader(const YAML::Node& node, std::string path, Problems& problems);

  bool valid() const { return valid_; }
  const std::string& path() const { return path_; }
  Problems& problems() { return problems_; }
  // "<path>.<key>", or "<key>" at the root.
  std::string key_path(const std::string& key) const;

  bool has(const std::string& key) const;
  // The value of `key` (an undefined node when absent); marks the key as known.
  YAML::Node get(const std::string& key);

  // When `key` is present: converts it into `out` and returns true, or records a problem and
  // returns false (out unchanged). Absent: returns false, out unchanged.
  bool read(const std::string& key, double& out);
  bool read(const std::string& key, int& out);
  bool read(const std::string& key, std::int64_t& out);
  bool read(const std::string& key, std::size_t& out);
  bool read(const std::string& key, bool& out);
  bool read(const std::string& key, std::string& out);

  // Reports every key that was not read. `hint` (may be null) gives an extra explanation for a key,
  // or nullptr to use the plain "unknown key".
  void finish(const char* (*hint)(const std::string& key) = nullptr);

 private:
  YAML::Node node_;
  std::string path_;
  Problems& problems_;
  bool valid_{true};
  std::set<std::string> known_;
};

}  // namespace pullout::yaml_fields
