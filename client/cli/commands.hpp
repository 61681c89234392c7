// The two subcommands of the pullout CLI. Each returns the process exit code:
//   0 a path was found, 1 no path, 2 bad input (unreadable or malformed scenario/config, rejected
//   request, unwritable SVG), 3 communication failure or timeout (request only), 4 internal error,
//   130 interrupted (SIGINT/SIGTERM during a request).
// Results go to `out`; diagnostics (one clear line each) to `err`.
#pragma once

#include <ostream>
#include <string>

namespace pullout::cli {

inline constexpr int kExitFound = 0;
inline constexpr int kExitNoPath = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitCommunication = 3;
inline constexpr int kExitInternal = 4;
inline constexpr int kExitInterrupted = 130;

struct OutputOptions {
  bool json{false};
  std::string svg_file;   // empty: no SVG
  bool svg_whole{false};  // the SVG's main view shows the whole scene (no manoeuvre framing, no inset)
};

struct PlanOptions {
  std::string scenario_file;
  std::string config_file;  // empty: built-in defaults
  OutputOptions output;
};

struct RequestOptions {
  std::string scenario_file;
  int domain_id{0};
  std::string profiles_file;  // empty: built-in loopback-only DDS defaults
  std::string security_dir;   // empty: no DDS Security
  double timeout_s{10.0};     // whole exchange: discovery, planning, reply
  OutputOptions output;
};

struct WatchOptions {
  int domain_id{0};
  std::string profiles_file;  // empty: built-in loopback-only DDS profiles
  double interval_s{1.0};     // redraw period
  double duration_s{0.0};     // > 0: stop after this long; 0: until interrupted
  bool once{false};           // print one table once the service's samples have arrived, then exit
  double wait_s{5.0};         // --once: wait at most this long for the service
};

struct ViewOptions {
  std::string http{"127.0.0.1:8080"};  // ADDRESS:PORT to listen on (port 0: any free port)
  int domain_id{0};
  bool domain_given{false};  // --domain was given (else a --config's dds.domain_id applies)
  std::string profiles_file;
  bool profiles_given{false};
  std::string config_file;  // pullout.yaml: the vehicle drawn, and dds.* as defaults
  double duration_s{0.0};   // > 0: stop after this long; 0: until interrupted
};

int run_plan(const PlanOptions& options, std::ostream& out, std::ostream& err);
int run_request(const RequestOptions& options, std::ostream& out, std::ostream& err);
// `pullout watch`: 0 when stopped by --duration, --once or an interrupt; 2 bad options; 3 DDS
// setup failed, or --once found no service within wait_s (the table is printed anyway).
// `terminal`: redraw in place with ANSI escapes instead of printing one table after another.
int run_watch(const WatchOptions& options, bool terminal, std::ostream& out, std::ostream& err);

// `pullout view`: serves the web page until interrupted (or --duration); prints its URL first.
// 0 when stopped, 2 bad options or the address cannot be listened on, 3 DDS setup failed.
int run_view(const ViewOptions& options, std::ostream& out, std::ostream& err);

// Makes SIGINT and SIGTERM interrupt run_request's waits (which then return kExitInterrupted)
// and end run_watch, instead of killing the process without deleting its DDS participant.
void install_interrupt_handlers();
// Whether SIGINT or SIGTERM arrived since install_interrupt_handlers().
bool interrupted();

}  // namespace pullout::cli
