// Pieces of the config loader that the scenario loader reuses. Not part of the public API.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/parameters.hpp"

namespace pullout {

// A planner name as written in config and scenario files: Autoware's upper case ("SHIFT") or the
// model's lower case ("shift").
std::optional<PlannerType> parse_planner_name(const std::string& name);

std::string format_number(double v);

// Reads and parses a YAML file. Throws ConfigError("cannot read file" or the parser's message with
// its line and column).
YAML::Node load_yaml_file(const std::string& path);

// Appends "<prefix>.<name>: <problem>" for each issue.
void append_parameter_issues(const std::vector<ParameterIssue>& issues, const std::string& prefix,
                             std::vector<std::string>& problems);

}  // namespace pullout
