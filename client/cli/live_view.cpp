// `pullout watch` (the fleet table of a FleetMonitor, redrawn in the terminal) and `pullout view`
// (its web page).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <optional>
#include <thread>

#include "commands.hpp"
#include "fleet_monitor.hpp"
#include "fleet_view.hpp"
#include "open_endpoint.hpp"
#include "pullout/config/config.hpp"
#include "view/view_server.hpp"

namespace pullout::cli {

namespace {

using SteadyClock = std::chrono::steady_clock;

constexpr auto kSlice = std::chrono::milliseconds(100);
// --once: the service's transient-local samples have arrived when nothing new came for this long.
constexpr auto kQuietPeriod = std::chrono::milliseconds(300);
// "\033[H\033[2J": cursor home, clear the screen.
constexpr const char* kClearScreen = "\033[H\033[2J";

SteadyClock::duration seconds(double s) {
  return std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(s));
}

std::string header(const WatchOptions& options, const FleetSnapshot& snapshot) {
  const std::time_t t = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return std::string("pullout watch  domain ") + std::to_string(options.domain_id) + "  service " +
         (snapshot.service_matched ? "up" : "not found") + "  " + std::to_string(snapshot.vehicles.size()) +
         " vehicle(s)  " + stamp + "\n";
}

}  // namespace

int run_watch(const WatchOptions& options, bool terminal, std::ostream& out, std::ostream& err) {
  if (!(options.interval_s > 0.0) || !std::isfinite(options.interval_s)) {
    err << "pullout: --interval must be a positive number of seconds\n";
    return kExitBadInput;
  }
  if (!(options.duration_s >= 0.0) || !std::isfinite(options.duration_s)) {
    err << "pullout: --duration must be a non-negative number of seconds\n";
    return kExitBadInput;
  }
  std::optional<FleetMonitor> monitor;
  FleetMonitorOptions monitor_options;
  monitor_options.domain_id = options.domain_id;
  monitor_options.profiles_file = options.profiles_file;
  if (const auto failed = open_endpoint<FleetMonitorError>(monitor, monitor_options, err)) return *failed;

  const auto start = SteadyClock::now();
  if (options.once) {
    // Until a service is matched and its samples stop coming, bounded by --wait.
    const auto deadline = start + seconds(options.wait_s);
    std::uint64_t version = 0;
    auto last_change = start;
    while (!interrupted() && SteadyClock::now() < deadline) {
      const std::uint64_t now_version = monitor->wait_for_change(version, kSlice);
      if (now_version != version) {
        version = now_version;
        last_change = SteadyClock::now();
      } else if (monitor->snapshot().service_matched && SteadyClock::now() - last_change >= kQuietPeriod) {
        break;
      }
    }
    const FleetSnapshot snapshot = monitor->snapshot();
    out << header(options, snapshot) << render_fleet_table(snapshot, std::chrono::system_clock::now()) << std::flush;
    if (!snapshot.service_matched) {
      err << "pullout: no pullout service found on DDS domain " << options.domain_id << " within " << options.wait_s
          << " s\n";
      return kExitCommunication;
    }
    return kExitFound;
  }

  const auto end = options.duration_s > 0.0 ? start + seconds(options.duration_s) : SteadyClock::time_point::max();
  const auto interval = seconds(options.interval_s);
  std::uint64_t shown = 0;
  auto next = start;
  while (!interrupted()) {
    const auto now = SteadyClock::now();
    if (now >= end) break;
    const auto slice = std::min<SteadyClock::duration>(kSlice, end - now);
    std::uint64_t version = shown;
    if (terminal) {
      version = monitor->wait_for_change(shown, slice);
    } else if (next > now) {
      std::this_thread::sleep_for(std::min<SteadyClock::duration>(slice, next - now));
    }
    // A terminal is redrawn as samples arrive (at most every kSlice) and at least every interval
    // (the ages); a pipe or file gets one table per interval.
    const bool due = SteadyClock::now() >= next || (terminal && version != shown);
    if (!due) continue;
    const FleetSnapshot snapshot = monitor->snapshot();
    shown = snapshot.version;
    next = SteadyClock::now() + interval;
    if (terminal) out << kClearScreen;
    out << header(options, snapshot) << render_fleet_table(snapshot, std::chrono::system_clock::now());
    if (!terminal) out << '\n';
    out << std::flush;
    if (terminal) std::this_thread::sleep_for(kSlice);  // rate limit
  }
  return kExitFound;
}

int run_view(const ViewOptions& options, std::ostream& out, std::ostream& err) {
  if (!(options.duration_s >= 0.0) || !std::isfinite(options.duration_s)) {
    err << "pullout: --duration must be a non-negative number of seconds\n";
    return kExitBadInput;
  }
  const std::size_t colon = options.http.rfind(':');
  int port = -1;
  if (colon != std::string::npos && colon > 0 && colon + 1 < options.http.size() &&
      options.http.find_first_not_of("0123456789", colon + 1) == std::string::npos &&
      options.http.size() - colon <= 6) {
    port = std::stoi(options.http.substr(colon + 1));
  }
  if (port < 0 || port > 65535) {
    err << "pullout: --http must be ADDRESS:PORT (e.g. 127.0.0.1:8080), not '" << options.http << "'\n";
    return kExitBadInput;
  }
  ViewServerOptions server_options;
  server_options.address = options.http.substr(0, colon);
  server_options.port = port;
  FleetMonitorOptions monitor_options;
  monitor_options.domain_id = options.domain_id;
  monitor_options.profiles_file = options.profiles_file;
  if (!options.config_file.empty()) {
    try {
      const Config config = load_config(options.config_file);
      server_options.vehicle = config.vehicle;
      if (!options.domain_given) monitor_options.domain_id = config.dds.domain_id;
      if (!options.profiles_given) {
        monitor_options.profiles_file = config.dds.profiles_file;
        monitor_options.participant_profile = config.dds.participant_profile;
      }
    } catch (const ConfigError& e) {
      err << "pullout: " << e.what() << '\n';
      return kExitBadInput;
    }
  }

  std::optional<FleetMonitor> monitor;
  std::optional<ViewServer> server;
  if (const auto failed = open_endpoint<FleetMonitorError>(monitor, monitor_options, err)) return *failed;
  try {
    server.emplace(*monitor, server_options);
  } catch (const std::runtime_error& e) {
    err << "pullout: --http: " << e.what() << '\n';
    return kExitBadInput;
  }
  out << "pullout view: http://" << server_options.address << ":" << server->port() << "/ (DDS domain "
      << monitor_options.domain_id << ")" << std::endl;
  const auto end =
      options.duration_s > 0.0 ? SteadyClock::now() + seconds(options.duration_s) : SteadyClock::time_point::max();
  while (!interrupted() && SteadyClock::now() < end) std::this_thread::sleep_for(kSlice);
  server.reset();
  return kExitFound;
}

}  // namespace pullout::cli
