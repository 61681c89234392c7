// Fuzz target: one pullout/progress sample, from its bytes to the answer, the way the service
// handles it (service/src/service/pullout_service.cpp), without DDS, against a vehicle that has a
// path:
//
//   bytes -> SerializedPayload_t -> GuardedType<ExecutionProgressPubSubType>::deserialize and getKey
//   (what the progress reader does) -> the vehicle_id size check -> idl::from_msg -> a
//   VehicleSession that planned tests/scenarios/straight_shoulder.yaml (waiting for approval) ->
//   on_progress three times: the sample as it came, the same sample approved 100 ms later (a
//   departure when it stands at the start), the same sample with the approval withdrawn 100 ms
//   after that (a stop inserted from its speed) -> the path and status to publish, converted with
//   idl::to_msg and serialized with the guarded type support (what the writers do).
//
// The sample's request id 0 stands for the session's own request (so that most inputs reach the
// departure rules); any other id is kept (a sample for another request, ignored). A crash, a
// sanitizer report, an exception escaping or an input taking more than libFuzzer's -timeout
// (scripts/fuzz: 1 s) is a defect: a progress sample costs microseconds.
// With PULLOUT_FUZZ_VERBOSE set, each sample's outcome is printed (to read a reproducer).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "fuzz_dds.hpp"
#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/idl/convert.hpp"
#include "pullout/idl/guarded_type.hpp"
#include "pullout/model/names.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/session/vehicle_session.hpp"

namespace {

using pullout::fuzz::publish;

struct Fixture {
  Fixture()
      : config(pullout::load_config(PULLOUT_SOURCE_DIR "/config/pullout.yaml")),
        scenario(pullout::load_scenario(PULLOUT_SOURCE_DIR "/tests/scenarios/straight_shoulder.yaml")),
        planner(config.vehicle, config.start_planner, config.service.limits, nullptr, config.vehicle_profiles) {
    scenario.request.vehicle_id = "fuzz";
    result = planner.plan(scenario.request, pullout::StopCondition());
    if (result.outcome != pullout::PlanningResult::Outcome::kFound) {
      throw std::runtime_error("fuzz_progress: straight_shoulder has no path");
    }
  }

  pullout::Config config;
  pullout::Scenario scenario;
  pullout::StartPlanner planner;
  pullout::PlanningResult result;
  bool verbose{std::getenv("PULLOUT_FUZZ_VERBOSE") != nullptr};
  pullout::idl::GuardedType<pullout::msg::ExecutionProgressPubSubType> progress_type;
  pullout::idl::GuardedType<pullout::msg::PullOutPathPubSubType> path_type;
  pullout::idl::GuardedType<pullout::msg::PullOutStatusPubSubType> status_type;
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void publish_effects(Fixture& f, const pullout::SessionEffects& effects, const char* step) {
  if (effects.path) publish(f.path_type, pullout::idl::to_msg(*effects.path));
  if (effects.status) publish(f.status_type, pullout::idl::to_msg(*effects.status));
  if (f.verbose) {
    std::cerr << "fuzz_progress: " << step << ": "
              << (effects.status ? pullout::to_string(effects.status->state) : "no status") << " "
              << (effects.status ? effects.status->error : std::string()) << " " << effects.note << "\n";
  }
}

}  // namespace

// The fixture (a plan) is made before the first input, so that its cost is not counted in -timeout.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  fixture();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Fixture& f = fixture();
  pullout::msg::ExecutionProgress sample;
  if (!pullout::fuzz::receive(f.progress_type, data, size, sample)) return 0;  // the reader or the service drops it
  std::vector<pullout::RequestIssue> issues;
  pullout::ExecutionProgress progress = pullout::idl::from_msg(sample, issues);
  if (!issues.empty()) {  // the service answers a conversion problem without the session
    if (f.verbose) std::cerr << "fuzz_progress: not converted: " << pullout::format_issues(issues) << "\n";
    return 0;
  }

  pullout::VehicleSession session(f.scenario.request.vehicle_id, f.planner,
                                  pullout::SessionOptions{f.config.service.progress_timeout_s});
  auto now = std::chrono::steady_clock::now();
  const pullout::SessionEffects ordered = session.on_request(f.scenario.request, {}, now);
  if (!ordered.search) return 0;
  session.on_result(ordered.search->sequence, f.result, now);
  if (progress.request_id == 0) progress.request_id = session.status().request_id;

  now += std::chrono::milliseconds(100);
  publish_effects(f, session.on_progress(progress, now), "as sent");
  progress.approved = true;
  progress.stamp_ns += 100'000'000;
  now += std::chrono::milliseconds(100);
  publish_effects(f, session.on_progress(progress, now), "approved");
  progress.approved = false;
  progress.stamp_ns += 100'000'000;
  now += std::chrono::milliseconds(100);
  publish_effects(f, session.on_progress(progress, now), "withdrawn");
  return 0;
}
