// StateJournal on real files: what is written is read back; a file that is stale, truncated, of
// another format or for another vehicle is reported by name and left out (never half-restored).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "pullout/idl/convert.hpp"
#include "service/state_journal.hpp"
#include "test_world.hpp"

namespace pullout::service {
namespace {

class NullOutbox : public Outbox {
 public:
  bool publish_path(const PullOutPath&) override { return true; }
  bool publish_status(const PullOutStatus&) override { return true; }
  bool forget_vehicle(const std::string&) override { return true; }
};

std::int64_t wall_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

class Journal : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/pullout-journal-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // The request, a path and a status of `vehicle`, through a journal; its file.
  std::string record(const std::string& vehicle, std::int64_t status_stamp_ns) {
    StateJournal journal(dir_, outbox_);
    PullOutRequest request = test::straight_shoulder_request();
    request.vehicle_id = vehicle;
    request.request_id = 7;
    journal.on_request(idl::to_msg(request));
    PullOutPath path;
    path.vehicle_id = vehicle;
    path.request_id = 7;
    path.found = true;
    PathWithLaneId segment;
    segment.points.resize(3);
    path.partial_paths = {segment, segment};
    path.pairs_terminal_velocity_and_accel.resize(2);
    journal.publish_path(path);
    PullOutStatus status;
    status.vehicle_id = vehicle;
    status.request_id = 7;
    status.state = ExecutionState::kExecuting;
    status.current_path_idx = 1;
    status.departed = true;
    status.stamp_ns = status_stamp_ns;
    journal.publish_status(status);
    return journal.file_of(vehicle);
  }

  std::string dir_;
  NullOutbox outbox_;
};

TEST_F(Journal, WhatIsWrittenIsReadBack) {
  record("car-1", wall_ns());
  StateJournal journal(dir_, outbox_);
  const JournalLoad loaded = journal.load(0.0);
  EXPECT_TRUE(loaded.problems.empty());
  ASSERT_EQ(loaded.entries.size(), 1u);
  const JournalEntry& e = loaded.entries.front();
  EXPECT_EQ(e.vehicle_id, "car-1");
  ASSERT_TRUE(e.request);
  EXPECT_EQ(e.request->request_id, 7u);
  EXPECT_TRUE(e.request_issues.empty());
  EXPECT_EQ(e.request->lanes.size(), test::straight_shoulder_request().lanes.size());
  ASSERT_TRUE(e.path);
  EXPECT_EQ(e.path->partial_paths.size(), 2u);
  EXPECT_EQ(e.status.current_path_idx, 1u);
  EXPECT_TRUE(e.status.departed);
  EXPECT_EQ(e.status.state, ExecutionState::kExecuting);
}

TEST_F(Journal, AStaleFileIsReportedAndNotRestored) {
  const std::string file = record("old-car", wall_ns() - 3600LL * 1'000'000'000);
  StateJournal journal(dir_, outbox_);
  const JournalLoad loaded = journal.load(300.0);
  EXPECT_TRUE(loaded.entries.empty());
  ASSERT_EQ(loaded.problems.size(), 1u);
  EXPECT_NE(loaded.problems.front().find(file), std::string::npos) << loaded.problems.front();
  EXPECT_NE(loaded.problems.front().find("older than"), std::string::npos) << loaded.problems.front();
}

TEST_F(Journal, ATruncatedOrForeignFileIsReportedAndNotRestored) {
  const std::string file = record("cut-car", wall_ns());
  std::filesystem::resize_file(file, std::filesystem::file_size(file) - 20);
  std::ofstream(dir_ + "/0123456789abcdef.state") << "pullout-state 9\nsomething else";
  StateJournal journal(dir_, outbox_);
  const JournalLoad loaded = journal.load(0.0);
  EXPECT_TRUE(loaded.entries.empty());
  ASSERT_EQ(loaded.problems.size(), 2u);
  for (const std::string& p : loaded.problems) EXPECT_NE(p.find(dir_), std::string::npos) << p;
}

TEST_F(Journal, AnEvictedVehicleLeavesNoFile) {
  const std::string file = record("gone-car", wall_ns());
  ASSERT_TRUE(std::filesystem::exists(file));
  StateJournal journal(dir_, outbox_);
  journal.forget_vehicle("gone-car");
  EXPECT_FALSE(std::filesystem::exists(file));
}

TEST_F(Journal, AnUnwritableDirectoryStopsTheStartWithItsName) {
  const std::string blocked = dir_ + "/file";
  std::ofstream(blocked) << "x";
  try {
    StateJournal journal(blocked + "/sub", outbox_);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("service.state_dir"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(blocked), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pullout::service
