// `pullout watch` as an operator runs it: the real binary, a real service and real vehicles over
// loopback DDS. The table's rows are checked against the statuses the vehicles themselves
// received: one vehicle released and driven into its second segment, one waiting for approval.
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "live_view_support.hpp"
#include "pullout/model/names.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;

struct WatchRun {
  ExitResult exit;
  std::string out;
};

class Watch : public ServiceTest {
 protected:
  WatchRun run_watch(const std::vector<std::string>& arguments, Millis timeout) {
    std::vector<std::string> argv{PULLOUT_CLI_EXE, "watch", "--domain", std::to_string(domain())};
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    const std::string out_file = temp_.path() + "/watch.out";
    ChildProcess watch(argv, out_file, temp_.path() + "/watch.err");
    WatchRun run;
    const auto exit = watch.wait_exit(timeout);
    EXPECT_TRUE(exit) << "pullout watch did not stop within " << timeout.count() << " ms";
    run.exit = exit ? *exit : watch.stop();
    run.out = read_file_tail(out_file, 1 << 20);
    return run;
  }

  static const std::vector<std::string>* row_of(const std::vector<std::vector<std::string>>& rows,
                                                const std::string& vehicle) {
    for (const auto& row : rows) {
      if (!row.empty() && row.front() == vehicle) return &row;
    }
    return nullptr;
  }

  // The row the table must show for a vehicle whose latest received status is `s`.
  static std::vector<std::string> expected_row(const std::string& vehicle, const PullOutStatus& s) {
    return {vehicle, to_string(s.state), to_string(s.planner_type),
            std::to_string(s.current_path_idx + 1) + "/" + std::to_string(s.segment_count), s.safe ? "yes" : "no"};
  }
};

TEST_F(Watch, ShowsEveryVehicleWithItsStateAndSegment) {
  Sent driven = start_and_send("parallel_spot_reverse", "watch-driven");
  ASSERT_TRUE(driven.path);
  ASSERT_EQ(driven.path->partial_paths.size(), 3u);
  SegmentDriver driver(*driven.client, driven.id, *driven.path);
  ASSERT_TRUE(driver.depart());
  const auto second = driver.drive_segment();
  ASSERT_TRUE(second) << "the service did not move to segment 1";
  ASSERT_EQ(second->state, ExecutionState::kExecuting);

  const auto waiting = connect("watch-waiting");
  ASSERT_NE(waiting, nullptr);
  Scenario straight = load_test_scenario("straight_shoulder");
  translate(straight.request, 1000.0, 0.0);  // far away: not held for the driven vehicle's path
  const std::uint64_t waiting_id = waiting->send(straight.request);
  const auto waiting_status = waiting->wait_for_status(
      waiting_id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout);
  ASSERT_TRUE(waiting_status);

  std::optional<WatchRun> watched;
  {
    const KeepAlive alive(driver);  // executing stays executing while watched
    watched = run_watch({"--duration", "3", "--interval", "0.5"}, 20s);
  }
  const WatchRun& run = *watched;
  EXPECT_TRUE(run.exit.clean()) << run.exit.describe();
  const auto rows = last_table_rows(run.out);
  ASSERT_EQ(rows.size(), 2u) << run.out;

  const auto driven_status = driven.client->latest_status();
  ASSERT_TRUE(driven_status);
  EXPECT_EQ(driven_status->current_path_idx, 1u);
  const auto* driven_row = row_of(rows, "watch-driven");
  ASSERT_NE(driven_row, nullptr) << run.out;
  ASSERT_GE(driven_row->size(), 6u) << run.out;
  const std::vector<std::string> driven_cells(driven_row->begin(), driven_row->begin() + 5);
  EXPECT_EQ(driven_cells, expected_row("watch-driven", *driven_status)) << run.out;
  EXPECT_EQ(driven_cells[1], "executing");
  EXPECT_EQ(driven_cells[3], "2/3");

  const auto* waiting_row = row_of(rows, "watch-waiting");
  ASSERT_NE(waiting_row, nullptr) << run.out;
  ASSERT_GE(waiting_row->size(), 6u) << run.out;
  const std::vector<std::string> waiting_cells(waiting_row->begin(), waiting_row->begin() + 5);
  EXPECT_EQ(waiting_cells, expected_row("watch-waiting", *waiting->latest_status())) << run.out;
  EXPECT_EQ(waiting_cells[1], "waiting_approval");
}

TEST_F(Watch, OncePrintsOneTableWithTheVehicle) {
  Sent sent = start_and_send("straight_shoulder", "watch-once");
  ASSERT_TRUE(sent.path);
  const WatchRun run = run_watch({"--once"}, 20s);
  EXPECT_TRUE(run.exit.clean()) << run.exit.describe() << "\n" << run.out;
  const auto rows = last_table_rows(run.out);
  ASSERT_EQ(rows.size(), 1u) << run.out;
  EXPECT_EQ(rows[0][0], "watch-once");
  EXPECT_EQ(rows[0][1], to_string(sent.client->latest_status()->state));
}

TEST_F(Watch, OnceWithoutAServiceSaysSoAndFails) {
  DomainLease lease;  // a domain with nobody on it
  const std::string out_file = temp_.path() + "/empty.out";
  ChildProcess watch({PULLOUT_CLI_EXE, "watch", "--domain", std::to_string(lease.domain()), "--once", "--wait", "1"},
                     out_file, temp_.path() + "/empty.err");
  const auto exit = watch.wait_exit(15s);
  ASSERT_TRUE(exit);
  EXPECT_TRUE(exit->exited);
  EXPECT_EQ(exit->exit_code, 3);
  EXPECT_NE(read_file_tail(temp_.path() + "/empty.err", 4000).find("no pullout service found"), std::string::npos);
  EXPECT_NE(read_file_tail(out_file, 4000).find("(no vehicles)"), std::string::npos);
}

// `pullout request` sends a scenario's search_priority and search_policy only: the service plans
// with its own parameters. The other `planner:` keys are named on stderr before it looks for a
// service (none here: it then fails as it must), not dropped without a word.
TEST(RequestCli, NamesThePlannerKeysItDoesNotSend) {
  DomainLease lease;
  TempDir temp;
  const auto stderr_of = [&](const std::string& scenario) {
    const std::string err_file = temp.path() + "/" + scenario + ".err";
    ChildProcess request({PULLOUT_CLI_EXE, "request", source_path("tests/scenarios/" + scenario + ".yaml"), "--domain",
                          std::to_string(lease.domain()), "--profiles", loopback_profiles_path(), "--timeout", "0.5"},
                         temp.path() + "/" + scenario + ".out", err_file);
    const auto exit = request.wait_exit(15s);
    EXPECT_TRUE(exit && exit->exited && exit->exit_code == 3) << scenario;
    return read_file_tail(err_file, 4000);
  };
  const std::string lot = stderr_of("freespace_parking_lot");
  EXPECT_NE(lot.find("the scenario's planner key freespace_planner.vehicle_shape_margin is not sent"),
            std::string::npos)
      << lot;
  EXPECT_NE(lot.find("no pullout service found"), std::string::npos) << lot;
  const std::string blocked = stderr_of("freespace_blocked_ahead");
  EXPECT_NE(blocked.find("planner keys maximum_lateral_acc, minimum_lateral_acc, "
                         "freespace_planner.vehicle_shape_margin are not sent"),
            std::string::npos)
      << blocked;
  const std::string carried = stderr_of("clothoid_only");  // search_priority only: all of it is sent
  EXPECT_EQ(carried.find("not sent"), std::string::npos) << carried;
}

// A credentials directory that lacks a file is a bad argument (exit status 2, the file named),
// not a DDS failure (it was status 3, "DDS setup failed").
TEST(RequestCli, ASecurityDirWithoutItsCredentialsIsABadArgument) {
  DomainLease lease;
  TempDir temp;
  const std::string err_file = temp.path() + "/request.err";
  ChildProcess request(
      {PULLOUT_CLI_EXE, "request", source_path("tests/scenarios/straight_shoulder.yaml"), "--security-dir", temp.path(),
       "--domain", std::to_string(lease.domain()), "--profiles", loopback_profiles_path(), "--timeout", "0.5"},
      temp.path() + "/request.out", err_file);
  const auto exit = request.wait_exit(15s);
  ASSERT_TRUE(exit && exit->exited);
  EXPECT_EQ(exit->exit_code, 2);
  const std::string err = read_file_tail(err_file, 4000);
  EXPECT_NE(err.find("ClientOptions.security_dir: DDS security credentials: " + temp.path() + "/ca.pem is missing"),
            std::string::npos)
      << err;
}

}  // namespace
}  // namespace pullout::integration
