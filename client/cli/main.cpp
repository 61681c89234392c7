// pullout: plan a pull-out in-process, or ask a running pullout service over DDS.
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace {

constexpr const char* kExitCodes =
    "Exit codes:\n"
    "  0    a path was found\n"
    "  1    no path (the reasons are printed)\n"
    "  2    bad input or usage: unreadable or malformed scenario/config (the message names the\n"
    "       field), request rejected by the planner, SVG file not writable\n"
    "  3    communication failure or timeout (request: no service, no answer in time)\n"
    "  4    internal error\n"
    "  130  interrupted\n";

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pullout: start (pull-out) planner for automated vehicles"};
  app.require_subcommand(1);
  app.footer(kExitCodes);

  pullout::cli::PlanOptions plan;
  CLI::App* plan_cmd = app.add_subcommand("plan", "Plan in-process with the service's pipeline");
  plan_cmd->add_option("scenario", plan.scenario_file, "Scenario file (YAML)")->required()->check(CLI::ExistingFile);
  plan_cmd->add_flag("--json", plan.output.json, "Print one JSON object instead of text");
  plan_cmd->add_option("--svg", plan.output.svg_file, "Also draw the scenario and path into this SVG file");
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
  request_cmd->add_option("--svg", request.output.svg_file, "Also draw the scenario and path into this SVG file");
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
      ->check(CLI::PositiveNumber);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help or the usage error
    return code == 0 ? 0 : pullout::cli::kExitBadInput;
  }

  try {
    if (plan_cmd->parsed()) return pullout::cli::run_plan(plan, std::cout, std::cerr);
    pullout::cli::install_interrupt_handlers();
    return pullout::cli::run_request(request, std::cout, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "pullout: internal error: " << e.what() << '\n';
    return pullout::cli::kExitInternal;
  }
}
