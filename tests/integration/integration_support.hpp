// Shared pieces of the integration tests: a GoogleTest fixture that runs the real pullout_service
// on a domain of its own and checks, after every test, that it stopped cleanly (exit status 0,
// nothing left in /dev/shm); clients on that domain; scenario loading; path invariants.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "pullout/client/client.hpp"
#include "pullout/config/config.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/model/types.hpp"
#include "service_process.hpp"

namespace pullout::integration {

// Bounds of the waits. Generous: the machine may be busy with builds; a healthy run takes a
// fraction of each.
constexpr std::chrono::seconds kMatchTimeout{15};
constexpr std::chrono::seconds kReplyTimeout{10};

std::string source_path(const std::string& relative);  // PULLOUT_SOURCE_DIR/relative
std::string scenario_path(const std::string& name);    // tests/scenarios/<name>.yaml
std::string default_config_path();                     // config/pullout.yaml
std::string loopback_profiles_path();                  // config/dds/loopback.xml

// The scenario on top of config/pullout.yaml (what the service plans with).
Scenario load_test_scenario(const std::string& name);

// The request moved by (dx, dy) in the map frame (poses, lanes, objects and their predictions,
// the grid's origin): two test vehicles on one service are then far apart, so that neither is
// held for the other's path (vehicles that see each other, issue 15). Inline lanes only.
void translate(PullOutRequest& request, double dx, double dy);

// Checks the invariants of a found PullOutPath (DESIGN.md): found, pairs == partial paths >= 1,
// every partial path >= 2 finite points, constant driving direction inside a partial path,
// consecutive partial paths join.
void expect_found_path_invariants(const PullOutPath& path);

// One odometry sample of the vehicle executing request `request_id`.
ExecutionProgress progress_sample(std::uint64_t request_id, std::int64_t stamp_ns, const Pose2& pose,
                                  double velocity_mps, bool approved);

class ServiceTest : public ::testing::Test {
 protected:
  void TearDown() override;

  // Starts pullout_service with `config_path` (default: config/pullout.yaml); fails the test
  // (fatal) when it does not become ready.
  void start_service(const std::string& config_path = default_config_path());

  // A client of `vehicle` on the service's domain, matched with the service (fatal failure when
  // it does not match within kMatchTimeout). profiles_file empty: the client's built-in
  // loopback defaults.
  std::unique_ptr<Client> connect(const std::string& vehicle, const std::string& profiles_file = "");

  // Starts the service (default config), connects `vehicle`, sends the scenario's request and
  // waits for its path (nullopt on timeout; a found path is checked against the invariants).
  struct Sent {
    Scenario scenario;
    std::unique_ptr<Client> client;
    std::uint64_t id{0};
    std::optional<PullOutPath> path;
  };
  Sent start_and_send(const std::string& scenario_name, const std::string& vehicle);

  int domain() const { return service_ ? service_->domain() : -1; }
  ServiceProcess& service() { return *service_; }
  std::string service_stderr() const { return service_ ? service_->stderr_tail() : ""; }

  TempDir temp_;

 private:
  std::optional<ServiceProcess> service_;
};

}  // namespace pullout::integration
