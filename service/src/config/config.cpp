// Loading and validation of config/pullout.yaml (see config.hpp).
#include "pullout/config/config.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>

#include <arpa/inet.h>
#include <yaml-cpp/yaml.h>

#include "config/config_detail.hpp"
#include "config/config_table.hpp"
#include "config/yaml_fields.hpp"
#include "pullout/model/names.hpp"

namespace pullout {
namespace {

using yaml_fields::MapReader;
using yaml_fields::Problems;

std::string join_lines(const std::string& file, const std::vector<std::string>& problems) {
  std::string out;
  for (const auto& p : problems) {
    if (!out.empty()) out += '\n';
    out.append(file).append(": ").append(p);
  }
  return out;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

void resolve_map(MapConfig& m, const std::filesystem::path& config_dir, Problems& problems) {
  if (m.path.empty()) return;
  std::filesystem::path file(m.path);
  if (file.is_relative()) file = config_dir / file;
  file = file.lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    problems.push_back("map.path: file not found: " + file.string());
    return;
  }
  m.path = file.string();
}

// Resolves service.state_dir relative to the config file (created by the service if missing).
void resolve_state_dir(ServiceConfig& s, const std::filesystem::path& config_dir) {
  if (s.state_dir.empty()) return;
  std::filesystem::path dir(s.state_dir);
  if (dir.is_relative()) dir = config_dir / dir;
  s.state_dir = dir.lexically_normal().string();
}

// Checks between keys of `service` (the table checks each key on its own).
void service_problems(const ServiceConfig& s, Problems& problems) {
  const double cap = s.limits.max_deadline_ms;
  if (s.default_deadline_ms > 0.0 && cap > 0.0 && s.default_deadline_ms > cap) {
    problems.push_back("service.default_deadline_ms: must be in (0, service.limits.max_deadline_ms = " +
                       format_number(cap) + "], got " + format_number(s.default_deadline_ms));
  }
}

// The metrics address must be an IPv4 address in dotted form (the HTTP server binds it as given).
void observability_problems(const ObservabilityConfig& o, Problems& problems) {
  in_addr parsed{};
  if (!o.metrics.address.empty() && inet_pton(AF_INET, o.metrics.address.c_str(), &parsed) != 1) {
    problems.push_back("observability.metrics.address: must be an IPv4 address such as 127.0.0.1, got '" +
                       o.metrics.address + "'");
  }
}

// Checks between keys of the whole config: the core's (start_planner) and the service's.
void cross_key_problems(const Config& config, Problems& problems) {
  append_parameter_issues(validate_parameters(config.start_planner), "start_planner", problems);
  service_problems(config.service, problems);
  observability_problems(config.observability, problems);
}

// Resolves dds.profiles_file relative to the config file; empty stays empty (the built-in
// profiles). `name` is what the problem names: the key, or the variable that set it.
void resolve_dds(DdsConfig& d, const std::filesystem::path& config_dir, const std::string& name, Problems& problems) {
  if (d.profiles_file.empty()) return;
  std::filesystem::path file(d.profiles_file);
  if (file.is_relative()) file = config_dir / file;
  file = file.lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    problems.push_back(name + ": file not found: " + file.string());
    return;
  }
  d.profiles_file = file.string();
}

// Resolves dds.security_dir relative to the config file and checks that it holds the five
// credential files (pullout/idl/security.hpp).
void resolve_security(DdsConfig& d, const std::filesystem::path& config_dir, const std::string& name,
                      Problems& problems) {
  if (d.security_dir.empty()) return;
  std::filesystem::path dir(d.security_dir);
  if (dir.is_relative()) dir = config_dir / dir;
  dir = dir.lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    problems.push_back(name + ": directory not found: " + dir.string());
    return;
  }
  for (const char* file : kSecurityFileNames) {
    if (!std::filesystem::is_regular_file(dir / file, ec)) {
      problems.push_back(name + ": " + (dir / file).string() + " not found");
    }
  }
  d.security_dir = dir.string();
}

const char* no_environment(const char* /*name*/) { return nullptr; }

// The value of a set, non-empty variable.
std::optional<std::string> variable(const Environment& env, const char* name) {
  const char* value = env(name);
  if (value == nullptr || *value == '\0') return std::nullopt;
  return std::string(value);
}

// What a problem with a file or directory names: the variable that set it, or the key.
struct Origins {
  std::string profiles_file{"dds.profiles_file"};
  std::string security_dir{"dds.security_dir"};
};

std::string joined_profile_names() {
  std::string out;
  for (const char* name : kDdsProfileNames) out.append(out.empty() ? "" : ", ").append(name);
  return out;
}

// Applies kEnvironmentVariables onto `config`, appending one line per bad value.
void apply_environment(Config& config, const Environment& env, Origins& origins, Problems& problems) {
  DdsConfig& d = config.dds;
  if (const auto v = variable(env, "PULLOUT_DOMAIN_ID")) {
    const bool digits =
        v->size() <= 3 && std::all_of(v->begin(), v->end(), [](unsigned char c) { return std::isdigit(c) != 0; });
    if (!digits || std::stoi(*v) > 232) {
      problems.push_back("PULLOUT_DOMAIN_ID: must be an integer in [0, 232] (it overrides dds.domain_id), got '" + *v +
                         "'");
    } else {
      d.domain_id = std::stoi(*v);
    }
  }
  if (const auto v = variable(env, "PULLOUT_DDS_PROFILE")) {
    const bool named =
        std::any_of(kDdsProfileNames.begin(), kDdsProfileNames.end(), [&](const char* name) { return *v == name; });
    const bool path = v->find('/') != std::string::npos || (v->size() > 4 && v->compare(v->size() - 4, 4, ".xml") == 0);
    if (named) {
      d.profiles_file = "dds/" + *v + ".xml";
      origins.profiles_file = "PULLOUT_DDS_PROFILE=" + *v;
      if (*v == "discovery_client" && !variable(env, "ROS_DISCOVERY_SERVER")) {
        problems.push_back(
            "PULLOUT_DDS_PROFILE: discovery_client needs ROS_DISCOVERY_SERVER, the discovery server's "
            "ADDRESS:PORT (e.g. 10.0.0.1:11811)");
      }
    } else if (path) {
      d.profiles_file = *v;
      origins.profiles_file = "PULLOUT_DDS_PROFILE";
    } else {
      problems.push_back("PULLOUT_DDS_PROFILE: unknown profile '" + *v + "': one of " + joined_profile_names() +
                         ", or the path of a Fast DDS XML profiles file");
    }
  }
  if (const auto v = variable(env, "PULLOUT_DDS_SECURITY_DIR")) {
    d.security_dir = *v;
    origins.security_dir = "PULLOUT_DDS_SECURITY_DIR";
  }
  MetricsConfig& m = config.observability.metrics;
  if (const auto v = variable(env, "PULLOUT_METRICS_ENABLED")) {
    if (*v == "true" || *v == "false") {
      m.enabled = *v == "true";
    } else {
      problems.push_back(
          "PULLOUT_METRICS_ENABLED: must be true or false (it overrides "
          "observability.metrics.enabled), got '" +
          *v + "'");
    }
  }
  if (const auto v = variable(env, "PULLOUT_METRICS_ADDRESS")) {
    in_addr parsed{};
    if (inet_pton(AF_INET, v->c_str(), &parsed) == 1) {
      m.address = *v;
    } else {
      problems.push_back(
          "PULLOUT_METRICS_ADDRESS: must be an IPv4 address such as 0.0.0.0 (it overrides "
          "observability.metrics.address), got '" +
          *v + "'");
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// shared with scenario.cpp (config_detail.hpp)

std::optional<PlannerType> parse_planner_name(const std::string& name) {
  // Autoware writes planner names in upper case ("SHIFT"), the model's names are lower case.
  return planner_type_from_string(lower(name));
}

std::string format_number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

YAML::Node load_yaml_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path, {"cannot read file"});
  std::stringstream content;
  content << in.rdbuf();
  if (in.bad()) throw ConfigError(path, {"cannot read file"});
  try {
    return YAML::Load(content.str());
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, {"line " + std::to_string(e.mark.line + 1) + ", column " +
                             std::to_string(e.mark.column + 1) + ": " + e.msg});
  }
}

void append_parameter_issues(const std::vector<ParameterIssue>& issues, const std::string& prefix,
                             std::vector<std::string>& problems) {
  for (const auto& issue : issues) problems.push_back(prefix + "." + issue.name + ": " + issue.problem);
}

// ---------------------------------------------------------------------------------------------
// public API

ConfigError::ConfigError(const std::string& file, std::vector<std::string> problems)
    : std::runtime_error(join_lines(file, problems)), problems_(std::move(problems)) {}

void apply_start_planner_parameters(const YAML::Node& node, const std::string& prefix, StartPlannerParameters& params,
                                    std::vector<std::string>& problems) {
  MapReader r(node, prefix, problems);
  if (r.valid()) config_table::read_table(config_table::start_planner_table(), r, params);
}

void apply_vehicle_info(const YAML::Node& node, const std::string& prefix, VehicleInfo& vehicle,
                        std::vector<std::string>& problems) {
  MapReader r(node, prefix, problems);
  if (r.valid()) config_table::read_table(config_table::vehicle_table(), r, vehicle);
}

std::vector<std::string> check_config(const Config& config) {
  Problems problems;
  config_table::check_table(config_table::config_file_table(), config, "", problems);
  cross_key_problems(config, problems);
  return problems;
}

std::string documented_config(const Config& values) {
  config_table::Doc doc;
  for (const char* line : {
           "pullout_service configuration: every key, with its default (the C++ structs' initialisers).",
           "",
           "Every key is optional: a missing key takes the default written here. An unknown key, a value",
           "of the wrong type or an out-of-range value stops the service at start-up with one line per",
           "problem. Comments give the unit ([m], [s], [m/s], [rad], ...) and the allowed values.",
           "",
           "Generated from the config tables (service/src/config/config_tables.cpp) by",
           "`pullout_service --print-config`; a test checks that this file and the tables agree.",
       }) {
    doc.push_back({0, line, "", true});
  }
  config_table::write_table(config_table::config_file_table(), values, 0, doc);
  return config_table::render(doc);
}

Config load_config(const std::string& path) { return load_config(path, no_environment); }

Config load_config(const std::string& path, const Environment& env) {
  const YAML::Node doc = load_yaml_file(path);
  Config config;
  Problems problems;
  MapReader root(doc, "", problems);
  if (root.valid()) {
    // Reading checks each key's type and allowed values and reports unknown keys.
    config_table::read_table(config_table::config_file_table(), root, config);
    Origins origins;
    apply_environment(config, env, origins, problems);
    cross_key_problems(config, problems);
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    resolve_dds(config.dds, dir, origins.profiles_file, problems);
    resolve_security(config.dds, dir, origins.security_dir, problems);
    resolve_map(config.map, dir, problems);
    resolve_state_dir(config.service, dir);
  }
  if (!problems.empty()) throw ConfigError(path, std::move(problems));
  return config;
}

std::string describe_profiles(const DdsConfig& dds) {
  return dds.profiles_file.empty() ? std::string("the built-in loopback profiles") : dds.profiles_file;
}

}  // namespace pullout
