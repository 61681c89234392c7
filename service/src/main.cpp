// pullout_service: the start planner as a Fast DDS microservice.
//
//   pullout_service --config config/pullout.yaml [--domain N] [--log-level L] [--log-format text|json]
//   pullout_service --print-config     # the documented config with every default (config/pullout.yaml)
//   pullout_service --version          # "pullout_service <project version> (git <describe>)"
//
// Exit codes: 0 after SIGINT/SIGTERM, 1 bad command line, config or map, 2 DDS setup failed, 3 any
// other start-up failure (e.g. the metrics port is taken), 4 another pullout_service appeared on
// the domain and observability.on_duplicate_service is exit. Everything is built inside one try block; a failure prints
// one line per problem and exits.
#include <pthread.h>
#include <signal.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "observability/json_log.hpp"
#include "pullout/config/config.hpp"
#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/model/names.hpp"
#include "pullout/process_heap.hpp"
#include "pullout/version.hpp"
#include "service/pullout_service.hpp"

namespace {

constexpr int kExitUsage = 1;
constexpr int kExitConfig = 1;
constexpr int kExitDds = 2;
constexpr int kExitOther = 3;
constexpr int kExitDuplicate = 4;

// Blocks SIGINT and SIGTERM in the calling thread and, because the mask is inherited, in every
// thread created afterwards (Fast DDS's and ours). They are then received only by sigtimedwait()
// in main, where stopping the service is an ordinary function call instead of work inside a
// signal handler.
sigset_t block_stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  return set;
}

// Waits for SIGINT or SIGTERM, or for `give_up` to return true (polled every second); returns the
// signal's name, or null when give_up ended the wait.
template <typename GiveUp>
const char* wait_for_stop_signal(const sigset_t& set, GiveUp give_up) {
  const timespec poll_period{1, 0};
  while (true) {
    const int sig = sigtimedwait(&set, nullptr, &poll_period);
    if (sig == SIGINT) return "SIGINT";
    if (sig == SIGTERM) return "SIGTERM";
    // -1: timeout or EINTR (another signal): keep waiting.
    if (give_up()) return nullptr;
  }
}

void setup_logging(bool json) {
  if (json) {
    // No colours: each line must be exactly one JSON object.
    spdlog::set_default_logger(spdlog::stderr_logger_mt("pullout_service"));
    pullout::service::use_json_logs();
    return;
  }
  auto logger = spdlog::stderr_color_mt("pullout_service");
  logger->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] %v");
  spdlog::set_default_logger(logger);
}

int run(int argc, char** argv) {
  CLI::App app{"pullout_service: start (pull-out) planner for automated vehicles, over Fast DDS"};
  std::string config_path;
  int domain_id = -1;
  std::string log_level;
  std::string log_format;
  bool print_config = false;
  app.set_version_flag("--version", std::string("pullout_service ") + pullout::kVersionString);
  app.add_option("-c,--config", config_path, "config file (e.g. config/pullout.yaml)");
  app.add_flag("--print-config", print_config,
               "print the documented config file with every default (config/pullout.yaml) and exit");
  app.add_option("--domain", domain_id, "DDS domain id, overrides dds.domain_id")->check(CLI::Range(0, 232));
  app.add_option("--log-level", log_level, "overrides service.log_level")
      ->check(CLI::IsMember(std::vector<std::string>(pullout::kLogLevels.begin(), pullout::kLogLevels.end())));
  app.add_option("--log-format", log_format, "overrides observability.log_format (json: one JSON object per line)")
      ->check(CLI::IsMember(std::vector<std::string>(pullout::kLogFormats.begin(), pullout::kLogFormats.end())));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitUsage;
  }
  if (print_config) {
    std::fputs(pullout::documented_config().c_str(), stdout);
    return 0;
  }
  if (config_path.empty()) {
    std::fprintf(stderr, "pullout_service: --config is required\nRun with --help for more information.\n");
    return kExitUsage;
  }

  // Before any thread: the heap settings are process-wide (see process_heap.hpp).
  const pullout::HeapTuning heap = pullout::tune_process_heap();
  const sigset_t stop_signals = block_stop_signals();

  pullout::Config config;
  std::string config_error;
  try {
    // The file, then the environment's overrides (PULLOUT_DOMAIN_ID, PULLOUT_DDS_PROFILE, ...), then
    // the command line's.
    config = pullout::load_config(config_path, [](const char* name) { return std::getenv(name); });
  } catch (const pullout::ConfigError& e) {
    // One line per problem, already "<file>: <key>: <problem>".
    config_error = std::string("invalid config:\n") + e.what();
  } catch (const std::exception& e) {
    config_error = config_path + ": " + e.what();
  }
  if (!log_format.empty()) config.observability.log_format = log_format;
  const bool json_logs = config.observability.log_format == "json";
  setup_logging(json_logs);
  // A start-up error: "pullout_service: <message>" on stderr, or one JSON line.
  const auto startup_error = [json_logs](const std::string& message) {
    if (json_logs) {
      spdlog::critical("{}", message);
    } else {
      std::fprintf(stderr, "pullout_service: %s\n", message.c_str());
    }
  };
  if (!config_error.empty()) {
    startup_error(config_error);
    return kExitConfig;
  }
  // The map is read once, before any DDS entity exists: a bad map stops the service with one line.
  std::shared_ptr<const pullout::LaneletMap> map;
  if (!config.map.path.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      map = pullout::load_lanelet_map(config.map.path);
    } catch (const pullout::MapLoadError& e) {
      startup_error(std::string("invalid map (map.path): ") + e.what());
      return kExitConfig;
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    spdlog::info("map {}: {} lanelets ({} road, {} road_shoulder) loaded in {:.1f} ms", config.map.path,
                 map->lanelets().size(), map->count(pullout::LaneletSubtype::kRoad),
                 map->count(pullout::LaneletSubtype::kRoadShoulder), ms);
  }
  if (domain_id >= 0) config.dds.domain_id = domain_id;
  if (!log_level.empty()) config.service.log_level = log_level;
  spdlog::set_level(spdlog::level::from_str(config.service.log_level));
  switch (heap) {
    case pullout::HeapTuning::kApplied:
      spdlog::debug("heap: blocks up to {} MiB from the heap, up to {} MiB of free memory kept for reuse",
                    pullout::kHeapMmapThresholdBytes >> 20, pullout::kHeapTrimThresholdBytes >> 20);
      break;
    case pullout::HeapTuning::kLeftToTunables:
      spdlog::info("heap: GLIBC_TUNABLES sets glibc.malloc tunables: the heap is left as they say");
      break;
    case pullout::HeapTuning::kRefused:
      spdlog::warn("heap: mallopt refused the settings (a sanitizer's allocator?): glibc's defaults apply");
      break;
  }

  try {
    pullout::service::PulloutService service(config, map);
    service.start();
    spdlog::info("pullout_service ready: domain {}, participant profile '{}' from {}, {} planning thread(s)",
                 config.dds.domain_id, config.dds.participant_profile, pullout::describe_profiles(config.dds),
                 config.service.worker_threads);
    const bool exit_on_duplicate = config.observability.on_duplicate_service == "exit";
    const char* signal_name =
        wait_for_stop_signal(stop_signals, [&] { return exit_on_duplicate && service.other_services() > 0; });
    if (signal_name == nullptr) {
      spdlog::critical(
          "another pullout_service is on DDS domain {} and observability.on_duplicate_service is exit: stopping",
          config.dds.domain_id);
      service.stop();
      return kExitDuplicate;
    }
    spdlog::info("{} received, stopping", signal_name);
    service.stop();
  } catch (const pullout::service::DdsSetupError& e) {
    spdlog::critical("DDS setup failed: {}", e.what());
    return kExitDds;
  } catch (const std::exception& e) {
    spdlog::critical("start-up failed: {}", e.what());
    return kExitOther;
  }
  spdlog::info("pullout_service stopped");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    // Only reachable if logging itself failed to set up.
    std::fprintf(stderr, "pullout_service: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "pullout_service: unknown error\n");
  }
  return kExitOther;
}
