// Checks of the planner parameters that involve more than one key, and of what this version of
// the core implements (see parameters.hpp). Each key's own allowed values are in the config
// tables (service/src/config/config_tables.cpp), which check them when a file is read.
#include "pullout/pipeline/parameters.hpp"

#include "pullout/freespace/freespace_search.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "pullout/model/names.hpp"

namespace pullout {
namespace {

// "shift, geometric": the planners this version implements (planner_available), for messages.
std::string available_planner_names() {
  std::string names;
  for (const PlannerType p : kSearchPlanners) {
    if (!planner_available(p)) continue;
    if (!names.empty()) names += ", ";
    names += to_string(p);
  }
  return names;
}

std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

}  // namespace

std::vector<ParameterIssue> validate_parameters(const StartPlannerParameters& p) {
  std::vector<ParameterIssue> issues;
  const auto fail = [&](const std::string& name, const std::string& problem) { issues.push_back({name, problem}); };

  for (std::size_t i = 0; i < p.search_priority.size(); ++i) {
    const PlannerType planner = p.search_priority[i];
    if (!planner_available(planner)) {
      fail("search_priority[" + std::to_string(i) + "]",
           std::string("planner '") + to_string(planner) +
               "' is not available in this version (available: " + available_planner_names() + ")");
    }
  }
  if (std::isfinite(p.minimum_lateral_acc) && std::isfinite(p.maximum_lateral_acc) &&
      p.minimum_lateral_acc > p.maximum_lateral_acc) {
    fail("maximum_lateral_acc",
         "must be >= minimum_lateral_acc (" + text(p.minimum_lateral_acc) + "), got " + text(p.maximum_lateral_acc));
  }
  // Tried in turn, the largest first (the first margin a path keeps wins), and the last is the
  // least the backward search keeps: an unsorted list tried a small margin first and backed up
  // to the wrong one.
  for (std::size_t i = 1; i < p.collision_check_margins.size(); ++i) {
    const double before = p.collision_check_margins[i - 1];
    const double margin = p.collision_check_margins[i];
    if (std::isfinite(before) && std::isfinite(margin) && !(margin < before)) {
      fail("collision_check_margins[" + std::to_string(i) + "]",
           "must be below the one before (" + text(before) + "; tried largest first), got " + text(margin));
      break;
    }
  }
  const FreespaceParameters& f = p.freespace_planner;
  if (std::isfinite(f.end_pose_search_start_distance) && std::isfinite(f.end_pose_search_end_distance) &&
      f.end_pose_search_end_distance < f.end_pose_search_start_distance) {
    fail("freespace_planner.end_pose_search_end_distance", "must be >= end_pose_search_start_distance (" +
                                                               text(f.end_pose_search_start_distance) + "), got " +
                                                               text(f.end_pose_search_end_distance));
  }
  if (f.freespace_planner_algorithm != kAstarAlgorithm && f.freespace_planner_algorithm != kRrtStarAlgorithm) {
    fail("freespace_planner.freespace_planner_algorithm",
         "must be astar or rrtstar, got '" + f.freespace_planner_algorithm + "'");
  }
  return issues;
}

}  // namespace pullout
