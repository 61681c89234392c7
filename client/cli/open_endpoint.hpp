// Opening the CLI's DDS endpoints (a pullout::Client for `request`, a FleetMonitor for `watch` and
// `view`) with one answer to a failure: a line naming the reason, and the exit code.
#pragma once

#include <optional>
#include <ostream>
#include <stdexcept>
#include <utility>

#include "commands.hpp"

namespace pullout::cli {

// Constructs `endpoint` from `options`. On failure writes "pullout: ..." to `err` and returns the
// exit code: kExitBadInput for a bad option (std::invalid_argument, e.g. the domain id),
// kExitCommunication when DDS cannot be set up (SetupError: ClientError, FleetMonitorError).
template <typename SetupError, typename Endpoint, typename Options>
std::optional<int> open_endpoint(std::optional<Endpoint>& endpoint, Options&& options, std::ostream& err) {
  try {
    endpoint.emplace(std::forward<Options>(options));
  } catch (const std::invalid_argument& e) {
    err << "pullout: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const SetupError& e) {
    err << "pullout: DDS setup failed: " << e.what() << '\n';
    return kExitCommunication;
  }
  return std::nullopt;
}

}  // namespace pullout::cli
