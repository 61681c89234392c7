// The `pullout plan` tool as a user runs it: the real binary on the bundled scenarios, its JSON
// read back. What it prints is the first status the service would publish after planning.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "pullout/config/scenario.hpp"

namespace pullout {
namespace {

struct CliRun {
  int exit_code{-1};
  std::string out;
};

CliRun run_cli(const std::string& arguments) {
  const std::string command = std::string(PULLOUT_CLI_EXE) + " " + arguments + " 2>/dev/null";
  CliRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

std::string scenario_file(const std::string& name) {
  return std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + name + ".yaml";
}

class PlanVerdict : public ::testing::TestWithParam<const char*> {};

// The verdict printed before departure is the file's `expect: {safe: ...}`, on inline lanes and
// on a map route alike.
TEST_P(PlanVerdict, JsonCarriesTheSafetyVerdictAtTheStart) {
  const Scenario sc = load_scenario(scenario_file(GetParam()));
  ASSERT_TRUE(sc.expect.safe.has_value());
  const CliRun run = run_cli("plan " + scenario_file(GetParam()) + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const auto json = nlohmann::json::parse(run.out);
  EXPECT_EQ(json.at("state"), "waiting_approval");
  EXPECT_EQ(json.at("safe").get<bool>(), *sc.expect.safe) << run.out;
}

INSTANTIATE_TEST_SUITE_P(Bundled, PlanVerdict,
                         ::testing::Values("traffic_fast_from_behind", "traffic_far_behind", "traffic_cannot_pass",
                                           "map_traffic_fast_from_behind"));

TEST(PlanText, SaysUnsafeForAFastCarFromBehind) {
  const CliRun run = run_cli("plan " + scenario_file("traffic_fast_from_behind"));
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("safe: no"), std::string::npos) << run.out;
}

}  // namespace
}  // namespace pullout
