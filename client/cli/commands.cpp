#include "commands.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <exception>
#include <optional>

#include "json_output.hpp"
#include "open_endpoint.hpp"
#include "pullout/client/client.hpp"
#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/parameters.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/search/stop_condition.hpp"
#include "pullout/session/vehicle_session.hpp"
#include "report.hpp"
#include "svg_writer.hpp"
#include "text_output.hpp"

namespace pullout::cli {

namespace {

using SteadyClock = std::chrono::steady_clock;

constexpr const char* kDefaultVehicleId = "pullout-cli";
// Waits are cut into slices so that an interrupt is noticed quickly.
constexpr auto kWaitSlice = std::chrono::milliseconds(100);
// After the final status, how long to wait for the path at least (it is published alongside).
constexpr auto kPathGrace = std::chrono::seconds(1);
// [m] The SVG draws a scenario map's lanelets this close to the vehicle.
constexpr double kSvgMapRadius = 60.0;

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void handle_interrupt(int /*signal*/) { g_interrupted.store(true); }

// Renders the report on `out` (text or JSON) and writes the SVG. Returns the exit code.
int emit(const PlanReport& report, const Scenario& scenario, const std::string& scenario_file,
         const OutputOptions& options, std::ostream& out, std::ostream& err) {
  const PullOutRequest& request = scenario.request;
  const VehicleInfo& vehicle = scenario.vehicle;
  if (options.json) {
    // Strings from the service may hold invalid UTF-8: replace rather than throw.
    out << to_json(report).dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
  } else {
    print_report(out, report);
  }
  if (!options.svg_file.empty()) {
    SvgOptions svg;
    svg.frame_manoeuvre = !options.svg_whole;
    svg.title = scenario_file + (report.found ? "  (" + std::string(to_string(report.planner)) + ")" : "  (no path)");
    if (scenario.map) {
      for (std::size_t i : scenario.map->lanelets_near({request.ego_pose.x, request.ego_pose.y}, kSvgMapRadius)) {
        if (auto lane = to_lane(scenario.map->lanelet(i))) svg.map_lanes.push_back(std::move(*lane));
      }
    }
    try {
      write_text_file(options.svg_file, render_svg(request, vehicle, report.path ? &*report.path : nullptr, svg));
    } catch (const std::exception& e) {
      err << "pullout: " << e.what() << '\n';
      return kExitBadInput;
    }
  }
  return exit_code(report);
}

bool is_final(const PullOutStatus& status) {
  return status.state != ExecutionState::kIdle && status.state != ExecutionState::kPlanning;
}

// Calls `attempt(slice)` until it yields a value, the deadline passes or an interrupt arrives.
template <typename Attempt>
auto wait_sliced(SteadyClock::time_point deadline, Attempt attempt) -> decltype(attempt(kWaitSlice)) {
  while (!g_interrupted.load()) {
    const auto now = SteadyClock::now();
    const auto slice = std::min<SteadyClock::duration>(kWaitSlice, std::max(deadline - now, SteadyClock::duration{}));
    auto result = attempt(std::chrono::duration_cast<Client::Duration>(slice));
    if (result || SteadyClock::now() >= deadline) return result;
  }
  return {};
}

}  // namespace

void install_interrupt_handlers() {
  std::signal(SIGINT, handle_interrupt);
  std::signal(SIGTERM, handle_interrupt);
}

bool interrupted() { return g_interrupted.load(); }

namespace {

// A scenario's `fleet:` is driven by the scenario tests (each vehicle its own Client); the CLI
// plans or sends only the scenario's own vehicle, and says so rather than ignoring it silently.
void note_fleet_not_used(const Scenario& scenario, const char* what, std::ostream& err) {
  if (scenario.fleet.empty()) return;
  err << "pullout: note: the scenario's fleet (" << scenario.fleet.size() << " other vehicle"
      << (scenario.fleet.size() == 1 ? "" : "s") << ") is not " << what
      << ": only its own vehicle is, without the other vehicles' paths in the safety check\n";
}

// Only search_priority and search_policy travel with a request; the service plans with its own
// parameters otherwise (a vehicle does not set another's margins). Named, not dropped silently.
void note_planner_keys_not_sent(const Scenario& scenario, std::ostream& err) {
  if (scenario.local_planner_keys.empty()) return;
  err << "pullout: note: the scenario's planner key" << (scenario.local_planner_keys.size() == 1 ? " " : "s ");
  for (std::size_t i = 0; i < scenario.local_planner_keys.size(); ++i) {
    err << (i == 0 ? "" : ", ") << scenario.local_planner_keys[i];
  }
  err << (scenario.local_planner_keys.size() == 1 ? " is" : " are")
      << " not sent: the service plans with its own parameters (a request carries only search_priority and "
         "search_policy; `pullout plan` applies them all)\n";
}

}  // namespace

int run_plan(const PlanOptions& options, std::ostream& out, std::ostream& err) {
  Config config;
  Scenario scenario;
  try {
    if (!options.config_file.empty()) config = load_config(options.config_file);
    scenario = load_scenario(options.scenario_file, config);
  } catch (const ConfigError& e) {
    err << "pullout: " << e.what() << '\n';
    return kExitBadInput;
  }
  // A scenario without `map:` is planned on the config's map.path, as the service with that
  // config plans it (its route ids refer to that map).
  if (!scenario.map && !config.map.path.empty()) {
    try {
      scenario.map = load_lanelet_map(config.map.path);
      scenario.map_path = config.map.path;
    } catch (const MapLoadError& e) {
      err << "pullout: " << options.config_file << ": map.path: " << e.what() << '\n';
      return kExitBadInput;
    }
  }
  // load_config and load_scenario have checked every parameter (ConfigError above).
  note_fleet_not_used(scenario, "planned here", err);

  const StartPlanner planner(scenario.vehicle, scenario.parameters, config.service.limits, scenario.map,
                             config.vehicle_profiles);
  // The service's budget rule: the request's deadline, else the configured default.
  const double budget_ms =
      scenario.request.deadline_ms > 0.0 ? scenario.request.deadline_ms : config.service.default_deadline_ms;
  // The same session the service runs: what is printed is the first status the vehicle would get
  // after planning (with the safety verdict at the start pose), not a summary of the search.
  PullOutRequest request = scenario.request;
  if (request.vehicle_id.empty()) request.vehicle_id = kDefaultVehicleId;
  VehicleSession session(request.vehicle_id, planner);
  const auto now = SteadyClock::now();
  SessionEffects effects = session.on_request(request, {}, now);
  if (effects.search) {
    const PlanningResult result = planner.plan(effects.search->request, StopCondition::after_ms(budget_ms));
    effects = session.on_result(effects.search->sequence, result, now);
  }
  if (!effects.status) {
    err << "pullout: internal error: the session published no status\n";
    return kExitInternal;
  }
  return emit(make_report(effects.path, *effects.status), scenario, options.scenario_file, options.output, out, err);
}

int run_request(const RequestOptions& options, std::ostream& out, std::ostream& err) {
  if (!(options.timeout_s > 0.0) || !std::isfinite(options.timeout_s)) {
    err << "pullout: --timeout must be a positive number of seconds\n";
    return kExitBadInput;
  }
  Scenario scenario;
  try {
    scenario = load_scenario(options.scenario_file);
  } catch (const ConfigError& e) {
    err << "pullout: " << e.what() << '\n';
    return kExitBadInput;
  }
  note_fleet_not_used(scenario, "sent", err);
  note_planner_keys_not_sent(scenario, err);
  const auto deadline = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                 std::chrono::duration<double>(options.timeout_s));

  ClientOptions client_options;
  client_options.vehicle_id = scenario.request.vehicle_id.empty() ? kDefaultVehicleId : scenario.request.vehicle_id;
  client_options.domain_id = options.domain_id;
  client_options.profiles_file = options.profiles_file;
  client_options.security_dir = options.security_dir;
  std::optional<Client> client;
  if (const auto failed = open_endpoint<ClientError>(client, client_options, err)) return *failed;

  const bool matched = wait_sliced(deadline, [&](Client::Duration slice) { return client->wait_for_service(slice); });
  if (g_interrupted.load()) return kExitInterrupted;
  if (!matched) {
    err << "pullout: no pullout service found on DDS domain " << options.domain_id << " within " << options.timeout_s
        << " s\n";
    return kExitCommunication;
  }

  std::uint64_t request_id = 0;
  try {
    request_id = client->send(scenario.request);
  } catch (const ClientError& e) {
    err << "pullout: " << e.what() << '\n';
    return kExitCommunication;
  }

  const auto status = wait_sliced(
      deadline, [&](Client::Duration slice) { return client->wait_for_status(request_id, is_final, slice); });
  if (g_interrupted.load()) return kExitInterrupted;
  if (!status) {
    err << "pullout: no answer to request " << request_id << " within " << options.timeout_s << " s\n";
    return kExitCommunication;
  }

  std::optional<PullOutPath> path;
  if (status->state != ExecutionState::kRejected) {
    const auto path_deadline = std::max(deadline, SteadyClock::now() + kPathGrace);
    path = wait_sliced(path_deadline, [&](Client::Duration slice) { return client->wait_for_path(request_id, slice); });
    if (g_interrupted.load()) return kExitInterrupted;
    const bool executing = has_path(status->state);
    if (!path && executing) {
      err << "pullout: the service reported a path for request " << request_id << " but it did not arrive\n";
      return kExitCommunication;
    }
  }
  return emit(make_report(path, *status), scenario, options.scenario_file, options.output, out, err);
}

}  // namespace pullout::cli
