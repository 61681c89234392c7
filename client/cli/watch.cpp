// `pullout watch`: the fleet table of a FleetMonitor, redrawn in the terminal.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <optional>
#include <thread>

#include "commands.hpp"
#include "fleet_monitor.hpp"
#include "fleet_view.hpp"

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
  try {
    FleetMonitorOptions monitor_options;
    monitor_options.domain_id = options.domain_id;
    monitor_options.profiles_file = options.profiles_file;
    monitor.emplace(monitor_options);
  } catch (const std::invalid_argument& e) {
    err << "pullout: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const FleetMonitorError& e) {
    err << "pullout: DDS setup failed: " << e.what() << '\n';
    return kExitCommunication;
  }

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

}  // namespace pullout::cli
