// ReplicaShadows (service replica mode) without DDS: who serves a vehicle, whose vehicles wait for
// a takeover, and what a takeover restores from.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "service/replicas.hpp"

namespace pullout::service {
namespace {

ParticipantId replica(unsigned char n) {
  ParticipantId id;
  id.value[0] = 0x01;
  id.value[11] = n;
  return id;
}

PullOutRequest request(std::uint64_t id, std::int64_t stamp_ns) {
  PullOutRequest r;
  r.vehicle_id = "car";
  r.request_id = id;
  r.stamp_ns = stamp_ns;
  return r;
}

PullOutStatus status_for(std::uint64_t request_id) {
  PullOutStatus s;
  s.vehicle_id = "car";
  s.request_id = request_id;
  s.state = ExecutionState::kExecuting;
  s.departed = true;
  s.current_path_idx = 1;
  return s;
}

TEST(ReplicaShadows, AVehicleWhoseOwnerLeftWaitsForTheTakeoverInsteadOfBeingServedAfresh) {
  ReplicaShadows shadows(10);
  const ParticipantId self = replica(1), owner = replica(2), other = replica(3);
  shadows.at("car")->owner = owner;
  EXPECT_FALSE(shadows.owner_left("car", self, {owner, other}));
  EXPECT_FALSE(shadows.serves("car", self, {owner, other})) << "a live owner keeps its vehicle";
  EXPECT_TRUE(shadows.owner_left("car", self, {other}));
  EXPECT_FALSE(shadows.owner_left("bus", self, {other})) << "no shadow: nobody to wait for";
  EXPECT_EQ(shadows.owned_by(owner), std::vector<std::string>{"car"});
}

TEST(ReplicaShadows, ATakeoverRestoresWithTheRequestTheStatusAnswers) {
  ReplicaShadows shadows(10);
  shadows.keep_request(request(7, 100));
  shadows.at("car")->status = status_for(7);
  bool known = false;
  const auto snap = shadows.snapshot("car", known);
  ASSERT_TRUE(snap);
  EXPECT_TRUE(known);
  EXPECT_FALSE(snap->request_is_later);
  EXPECT_EQ(snap->request.request_id, 7u);
}

TEST(ReplicaShadows, WithoutTheAnsweredRequestTheNewestKeptOneGivesTheWorld) {
  ReplicaShadows shadows(10);
  // Ids are not ordered in time; the stamps are.
  shadows.keep_request(request(9, 300));
  shadows.keep_request(request(50, 200));
  shadows.at("car")->status = status_for(7);  // answered a request this replica never saw
  bool known = false;
  const auto snap = shadows.snapshot("car", known);
  ASSERT_TRUE(snap);
  EXPECT_TRUE(known);
  EXPECT_TRUE(snap->request_is_later);
  EXPECT_EQ(snap->request.request_id, 9u);
  EXPECT_EQ(snap->status.request_id, 7u);
}

TEST(ReplicaShadows, WithNoRequestAtAllTheTakeoverKnowsNone) {
  ReplicaShadows shadows(10);
  shadows.at("car")->status = status_for(7);
  bool known = true;
  const auto snap = shadows.snapshot("car", known);
  ASSERT_TRUE(snap);
  EXPECT_FALSE(known);
  EXPECT_FALSE(snap->request_is_later);
}

}  // namespace
}  // namespace pullout::service
