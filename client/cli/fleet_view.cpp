#include "fleet_view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "pullout/model/names.hpp"
#include "svg_writer.hpp"

namespace pullout::cli {

namespace {

constexpr std::size_t kMaxNoteChars = 60;
constexpr const char* kNone = "-";

std::string format_age(double seconds) {
  char buffer[32];
  if (!(seconds >= 0.0)) seconds = 0.0;
  if (seconds < 10.0) {
    std::snprintf(buffer, sizeof buffer, "%.1fs", seconds);
  } else if (seconds < 60.0) {
    std::snprintf(buffer, sizeof buffer, "%.0fs", std::floor(seconds));
  } else {
    const auto whole = static_cast<long long>(seconds);
    std::snprintf(buffer, sizeof buffer, "%lldm%02llds", whole / 60, whole % 60);
  }
  return buffer;
}

std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  if (line.size() > kMaxNoteChars) line = line.substr(0, kMaxNoteChars - 3) + "...";
  return line;
}

double age_seconds(const VehicleView& v, std::chrono::system_clock::time_point now) {
  return std::chrono::duration<double>(now - v.last_update).count();
}

nlohmann::json xy(const Point2& p) { return nlohmann::json::array({p.x, p.y}); }

template <typename Points>
nlohmann::json polyline(const Points& points) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : points) out.push_back(xy(p));
  return out;
}

// The lane's outline: the left bound, then the right bound backwards.
nlohmann::json lane_json(const Lane& lane) {
  std::vector<Point2> outline = lane.left_bound;
  outline.insert(outline.end(), lane.right_bound.rbegin(), lane.right_bound.rend());
  return {{"id", lane.id}, {"subtype", to_string(lane.subtype)}, {"outline", polyline(outline)}};
}

}  // namespace

FleetRow fleet_row(const VehicleView& vehicle, std::chrono::system_clock::time_point now) {
  FleetRow row{vehicle.vehicle_id, kNone, kNone, kNone, kNone, format_age(age_seconds(vehicle, now)), ""};
  if (const PullOutStatus* s = vehicle.status.get()) {
    row.state = to_string(s->state);
    if (s->planner_type != PlannerType::kNone) row.planner = to_string(s->planner_type);
    if (s->segment_count > 0) {
      row.segment = std::to_string(s->current_path_idx + 1) + "/" + std::to_string(s->segment_count);
    }
    if (has_path(s->state)) {
      row.safe = s->safe ? "yes" : "no";
      if (!s->safe && s->unsafe_object_id != 0) row.safe += " (object " + std::to_string(s->unsafe_object_id) + ")";
    }
    row.note = first_line(!s->error.empty() ? s->error : s->stop_reason);
  }
  return row;
}

std::string render_fleet_table(const FleetSnapshot& snapshot, std::chrono::system_clock::time_point now) {
  std::vector<FleetRow> rows;
  rows.push_back({"VEHICLE", "STATE", "PLANNER", "SEGMENT", "SAFE", "AGE", "NOTE"});
  for (const VehicleView& v : snapshot.vehicles) rows.push_back(fleet_row(v, now));
  std::array<std::size_t, 6> widths{};
  for (const FleetRow& r : rows) {
    const std::array<const std::string*, 6> cells{&r.vehicle, &r.state, &r.planner, &r.segment, &r.safe, &r.age};
    for (std::size_t i = 0; i < cells.size(); ++i) widths[i] = std::max(widths[i], cells[i]->size());
  }
  std::ostringstream out;
  for (const FleetRow& r : rows) {
    const std::array<const std::string*, 6> cells{&r.vehicle, &r.state, &r.planner, &r.segment, &r.safe, &r.age};
    std::string line;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      line += *cells[i];
      line.append(widths[i] - cells[i]->size() + 2, ' ');
    }
    line += r.note;
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << '\n';
  }
  if (snapshot.vehicles.empty()) out << "(no vehicles)\n";
  return out.str();
}

nlohmann::json fleet_json(const FleetSnapshot& snapshot, const VehicleInfo& vehicle_info,
                          std::chrono::system_clock::time_point now) {
  nlohmann::json vehicles = nlohmann::json::array();
  for (const VehicleView& v : snapshot.vehicles) {
    const FleetRow row = fleet_row(v, now);
    nlohmann::json j = {{"id", v.vehicle_id},           {"state", row.state}, {"planner", row.planner},
                        {"segment", row.segment},       {"safe", row.safe},   {"age", row.age},
                        {"age_s", age_seconds(v, now)}, {"note", row.note}};
    const PullOutStatus* status = v.status.get();
    j["current_segment"] = status != nullptr && status->segment_count > 0 ? nlohmann::json(status->current_path_idx)
                                                                          : nlohmann::json(nullptr);
    std::optional<Pose2> pose;
    if (v.progress) {
      pose = v.progress->pose;
    } else if (v.request) {
      pose = v.request->ego_pose;
    }
    if (pose) {
      j["pose"] = {{"x", pose->x}, {"y", pose->y}, {"yaw", pose->yaw}};
      j["footprint"] = polyline(vehicle_footprint(vehicle_info, *pose));
    }
    nlohmann::json lanes = nlohmann::json::array();
    nlohmann::json objects = nlohmann::json::array();
    if (v.request) {
      for (const Lane& lane : v.request->lanes) lanes.push_back(lane_json(lane));
      for (const Object& object : v.request->objects) {
        objects.push_back({{"id", object.id},
                           {"class", to_string(object.object_class)},
                           {"outline", polyline(object_footprint(object))}});
      }
      j["goal"] = {{"x", v.request->goal_pose.x}, {"y", v.request->goal_pose.y}};
    }
    j["lanes"] = std::move(lanes);
    j["objects"] = std::move(objects);
    if (const PullOutPath* path = v.path.get()) {
      nlohmann::json segments = nlohmann::json::array();
      for (const PathWithLaneId& partial : path->partial_paths) {
        nlohmann::json points = nlohmann::json::array();
        bool reverse = false;
        for (const PathPoint& p : partial.points) {
          points.push_back(nlohmann::json::array({p.pose.x, p.pose.y}));
          reverse = reverse || p.longitudinal_velocity_mps < 0.0;
        }
        segments.push_back({{"points", std::move(points)}, {"reverse", reverse}});
      }
      j["path"] = {{"request_id", std::to_string(path->request_id)},
                   {"found", path->found},
                   {"planner", to_string(path->planner_type)},
                   {"segments", std::move(segments)}};
    }
    vehicles.push_back(std::move(j));
  }
  return {{"version", snapshot.version}, {"service", snapshot.service_matched}, {"vehicles", std::move(vehicles)}};
}

}  // namespace pullout::cli
