// Fuzz target: one pullout/request sample, from its bytes to the answer, the way the service
// handles it (service/src/service/pullout_service.cpp), without DDS:
//
//   bytes -> SerializedPayload_t -> GuardedType<PullOutRequestPubSubType>::deserialize and getKey
//   (what the request reader does) -> the vehicle_id size check -> idl::from_msg -> a fresh
//   VehicleSession::on_request (full validation) -> StartPlanner::plan within kDeadlineMs ->
//   on_result (the safety verdict at the start) -> the path and status to publish, converted with
//   idl::to_msg and serialized with the guarded type support (what the writers do).
//
// The planner has the shipped parameters and vehicle profiles (config/pullout.yaml: a request may
// name the van or the bus) and the project's Lanelet2 map (tests/maps/straight_shoulder.osm), so
// that route requests are planned too. A crash, a sanitizer report or an exception escaping is a
// defect; so is an input whose handling takes more than libFuzzer's -timeout (scripts/fuzz: 1 s),
// since the search is bounded by kDeadlineMs.
// With PULLOUT_FUZZ_VERBOSE set, each input's outcome is printed (to read a reproducer).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <vector>

#include "fuzz_dds.hpp"
#include "pullout/config/config.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/model/names.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/session/vehicle_session.hpp"

namespace {

using pullout::fuzz::publish;

// [ms] The planning budget of every input: short, so that a run tries many inputs; the time an
// input takes beyond it is work that ignores the stop condition.
constexpr double kDeadlineMs = 50.0;

struct Fixture {
  Fixture()
      : config(pullout::load_config(PULLOUT_SOURCE_DIR "/config/pullout.yaml")),
        planner(config.vehicle, config.start_planner, config.service.limits,
                pullout::load_lanelet_map(PULLOUT_SOURCE_DIR "/tests/maps/straight_shoulder.osm"),
                config.vehicle_profiles) {}

  pullout::Config config;
  pullout::StartPlanner planner;
  bool verbose{std::getenv("PULLOUT_FUZZ_VERBOSE") != nullptr};
  pullout::idl::GuardedType<pullout::msg::PullOutRequestPubSubType> request_type;
  pullout::idl::GuardedType<pullout::msg::PullOutPathPubSubType> path_type;
  pullout::idl::GuardedType<pullout::msg::PullOutStatusPubSubType> status_type;
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void publish_effects(Fixture& f, const pullout::SessionEffects& effects) {
  if (effects.path) publish(f.path_type, pullout::idl::to_msg(*effects.path));
  if (effects.status) publish(f.status_type, pullout::idl::to_msg(*effects.status));
}

}  // namespace

// The fixture is made before the first input, so that its cost is not counted in -timeout.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  fixture();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Fixture& f = fixture();
  pullout::msg::PullOutRequest sample;
  if (!pullout::fuzz::receive(f.request_type, data, size, sample)) return 0;  // the reader or the service drops it

  std::vector<pullout::RequestIssue> issues;
  pullout::PullOutRequest request = pullout::idl::from_msg(sample, issues);
  pullout::VehicleSession session(request.vehicle_id, f.planner,
                                  pullout::SessionOptions{f.config.service.progress_timeout_s});
  const auto now = std::chrono::steady_clock::now();
  const pullout::SessionEffects accepted = session.on_request(std::move(request), issues, now);
  publish_effects(f, accepted);
  if (!accepted.search) {
    if (f.verbose && accepted.status) std::cerr << "fuzz_request: not planned: " << accepted.status->error << "\n";
    return 0;
  }

  const pullout::PlanningResult result =
      f.planner.plan(accepted.search->request, pullout::StopCondition::after_ms(kDeadlineMs));
  if (f.verbose) {
    std::cerr << "fuzz_request: "
              << (result.outcome == pullout::PlanningResult::Outcome::kFound ? "found" : "not found") << " ("
              << pullout::to_string(result.path.planner_type) << ") in " << result.planning_time_ms
              << " ms: " << result.stop_reason << pullout::format_issues(result.issues) << "\n";
  }
  publish_effects(f, session.on_result(accepted.search->sequence, result, std::chrono::steady_clock::now()));
  return 0;
}
