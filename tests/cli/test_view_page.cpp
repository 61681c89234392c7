// `pullout view` in a real browser: the real service, a real vehicle driven through the segments
// of its path over loopback DDS, the real `pullout view` process, and headless Chromium on the
// page, checked through the DevTools protocol while the scenario runs. One page load for the whole
// run: what changes is drawn by the page's live updates. Screenshots stay in the build tree
// (tests/view_page_*.png).
#include <signal.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "headless_browser.hpp"
#include "live_view_support.hpp"
#include "pullout/model/names.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

constexpr const char* kVehicle = "view-car";

// What the page shows of kVehicle (ids and classes of client/cli/view/view_page.html).
constexpr const char* kInspect = R"js((() => {
  const fp = document.getElementById("footprint-view-car");
  const path = document.getElementById("path-view-car");
  const segments = path ? [...path.querySelectorAll("polyline.segment")] : [];
  const label = document.getElementById("state-view-car");
  const row = document.getElementById("row-view-car");
  return {
    footprint_points: fp ? fp.getAttribute("points").trim().split(/\s+/).length : 0,
    footprint: fp ? fp.getAttribute("points") : "",
    footprint_state: fp ? fp.getAttribute("data-state") : "",
    request: path ? path.getAttribute("data-request") : "",
    segments: segments.length,
    current: segments.filter(s => s.classList.contains("current")).map(s => Number(s.getAttribute("data-index"))),
    label: label ? label.textContent : "",
    row_state: row ? row.querySelector(".col-state").textContent : "",
    lanes: document.querySelectorAll('polygon.lane[data-vehicle="view-car"]').length,
    objects: document.querySelectorAll('polygon.object[data-vehicle="view-car"]').length,
    marker: window.pulloutTestMarker === 1
  };
})())js";

class ViewPage : public ServiceTest {
 protected:
  void TearDown() override {
    if (browser_) {
      EXPECT_TRUE(browser_->close()) << "the browser did not exit on Browser.close";
      // Nothing of the browser's process group is left (renderers, GPU and utility processes).
      const pid_t group = browser_->pid();
      bool gone = false;
      for (int i = 0; i < 100 && !gone; ++i) {
        gone = ::kill(-group, 0) != 0 && errno == ESRCH;
        if (!gone) std::this_thread::sleep_for(50ms);
      }
      EXPECT_TRUE(gone) << "processes of the browser's group " << group << " are still alive";
      browser_.reset();
    }
    if (view_) {
      const ExitResult exit = view_->stop();
      EXPECT_TRUE(exit.clean()) << "pullout view: " << exit.describe() << "\n"
                                << read_file_tail(temp_.path() + "/view.err", 4000);
      view_.reset();
    }
    ServiceTest::TearDown();
  }

  // Starts `pullout view` on the service's domain at a free loopback port; returns its URL.
  std::string start_view() {
    const std::string out = temp_.path() + "/view.out";
    view_.emplace(std::vector<std::string>{PULLOUT_CLI_EXE, "view", "--http", "127.0.0.1:0", "--domain",
                                           std::to_string(domain()), "--config", default_config_path()},
                  out, temp_.path() + "/view.err");
    // "pullout view: http://127.0.0.1:PORT/ (DDS domain N)"
    for (int i = 0; i < 200; ++i) {
      const std::string text = read_file_tail(out, 4000);
      const auto begin = text.find("http://");
      const auto end = text.find("/ ", begin == std::string::npos ? 0 : begin + 7);
      if (begin != std::string::npos && end != std::string::npos) return text.substr(begin, end - begin + 1);
      if (!view_->running()) break;
      std::this_thread::sleep_for(50ms);
    }
    ADD_FAILURE() << "pullout view printed no URL: " << read_file_tail(temp_.path() + "/view.err", 4000);
    return "";
  }

  // Polls the page until `done` accepts what it shows (bounded); returns the last look.
  template <typename Done>
  nlohmann::json wait_page(Done done, std::chrono::seconds bound = 20s) {
    nlohmann::json look;
    const auto deadline = std::chrono::steady_clock::now() + bound;
    while (std::chrono::steady_clock::now() < deadline) {
      look = browser_->evaluate(kInspect);
      if (look.is_object() && done(look)) return look;
      std::this_thread::sleep_for(100ms);
    }
    return look;
  }

  std::string shot(const std::string& name) {
    const std::string file = std::string(PULLOUT_TEST_OUTPUT_DIR) + "/view_page_" + name + ".png";
    browser_->screenshot(file);
    std::ifstream in(file, std::ios::binary);
    char magic[8] = {};
    in.read(magic, sizeof magic);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG") << file;
    return file;
  }

  std::optional<ChildProcess> view_;
  std::unique_ptr<HeadlessBrowser> browser_;
};

TEST_F(ViewPage, DrawsTheVehicleAndFollowsItThroughItsSegments) {
  const std::string chromium = HeadlessBrowser::find_executable();
  ASSERT_FALSE(chromium.empty()) << "no chromium (install it with: bash scripts/setup --browser)";

  // The view runs before the vehicle asks (requests are volatile: it draws the lanes of the
  // requests it sees).
  start_service();
  const std::string url = start_view();
  ASSERT_FALSE(url.empty());
  auto client = connect(kVehicle);
  ASSERT_NE(client, nullptr);
  // The view reads the request topic too, and it is volatile: a request sent before the view has
  // matched this client's request writer never reaches it, and is not sent again once answered
  // (the page then showed the path with no lanes, objects or footprint in a CI run). Both the
  // service and the view read it before the vehicle asks.
  ASSERT_TRUE(client->wait_for_services(2, 10s)) << "the view's request reader never matched the vehicle's writer";
  const Scenario scenario = load_test_scenario("parallel_spot_reverse");
  const std::uint64_t id = client->send(scenario.request);
  const auto path = client->wait_for_path(id, kReplyTimeout);
  ASSERT_TRUE(path && path->found);
  const std::size_t segment_count = path->partial_paths.size();
  ASSERT_EQ(segment_count, 3u) << "reverse, arc 1, arc 2";
  const auto waiting = client->wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout);
  ASSERT_TRUE(waiting);

  ASSERT_NO_THROW(
      browser_ = std::make_unique<HeadlessBrowser>(chromium, temp_.path() + "/profile", temp_.path() + "/chromium.log"))
      << read_file_tail(temp_.path() + "/chromium.log", 4000);
  browser_->open(url);
  const auto loaded = wait_page([](const nlohmann::json& j) { return j["segments"].get<int>() > 0; });
  ASSERT_TRUE(loaded.is_object());
  browser_->evaluate("window.pulloutTestMarker = 1");

  // Waiting for approval on segment 0 of 3.
  auto look = wait_page([&](const nlohmann::json& j) {
    return j["segments"] == segment_count && j["current"] == nlohmann::json::array({0}) &&
           j["footprint_state"] == "waiting_approval";
  });
  EXPECT_EQ(look["segments"], segment_count) << look.dump();
  EXPECT_EQ(look["current"], nlohmann::json::array({0})) << look.dump();
  EXPECT_EQ(look["footprint_points"], 4) << look.dump();
  EXPECT_EQ(look["footprint_state"], "waiting_approval") << look.dump();
  EXPECT_EQ(look["label"], std::string(kVehicle) + ": waiting_approval 1/3") << look.dump();
  EXPECT_EQ(look["row_state"], "waiting_approval") << look.dump();
  EXPECT_EQ(look["request"], std::to_string(id)) << look.dump();
  EXPECT_EQ(look["lanes"], scenario.request.lanes.size()) << look.dump();
  EXPECT_EQ(look["objects"], scenario.request.objects.size()) << look.dump();
  shot("1_waiting");
  const std::string start_footprint = look["footprint"];

  // Released, then driven through segment 0 into segment 1, then into segment 2: the highlight
  // moves with the service's current_path_idx, on the same page.
  SegmentDriver driver(*client, id, *path);
  ASSERT_TRUE(driver.depart());
  for (std::uint32_t k = 1; k < segment_count; ++k) {
    const auto st = driver.drive_segment();
    ASSERT_TRUE(st) << "the service did not move to segment " << k;
    ASSERT_EQ(st->current_path_idx, k);
    const std::string state = to_string(st->state);
    {
      const KeepAlive alive(driver);  // no stop for lost odometry while the page is read
      look = wait_page([&](const nlohmann::json& j) {
        return j["current"] == nlohmann::json::array({k}) && j["footprint_state"] == state;
      });
    }
    EXPECT_EQ(look["current"], nlohmann::json::array({k})) << look.dump();
    EXPECT_EQ(look["segments"], segment_count) << look.dump();
    EXPECT_EQ(look["footprint_state"], state) << look.dump();
    EXPECT_EQ(look["label"], std::string(kVehicle) + ": " + state + " " + std::to_string(k + 1) + "/3") << look.dump();
    EXPECT_NE(look["footprint"], start_footprint) << "the footprint did not follow the vehicle";
    EXPECT_TRUE(look["marker"]) << "the page was reloaded instead of updated";
    {
      const KeepAlive alive(driver);
      shot("2_segment_" + std::to_string(k + 1));
    }
  }
}

}  // namespace
}  // namespace pullout::integration
