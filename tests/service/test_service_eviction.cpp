// The service over a lifetime of vehicles: more distinct vehicle ids than the DDS profiles have
// instances, and more than service.max_vehicles, all served alike.
//
// The real pullout_service process on a leased loopback domain, with a test profile whose
// endpoints hold at most kInstances instances (config/dds/loopback.xml with 4096 replaced) and a
// config with service.max_vehicles = kMaxVehicles. The clients are FleetClients: one participant
// speaking for many vehicles in turn (tests/integration/fleet_client.hpp).
//
// Before eviction (main at 107480b, the config without the new keys) the service answered exactly
// kInstances vehicles and then nobody (every instance of its path and status writers stayed
// registered); and with clients that unregister, it answered nobody after the first: its readers'
// DYNAMIC_REUSABLE memory policy stalls on an unregister sample (config/dds/loopback.xml).
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>

#include "fleet_client.hpp"
#include "pullout/config/scenario.hpp"
#include "service_process.hpp"

namespace pullout {
namespace {

using namespace std::chrono_literals;

const std::string kSourceDir = PULLOUT_SOURCE_DIR;
constexpr int kInstances = 16;
constexpr int kMaxVehicles = 8;
constexpr auto kAnswerTimeout = 5000ms;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// loopback.xml with every endpoint limited to kInstances instances (and as many samples).
std::string small_profiles() {
  const std::string original = read_text(kSourceDir + "/config/dds/loopback.xml");
  const std::string n = std::to_string(kInstances);
  std::string text =
      replace_all(original, "<max_instances>4096</max_instances>", "<max_instances>" + n + "</max_instances>");
  text = replace_all(text, "<max_samples>4096</max_samples>", "<max_samples>" + n + "</max_samples>");
  return text;
}

PullOutRequest request_for(const std::string& vehicle, std::uint64_t request_id) {
  PullOutRequest r = load_scenario(kSourceDir + "/tests/scenarios/straight_shoulder.yaml").request;
  r.vehicle_id = vehicle;
  r.request_id = request_id;
  return r;
}

class ServiceEviction : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string profiles = dir_.write_file("small.xml", small_profiles());
    ASSERT_NE(read_text(profiles).find("<max_instances>16</max_instances>"), std::string::npos);
    const std::string config = dir_.write_file(
        "pullout.yaml", "service:\n  max_vehicles: " + std::to_string(kMaxVehicles) +
                            "\n  session_idle_timeout_s: 600\ndds:\n  profiles_file: " + profiles + "\n");
    integration::ServiceOptions options;
    options.executable = PULLOUT_SERVICE_EXE;
    options.config_path = config;
    service_.emplace(options);
    client_.emplace(service_->domain(), kSourceDir + "/config/dds/loopback.xml");
    ASSERT_TRUE(client_->wait_matched(15000ms)) << service_->stderr_tail();
  }
  void TearDown() override {
    client_.reset();
    if (service_) {
      const integration::StopReport report = service_->stop();
      EXPECT_TRUE(report.clean()) << report.describe() << "\n" << service_->stderr_tail();
    }
  }

  integration::TempDir dir_;
  std::optional<integration::ServiceProcess> service_;
  std::optional<integration::FleetClient> client_;
};

// Vehicles come, are answered, and go (unregister their request instance): three times as many
// as the profiles have instances, each answered like the first, each evicted when it has gone.
TEST_F(ServiceEviction, VehiclesThatLeaveFreeTheirPlace) {
  constexpr int kVehicles = 3 * kInstances;
  for (int i = 0; i < kVehicles; ++i) {
    const std::string vehicle = "churn-" + std::to_string(i);
    ASSERT_TRUE(client_->send(request_for(vehicle, 1000 + i))) << vehicle;
    const auto answer = client_->wait_answer(vehicle, 1000 + i, kAnswerTimeout);
    ASSERT_TRUE(answer.has_value()) << vehicle << " (vehicle " << i + 1 << " of " << kVehicles << ") was not answered\n"
                                    << service_->stderr_tail();
    EXPECT_EQ(answer->status.state, ExecutionState::kWaitingApproval) << vehicle << answer->status.error;
    EXPECT_TRUE(answer->path.found) << vehicle;
    EXPECT_FALSE(answer->path.partial_paths.empty()) << vehicle;
    ASSERT_TRUE(client_->forget(vehicle, true)) << vehicle;
    // The service saw the vehicle go and evicted it (its path instance unregistered). The writer
    // frees an unregistered instance once every reader acknowledged it (next heartbeat, 200 ms).
    ASSERT_TRUE(client_->wait_path_gone(vehicle, kAnswerTimeout)) << vehicle << " was not evicted\n"
                                                                  << service_->stderr_tail();
  }
}

// Vehicles that stay (their request instances stay registered): when max_vehicles sessions are
// held, the least recently active idle one is evicted for a new vehicle, and its path instance is
// unregistered (the reader sees it go).
TEST_F(ServiceEviction, FullServiceEvictsTheLeastRecentlyActiveIdleVehicle) {
  // Fewer than kInstances in all: the vehicles' own request instances stay registered.
  constexpr int kVehicles = kMaxVehicles + 4;
  for (int i = 0; i < kVehicles; ++i) {
    const std::string vehicle = "stay-" + std::to_string(i);
    ASSERT_TRUE(client_->send(request_for(vehicle, 2000 + i))) << vehicle;
    const auto answer = client_->wait_answer(vehicle, 2000 + i, kAnswerTimeout);
    ASSERT_TRUE(answer.has_value()) << vehicle << " was not answered\n" << service_->stderr_tail();
    EXPECT_EQ(answer->status.state, ExecutionState::kWaitingApproval) << vehicle << answer->status.error;
  }
  // stay-0 .. stay-3 were the least recently active when stay-8 .. stay-11 came.
  for (int i = 0; i < kVehicles - kMaxVehicles; ++i) {
    EXPECT_TRUE(client_->wait_path_gone("stay-" + std::to_string(i), kAnswerTimeout)) << "stay-" << i;
  }
  // An evicted vehicle that asks again is served again.
  ASSERT_TRUE(client_->send(request_for("stay-0", 2100)));
  const auto again = client_->wait_answer("stay-0", 2100, kAnswerTimeout);
  ASSERT_TRUE(again.has_value()) << service_->stderr_tail();
  EXPECT_EQ(again->status.state, ExecutionState::kWaitingApproval);
}

// A max_vehicles the profiles' instances cannot hold stops the service at start-up, naming both.
TEST(ServiceEvictionConfig, MaxVehiclesAboveMaxInstancesStopsTheService) {
  integration::TempDir dir;
  integration::DomainLease lease;
  const std::string profiles = dir.write_file("small.xml", small_profiles());
  const std::string config =
      dir.write_file("pullout.yaml", "service:\n  max_vehicles: " + std::to_string(2 * kInstances) +
                                         "\ndds:\n  profiles_file: " + profiles + "\n");
  integration::ChildProcess service(
      {PULLOUT_SERVICE_EXE, "--config", config, "--domain", std::to_string(lease.domain())}, dir.path() + "/out",
      dir.path() + "/err");
  const auto exit = service.wait_exit(20000ms);
  ASSERT_TRUE(exit.has_value()) << "the service did not stop";
  EXPECT_TRUE(exit->exited && exit->exit_code != 0 && exit->exit_code != integration::kSanitizerExitCode)
      << exit->describe();
  const std::string err = read_text(dir.path() + "/err");
  EXPECT_NE(err.find("service.max_vehicles = 32"), std::string::npos) << err;
  EXPECT_NE(err.find("max_instances = 16"), std::string::npos) << err;
}

}  // namespace
}  // namespace pullout
