// Loading and validating config/pullout.yaml.
//
// The file has six sections: `vehicle` (VehicleInfo fields without the unit suffix, e.g.
// wheel_base), `start_planner` (StartPlannerParameters, Autoware's names), `service` (workers,
// default deadline, request limits, log level), `dds` (domain id, XML profiles file, participant
// profile), `map` (the Lanelet2 map file; its content is loaded by the service, not here) and
// `observability` (metrics and health endpoints, log format, a second service on the domain). Every
// key is optional (the struct defaults apply) but an unknown key, a value of the wrong type or an
// out-of-range value is an error. load_config() reports every problem at once.
//
// Each key is written once, in the config tables (service/src/config/config_tables.cpp: name,
// member, unit, allowed values, comment; the default is the member's initialiser). They drive the
// reading, the range checks and the documented file: config/pullout.yaml is documented_config()
// (`pullout_service --print-config`), and a test checks that the two agree.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pullout/pipeline/parameters.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace YAML {
class Node;
}

namespace pullout {

// Units, allowed values and comments of these structs' members are in the config tables.
struct DdsConfig {
  int domain_id{0};
  // Fast DDS XML profiles file; load_config resolves it relative to the config file and checks
  // that it exists. Empty: the built-in profiles, which are config/dds/loopback.xml compiled into
  // the service (loopback only), so a config file needs no profiles file beside it.
  std::string profiles_file;
  std::string participant_profile{"pullout_participant"};
  // DDS Security credentials of the service (a directory with kSecurityFileNames; load_config
  // resolves it relative to the config file). Empty: no security. When set, every vehicle's
  // samples live in the partition named after its vehicle id (pullout/idl/security.hpp).
  std::string security_dir;
};

// The files of a DDS Security credentials directory (the same list as pullout/idl/security.hpp,
// which this header cannot include: it has no DDS dependency).
inline constexpr std::array<const char*, 5> kSecurityFileNames{"ca.pem", "cert.pem", "key.pem", "governance.p7s",
                                                               "permissions.p7s"};

// spdlog's level names: the values of service.log_level and pullout_service --log-level.
inline constexpr std::array<const char*, 7> kLogLevels{"trace", "debug", "info", "warn", "error", "critical", "off"};

// Several pullout_service replicas on one domain serving one fleet (README, Replicas).
struct ReplicaConfig {
  bool enabled{false};  // off: a second service on the domain is a duplicate (warned about)
  // [ms] This participant's DDS lease (announced every quarter of it): how soon the other
  // replicas notice that it died and take its vehicles over.
  int lease_duration_ms{500};
};

struct ServiceConfig {
  int worker_threads{2};
  double default_deadline_ms{200.0};  // [ms]
  // [ms] A search that ends within this is answered without a `planning` status (the path and
  // the final status are the request's first samples): the planning thread tries it with this
  // budget first, and writes `planning` and searches again with the whole budget when it runs out.
  // 0: `planning` written when the request is accepted.
  double quick_answer_ms{2.0};
  // The quick attempt on the dispatcher itself (no hand-off) while it keeps up. Off: on a machine
  // short of CPU the one busy dispatcher thread got less of it than three lighter threads and
  // fell up to 1 s behind (bench/RESULTS.md, "Planning on the dispatcher").
  bool quick_answer_on_dispatcher{false};
  RequestLimits limits;
  std::string log_level{"info"};  // one of kLogLevels
  // [s] A departed vehicle with no progress sample for this long is told to stop (0: never).
  double progress_timeout_s{2.0};
  // [m] Vehicles that see each other: the ego's footprint is pushed out this much on each side
  // when its path is checked against another vehicle's executing path.
  double fleet_clearance_m{0.5};
  // [s] A session with no request and no progress for this long, no search running and not
  // driving a path (departed and not completed), is evicted (0: never by time).
  double session_idle_timeout_s{300.0};
  // Sessions held at once; when full, the least recently active idle one makes room, and when
  // none is idle a new vehicle is rejected. At most the DDS profiles' max_instances.
  std::size_t max_vehicles{2048};
  // A directory where every vehicle's latest request, path and status are kept (one file each,
  // replaced atomically), read back at start-up: a killed service restarts without losing its
  // vehicles. Relative to the config file; empty: off.
  std::string state_dir;
  ReplicaConfig replica;
};

struct MapConfig {
  // Lanelet2 OSM file (Autoware format) that route requests refer to; relative paths are relative
  // to the config file, and load_config makes them absolute. Empty: no map (inline lanes only).
  std::string path;
};

// The values of observability.log_format and observability.on_duplicate_service.
inline constexpr std::array<const char*, 2> kLogFormats{"text", "json"};
inline constexpr std::array<const char*, 2> kDuplicatePolicies{"warn", "exit"};

// The Prometheus endpoint (/metrics) and the health endpoints (/healthz, /readyz) on one HTTP port.
struct MetricsConfig {
  bool enabled{false};
  std::string address{"127.0.0.1"};  // IPv4 address to listen on; 0.0.0.0 = every interface
  int port{9464};
};

struct ObservabilityConfig {
  MetricsConfig metrics;
  std::string log_format{"text"};            // one of kLogFormats
  std::string on_duplicate_service{"warn"};  // one of kDuplicatePolicies
};

// The shipped vehicle profiles: a car (the default vehicle), a van and a 12 m bus. Dimensions are
// typical of their class (the bus: 5.9 m wheel base, 2.55 m wide, 7.0 m minimum turning radius of
// the rear axle).
inline VehicleProfiles default_vehicle_profiles() {
  VehicleInfo van;
  van.wheel_base_m = 3.665;
  van.wheel_tread_m = 1.73;
  van.front_overhang_m = 0.9;
  van.rear_overhang_m = 1.35;
  van.left_overhang_m = 0.15;
  van.right_overhang_m = 0.15;
  van.max_steer_angle_rad = 0.62;
  VehicleInfo bus;
  bus.wheel_base_m = 5.9;
  bus.wheel_tread_m = 2.15;
  bus.front_overhang_m = 2.6;
  bus.rear_overhang_m = 3.5;
  bus.left_overhang_m = 0.2;
  bus.right_overhang_m = 0.2;
  bus.max_steer_angle_rad = 0.70;
  return {{"car", VehicleInfo{}}, {"van", van}, {"bus", bus}};
}

struct Config {
  VehicleInfo vehicle;
  VehicleProfiles vehicle_profiles{default_vehicle_profiles()};
  StartPlannerParameters start_planner;
  ServiceConfig service;
  DdsConfig dds;
  MapConfig map;
  ObservabilityConfig observability;
};

// Thrown by load_config / load_scenario with one line per problem: "<file>: <key path>: <problem>".
class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& file, std::vector<std::string> problems);
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// Loads and validates a config file. Throws ConfigError (every problem) or if the file cannot be
// read or parsed.
Config load_config(const std::string& path);

// The environment variables that override keys of the config file (the container image is
// configured with them): the file stays the base, a set variable replaces its key. Checked like the
// key, each problem naming the variable. An empty variable counts as unset.
//   PULLOUT_DOMAIN_ID         dds.domain_id: an integer in [0, 232]
//   PULLOUT_DDS_PROFILE       dds.profiles_file: a profile name, loopback, network or
//                             discovery_client (the file dds/<name>.xml beside the config file), or
//                             the path of an XML file (relative to the config file; e.g. a copy of
//                             dds/initial_peers.xml with the peers filled in); discovery_client
//                             also needs ROS_DISCOVERY_SERVER (Fast DDS reads the server's
//                             ADDRESS:PORT from it)
//   PULLOUT_DDS_SECURITY_DIR  dds.security_dir: DDS Security credentials (the secure setup, with
//                             any of the profiles)
//   PULLOUT_METRICS_ENABLED   observability.metrics.enabled: true or false
//   PULLOUT_METRICS_ADDRESS   observability.metrics.address: an IPv4 address
struct EnvironmentVariable {
  const char* name;
  const char* key;  // the config key it overrides
};
inline constexpr std::array<EnvironmentVariable, 5> kEnvironmentVariables{{
    {"PULLOUT_DOMAIN_ID", "dds.domain_id"},
    {"PULLOUT_DDS_PROFILE", "dds.profiles_file"},
    {"PULLOUT_DDS_SECURITY_DIR", "dds.security_dir"},
    {"PULLOUT_METRICS_ENABLED", "observability.metrics.enabled"},
    {"PULLOUT_METRICS_ADDRESS", "observability.metrics.address"},
}};
// The profile names PULLOUT_DDS_PROFILE accepts (files dds/<name>.xml in config/).
inline constexpr std::array<const char*, 3> kDdsProfileNames{"loopback", "network", "discovery_client"};

// Looks up an environment variable: its value, or nullptr when unset (std::getenv's contract).
using Environment = std::function<const char*(const char*)>;

// load_config, then the overrides of kEnvironmentVariables looked up in `env` (pass
// `[](const char* n) { return std::getenv(n); }` for the process's environment). Throws
// ConfigError with every problem of the file and of the variables.
Config load_config(const std::string& path, const Environment& env);

// "the built-in loopback profiles" or the profiles file's path: for messages.
std::string describe_profiles(const DdsConfig& dds);

// Applies a YAML mapping of start_planner parameters (Autoware names) onto `params`, appending one
// "<prefix>.<key>: <problem>" line per problem. Used by load_config and by scenario files'
// `planner:` section.
void apply_start_planner_parameters(const YAML::Node& node, const std::string& prefix, StartPlannerParameters& params,
                                    std::vector<std::string>& problems);
void apply_vehicle_info(const YAML::Node& node, const std::string& prefix, VehicleInfo& vehicle,
                        std::vector<std::string>& problems);

// Every value of `config` outside its allowed values and every inconsistency between keys, one
// "<key path>: <problem>" line each; empty when valid. What load_config checks after reading,
// except that files (dds.profiles_file, map.path) are not looked for. For configs built in code.
std::vector<std::string> check_config(const Config& config);

// The documented config file for `values`: every key with its value, unit, allowed values and
// comment, in the file's order. documented_config(Config{}) is config/pullout.yaml.
std::string documented_config(const Config& values = Config{});

}  // namespace pullout
