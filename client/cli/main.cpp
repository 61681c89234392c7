// pullout: plan a pull-out in-process, or ask a running pullout service over DDS.
#include <cmath>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "health_probe.hpp"
#include "pullout/version.hpp"

namespace {

constexpr const char* kExitCodes =
    "Exit codes:\n"
    "  0    a path was found\n"
    "  1    no path (the reasons are printed)\n"
    "  2    bad input or usage: unreadable or malformed scenario/config (the message names the\n"
    "       field), request rejected by the planner, SVG file not writable\n"
    "  3    communication failure or timeout (request: no service, no answer in time)\n"
    "  4    internal error\n"
    "  130  interrupted\n"
    "view: 0 stopped, 2 bad option or address in use, 3 DDS setup failed\n"
    "watch: 0 stopped (--duration, --once, interrupt), 3 DDS setup failed or --once found no service\n"
    "health: 0 the URL answered 200, 1 another HTTP status, 2 bad URL, 3 no answer (refused, timeout)\n";

// The options that take seconds. CLI::PositiveNumber would print its range, "0.000000 to " and the
// 309 digits of the largest double, for 0; this says what is meant. Infinity and NaN are refused
// too: a run that waits forever is asked for by leaving --duration out.
const CLI::Validator kPositiveSeconds(
    [](std::string& value) -> std::string {
      char* end = nullptr;
      const double v = std::strtod(value.c_str(), &end);
      if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(v) || !(v > 0.0)) {
        return "must be a positive number of seconds, got '" + value + "'";
      }
      return {};
    },
    "SECONDS > 0");

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pullout: start (pull-out) planner for automated vehicles"};
  app.require_subcommand(1);
  app.footer(kExitCodes);
  app.set_version_flag("--version", std::string("pullout ") + pullout::kVersionString);

  pullout::cli::PlanOptions plan;
  CLI::App* plan_cmd = app.add_subcommand("plan", "Plan in-process with the service's pipeline");
  plan_cmd->add_option("scenario", plan.scenario_file, "Scenario file (YAML)")->required()->check(CLI::ExistingFile);
  plan_cmd->add_flag("--json", plan.output.json, "Print one JSON object instead of text");
  CLI::Option* plan_svg = plan_cmd->add_option("--svg", plan.output.svg_file,
                                               "Also draw the scenario and path into this SVG file (framed on the "
                                               "manoeuvre, the whole scene in an inset)");
  plan_cmd->add_flag("--svg-whole", plan.output.svg_whole, "The SVG shows the whole scene, no inset")->needs(plan_svg);
  plan_cmd->add_option("--config", plan.config_file, "pullout.yaml to start from (default: built-in defaults)")
      ->check(CLI::ExistingFile);

  pullout::cli::RequestOptions request;
  CLI::App* request_cmd = app.add_subcommand(
      "request",
      "Send the scenario's request to a running pullout service over DDS and print its answer (path and "
      "final status). The service plans with its own vehicle and parameters: of the scenario's vehicle and "
      "planner sections only planner.search_priority and planner.search_policy are sent (as request "
      "overrides).");
  request_cmd->add_option("scenario", request.scenario_file, "Scenario file (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  request_cmd->add_flag("--json", request.output.json, "Print one JSON object instead of text");
  CLI::Option* request_svg = request_cmd->add_option("--svg", request.output.svg_file,
                                                     "Also draw the scenario and path into this SVG file (framed on "
                                                     "the manoeuvre, the whole scene in an inset)");
  request_cmd->add_flag("--svg-whole", request.output.svg_whole, "The SVG shows the whole scene, no inset")
      ->needs(request_svg);
  request_cmd->add_option("--domain", request.domain_id, "DDS domain id")
      ->capture_default_str()
      ->check(CLI::Range(0, 232));
  request_cmd
      ->add_option("--profiles", request.profiles_file, "Fast DDS XML profiles file (default: built-in, loopback only)")
      ->check(CLI::ExistingFile);
  request_cmd
      ->add_option("--security-dir", request.security_dir,
                   "DDS Security credentials of the scenario's vehicle (ca.pem, cert.pem, key.pem, governance.p7s, "
                   "permissions.p7s; scripts/make-test-pki makes test ones). Default: no security")
      ->check(CLI::ExistingDirectory);
  request_cmd->add_option("--timeout", request.timeout_s, "Seconds to wait for the service and its answer")
      ->capture_default_str()
      ->check(kPositiveSeconds);

  pullout::cli::HealthOptions health;
  CLI::App* health_cmd = app.add_subcommand(
      "health",
      "GET an HTTP URL (e.g. the service's http://127.0.0.1:9464/readyz) and exit 0 if it answers 200: a "
      "container HEALTHCHECK without curl");
  health_cmd->add_option("url", health.url, "http://host:port/path")->required();
  health_cmd->add_option("--timeout", health.timeout_s, "Seconds for connecting and the answer")
      ->capture_default_str()
      ->check(kPositiveSeconds);
  health_cmd->add_flag("-q,--quiet", health.quiet, "Print nothing on success");

  pullout::cli::WatchOptions watch;
  CLI::App* watch_cmd = app.add_subcommand(
      "watch",
      "Print a live table of every vehicle on the DDS domain (state, planner, segment i/n, safe, age of its latest "
      "sample), read from the service's path and status topics and the vehicles' requests and progress as a passive "
      "participant. On a terminal the table is redrawn in place; otherwise one table is printed per interval");
  watch_cmd->add_option("--domain", watch.domain_id, "DDS domain id")->capture_default_str()->check(CLI::Range(0, 232));
  watch_cmd
      ->add_option("--profiles", watch.profiles_file, "Fast DDS XML profiles file (default: built-in, loopback only)")
      ->check(CLI::ExistingFile);
  watch_cmd->add_option("--interval", watch.interval_s, "Seconds between tables")
      ->capture_default_str()
      ->check(kPositiveSeconds);
  CLI::Option* duration_opt =
      watch_cmd->add_option("--duration", watch.duration_s, "Stop after this many seconds")->check(kPositiveSeconds);
  watch_cmd
      ->add_flag("--once", watch.once,
                 "Print one table once the service's samples have arrived (at most --wait seconds), then exit")
      ->excludes(duration_opt);
  watch_cmd->add_option("--wait", watch.wait_s, "--once: seconds to wait for the service")
      ->capture_default_str()
      ->check(kPositiveSeconds);

  pullout::cli::ViewOptions view;
  CLI::App* view_cmd = app.add_subcommand(
      "view",
      "Serve a web page that draws every vehicle on the DDS domain (lanes of its request, footprint, path with the "
      "current segment highlighted, state), updated as samples arrive (Server-Sent Events). Listens on loopback "
      "unless told otherwise");
  view_cmd->add_option("--http", view.http, "ADDRESS:PORT to serve the page on (port 0: any free port)")
      ->capture_default_str();
  CLI::Option* view_domain =
      view_cmd->add_option("--domain", view.domain_id, "DDS domain id (default: --config's dds.domain_id, else 0)")
          ->check(CLI::Range(0, 232));
  CLI::Option* view_profiles =
      view_cmd
          ->add_option("--profiles", view.profiles_file,
                       "Fast DDS XML profiles file (default: --config's dds.profiles_file, else built-in loopback)")
          ->check(CLI::ExistingFile);
  view_cmd
      ->add_option("--config", view.config_file,
                   "pullout.yaml of the service: its vehicle is the footprint drawn, its dds section the defaults")
      ->check(CLI::ExistingFile);
  view_cmd->add_option("--duration", view.duration_s, "Stop after this many seconds")->check(kPositiveSeconds);

  // CLI11 answers a misspelt command with "A subcommand is required", as if none had been given:
  // name it. The first argument that is not an option is the command (the top level takes flags only).
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (!arg.empty() && arg[0] == '-') continue;
    try {
      app.get_subcommand(arg);
    } catch (const CLI::OptionNotFound&) {
      std::cerr << "pullout: unknown command '" << arg << "' (plan, request, watch, view, health)\n"
                << "Run with --help for more information.\n";
      return pullout::cli::kExitBadInput;
    }
    break;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help or the usage error
    return code == 0 ? 0 : pullout::cli::kExitBadInput;
  }

  try {
    if (plan_cmd->parsed()) return pullout::cli::run_plan(plan, std::cout, std::cerr);
    if (health_cmd->parsed()) return pullout::cli::run_health(health, std::cout, std::cerr);
    pullout::cli::install_interrupt_handlers();
    if (view_cmd->parsed()) {
      view.domain_given = view_domain->count() > 0;
      view.profiles_given = view_profiles->count() > 0;
      return pullout::cli::run_view(view, std::cout, std::cerr);
    }
    if (watch_cmd->parsed()) return pullout::cli::run_watch(watch, isatty(STDOUT_FILENO) == 1, std::cout, std::cerr);
    return pullout::cli::run_request(request, std::cout, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "pullout: internal error: " << e.what() << '\n';
    return pullout::cli::kExitInternal;
  }
}
