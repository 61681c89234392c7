// The `pullout plan` tool as a user runs it: the real binary on the bundled scenarios, its JSON
// read back. What it prints is the first status the service would publish after planning.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <tinyxml2.h>
#include <nlohmann/json.hpp>

#include "pullout/config/scenario.hpp"

namespace pullout {
namespace {

struct CliRun {
  int exit_code{-1};
  std::string out;
};

// `stderr_too`: stderr is read with stdout (for the messages of bad options), else discarded.
CliRun run_cli(const std::string& arguments, bool stderr_too = false) {
  const std::string command = std::string(PULLOUT_CLI_EXE) + " " + arguments + (stderr_too ? " 2>&1" : " 2>/dev/null");
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

// `pullout plan` plans the scenario's own vehicle only; a fleet in the file is named on stderr,
// not dropped without a word (and a scenario without one gets no note).
TEST(PlanText, SaysThatTheFleetIsNotPlanned) {
  const auto stderr_of = [](const std::string& scenario) {
    const std::string command = std::string(PULLOUT_CLI_EXE) + " plan " + scenario_file(scenario) + " 2>&1 >/dev/null";
    std::string err;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return err;
    std::array<char, 4096> buffer{};
    std::size_t n = 0;
    while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) err.append(buffer.data(), n);
    ::pclose(pipe);
    return err;
  };
  EXPECT_NE(stderr_of("fleet_opposite_shoulders").find("the scenario's fleet (1 other vehicle) is not planned here"),
            std::string::npos);
  EXPECT_EQ(stderr_of("straight_shoulder").find("fleet"), std::string::npos);
}

TEST(PlanText, SaysUnsafeForAFastCarFromBehind) {
  const CliRun run = run_cli("plan " + scenario_file("traffic_fast_from_behind"));
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("safe: no"), std::string::npos) << run.out;
}

// The picture of a pull-out from a tight spot: framed on the manoeuvre, the whole 100 m road in an
// inset, one number per segment, a footprint at every change of direction.
TEST(PlanSvg, FreespaceBoxedInIsFramedOnTheManoeuvre) {
  const auto file =
      std::filesystem::temp_directory_path() / ("pullout_test_cli_boxed_in_" + std::to_string(::getpid()) + ".svg");
  const CliRun run = run_cli("plan " + scenario_file("freespace_boxed_in") + " --json --svg " + file.string());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const auto json = nlohmann::json::parse(run.out);
  ASSERT_EQ(json.at("planner"), "freespace");
  const auto& segments = json.at("segments");
  std::size_t changes = 0;
  for (std::size_t i = 1; i < segments.size(); ++i) {
    if (segments[i].at("direction") != segments[i - 1].at("direction")) ++changes;
  }
  ASSERT_GE(changes, 1u);  // the scenario wiggles out

  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(file.c_str()), tinyxml2::XML_SUCCESS) << doc.ErrorStr();
  std::filesystem::remove(file);
  std::vector<const tinyxml2::XMLElement*> elements;
  std::vector<const tinyxml2::XMLElement*> stack{doc.RootElement()};
  while (!stack.empty()) {
    const auto* e = stack.back();
    stack.pop_back();
    elements.push_back(e);
    for (const auto* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) stack.push_back(c);
  }
  const auto count = [&](const char* css_class) {
    std::size_t n = 0;
    for (const auto* e : elements) n += e->Attribute("class", css_class) != nullptr ? 1 : 0;
    return n;
  };
  EXPECT_EQ(count("segment-label"), segments.size());
  EXPECT_EQ(count("footprint-cusp"), changes);
  EXPECT_EQ(count("inset-frame"), 1u);
  EXPECT_EQ(count("inset-segment"), segments.size());
  // The main view's width in metres, from the scale bar (its first line is the bar, its text the
  // length): well under the 100 m road.
  const tinyxml2::XMLElement* bar = nullptr;
  const tinyxml2::XMLElement* frame = nullptr;
  for (const auto* e : elements) {
    if (e->Attribute("id", "scale-bar") != nullptr) bar = e;
    if (e->Attribute("class", "frame") != nullptr) frame = e;
  }
  ASSERT_NE(bar, nullptr);
  ASSERT_NE(frame, nullptr);
  const auto* line = bar->FirstChildElement("line");
  const double bar_px = line->DoubleAttribute("x2") - line->DoubleAttribute("x1");
  const double bar_m = std::stod(bar->FirstChildElement("text")->GetText());
  const double view_m = frame->DoubleAttribute("width") / (bar_px / bar_m);
  EXPECT_LT(view_m, 50.0);
  EXPECT_GT(view_m, 10.0);
}

TEST(PlanSvg, SvgWholeDrawsTheWholeSceneWithoutAnInset) {
  const auto file =
      std::filesystem::temp_directory_path() / ("pullout_test_cli_whole_" + std::to_string(::getpid()) + ".svg");
  const CliRun run =
      run_cli("plan " + scenario_file("freespace_boxed_in") + " --svg " + file.string() + " --svg-whole");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(file.c_str()), tinyxml2::XML_SUCCESS) << doc.ErrorStr();
  std::filesystem::remove(file);
  for (const auto* g = doc.RootElement()->FirstChildElement("g"); g != nullptr; g = g->NextSiblingElement("g")) {
    EXPECT_EQ(g->Attribute("id", "inset"), nullptr);
  }
  // The road's outline (0..100 m) is drawn whole: one lane-road polygon with its stroke.
  bool road = false;
  for (const auto* g = doc.RootElement()->FirstChildElement("g"); g != nullptr; g = g->NextSiblingElement("g")) {
    for (const auto* e = g->FirstChildElement("polygon"); e != nullptr; e = e->NextSiblingElement("polygon")) {
      if (e->Attribute("class", "lane-road") != nullptr) road = e->Attribute("stroke", "none") == nullptr;
    }
  }
  EXPECT_TRUE(road);
}

// `pullout plan SCENARIO --config pullout.yaml` plans like the service with that config: a route
// without `map:` is planned on the config's map.path, as the service does (it was rejected with
// "no Lanelet2 map is loaded by this planner: send inline lanes instead").
TEST(PlanConfig, ARouteWithoutMapIsPlannedOnTheConfigsMap) {
  const auto dir = std::filesystem::temp_directory_path() / ("pullout_test_cli_map_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string map = std::string(PULLOUT_SOURCE_DIR) + "/tests/maps/straight_shoulder.osm";
  {
    std::ofstream config(dir / "pullout.yaml");
    config << "map: {path: " << map << "}\n";
    std::ifstream in(scenario_file("map_shoulder"));
    std::ofstream scenario(dir / "route_only.yaml");
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("map:", 0) != 0) scenario << line << '\n';
    }
  }
  const std::string scenario = (dir / "route_only.yaml").string();
  const CliRun with_map = run_cli("plan " + scenario + " --json --config " + (dir / "pullout.yaml").string());
  const CliRun without = run_cli("plan " + scenario + " --json");
  std::filesystem::remove_all(dir);
  ASSERT_EQ(with_map.exit_code, 0) << with_map.out;
  EXPECT_EQ(nlohmann::json::parse(with_map.out).at("planner"), "shift");
  // Without a config (no map anywhere) it stays a rejection naming the route.
  EXPECT_EQ(without.exit_code, 2) << without.out;
  EXPECT_NE(without.out.find("route_lanelet_ids"), std::string::npos) << without.out;
}

// A rejected request has no path (report.hpp): `pullout plan` printed the session's empty one as
// "start pose: x 0.000 m  y 0.000 m" and the error a second time under "reasons:", unlike
// `pullout request` for the same answer.
TEST(PlanText, ARejectedRequestPrintsTheErrorOnceAndNoPose) {
  const auto dir = std::filesystem::temp_directory_path() / ("pullout_test_cli_rejected_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ifstream in(scenario_file("straight_shoulder"));
    std::ofstream scenario(dir / "tram.yaml");
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("expect:", 0) != 0) scenario << line << '\n';
    }
    scenario << "vehicle: {profile: tram}\n";
  }
  const CliRun run = run_cli("plan " + (dir / "tram.yaml").string());
  std::filesystem::remove_all(dir);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  const std::string error = "vehicle_profile: unknown profile 'tram'";
  ASSERT_NE(run.out.find(error), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find(error, run.out.find(error) + 1), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("start pose:"), std::string::npos) << run.out;
}

// A number of seconds that is not positive is refused naming the option in plain words; CLI11's own
// range check printed "Value 0 not in range 0.000000 to " and the 309 digits of the largest double.
TEST(Options, ANonPositiveNumberOfSecondsIsRefusedInPlainWords) {
  const std::string scenario = scenario_file("straight_shoulder");
  for (const std::string& arguments :
       {"request " + scenario + " --timeout 0", "request " + scenario + " --timeout -1",
        "request " + scenario + " --timeout nan", "request " + scenario + " --timeout inf",
        "request " + scenario + " --timeout 5s", std::string("watch --interval 0"), std::string("watch --duration -2"),
        std::string("watch --once --wait inf"), std::string("view --duration 0"),
        std::string("health http://127.0.0.1:1/ --timeout 0")}) {
    const CliRun run = run_cli(arguments, true);
    EXPECT_EQ(run.exit_code, 2) << arguments << ": " << run.out;
    const std::string option = arguments.substr(arguments.rfind("--"), arguments.rfind(' ') - arguments.rfind("--"));
    EXPECT_NE(run.out.find(option + ": must be a positive number of seconds"), std::string::npos)
        << arguments << ": " << run.out;
    EXPECT_EQ(run.out.find("179769"), std::string::npos) << arguments << ": " << run.out;
  }
}

// A misspelt command is named with the commands there are; CLI11 said only "A subcommand is
// required", as if none had been given.
TEST(Options, AnUnknownCommandIsNamed) {
  const CliRun run = run_cli("pln " + scenario_file("straight_shoulder"), true);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("unknown command 'pln'"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("plan, request, watch, view, health"), std::string::npos) << run.out;
}

// --svg-whole only shapes the picture --svg writes: alone it is a usage error, not ignored.
TEST(Options, SvgWholeWithoutSvgIsAUsageError) {
  const CliRun run = run_cli("plan " + scenario_file("straight_shoulder") + " --svg-whole", true);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("--svg-whole requires --svg"), std::string::npos) << run.out;
}

}  // namespace
}  // namespace pullout
