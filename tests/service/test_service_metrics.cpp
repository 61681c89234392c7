// The service's Prometheus metrics without DDS: what a status counts as, and the field classes of
// rejections (bounded label values).
#include <gtest/gtest.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

#include <sstream>
#include <string>

#include "observability/http_endpoint.hpp"
#include "observability/service_metrics.hpp"
#include "service/vehicle_registry.hpp"

namespace pullout::service {
namespace {

std::string exposition(const ServiceMetrics& metrics) {
  return prometheus::TextSerializer().Serialize(metrics.registry()->Collect());
}

bool has_line(const std::string& text, const std::string& line) {
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    if (l == line) return true;
  }
  return false;
}

TEST(RejectionFieldClass, IndicesAreRemovedAndNonFieldsGiveNothing) {
  EXPECT_EQ(rejection_field_class("lanes[2].left_bound[5].x: not finite"), "lanes.left_bound.x");
  EXPECT_EQ(rejection_field_class("ego_pose.orientation: not a unit quaternion (norm 0.5)"), "ego_pose.orientation");
  EXPECT_EQ(rejection_field_class("service.max_vehicles: the service holds 2 sessions"), "service.max_vehicles");
  EXPECT_EQ(rejection_field_class("no colon here"), "");
  EXPECT_EQ(rejection_field_class("two words: problem"), "");
  EXPECT_EQ(rejection_field_class(": empty field"), "");
}

TEST(ServiceMetrics, RepliesByOutcomeAndPlanningTimeByPlanner) {
  ServiceMetrics metrics("test");
  PullOutStatus found;
  found.state = ExecutionState::kWaitingApproval;
  found.planner_type = PlannerType::kGeometric;
  found.planning_time_ms = 3.0;
  metrics.on_reply(found);
  PullOutStatus no_path;
  no_path.state = ExecutionState::kNoPath;
  no_path.planning_time_ms = 40.0;
  metrics.on_reply(no_path);
  PullOutStatus planning;
  planning.state = ExecutionState::kPlanning;
  metrics.on_reply(planning);  // not an outcome: ignored
  const std::string text = exposition(metrics);
  EXPECT_TRUE(has_line(text, "pullout_replies_total{outcome=\"found\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_replies_total{outcome=\"no_path\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_replies_total{outcome=\"rejected\"} 0")) << text;
  EXPECT_TRUE(has_line(text, "pullout_planning_seconds_count{planner=\"geometric\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_planning_seconds_count{planner=\"none\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_planning_seconds_bucket{planner=\"geometric\",le=\"0.005\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_planning_seconds_bucket{planner=\"geometric\",le=\"0.002\"} 0")) << text;
  EXPECT_TRUE(has_line(text, "pullout_planning_seconds_count{planner=\"shift\"} 0")) << text;
}

TEST(ServiceMetrics, ARejectionCountsEachFieldClassOnceAndLabelsAreBounded) {
  ServiceMetrics metrics("test");
  PullOutStatus rejected;
  rejected.state = ExecutionState::kRejected;
  rejected.error = "lanes[0].left_bound[1].x: not finite\nlanes[3].left_bound[0].x: not finite\nego_pose: off";
  metrics.on_reply(rejected);
  std::string text = exposition(metrics);
  EXPECT_TRUE(has_line(text, "pullout_replies_total{outcome=\"rejected\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_rejections_total{field=\"lanes.left_bound.x\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_rejections_total{field=\"ego_pose\"} 1")) << text;
  // Many distinct field names: at most kMaxFieldClasses labels, the rest under "other".
  for (std::size_t i = 0; i < ServiceMetrics::kMaxFieldClasses + 10; ++i) {
    rejected.error = "field_" + std::to_string(i) + ": bad";
    metrics.on_reply(rejected);
  }
  text = exposition(metrics);
  std::size_t labels = 0;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) labels += l.rfind("pullout_rejections_total{", 0) == 0 ? 1 : 0;
  EXPECT_EQ(labels, ServiceMetrics::kMaxFieldClasses + 1) << text;
  EXPECT_TRUE(has_line(text, "pullout_rejections_total{field=\"other\"} 12")) << text;
}

TEST(ServiceMetrics, EvictionsByReason) {
  ServiceMetrics metrics("test");
  metrics.on_eviction(EvictionReason::kIdle);
  metrics.on_eviction(EvictionReason::kIdle);
  metrics.on_eviction(EvictionReason::kCapacity);
  const std::string text = exposition(metrics);
  EXPECT_TRUE(has_line(text, "pullout_evictions_total{reason=\"idle\"} 2")) << text;
  EXPECT_TRUE(has_line(text, "pullout_evictions_total{reason=\"capacity\"} 1")) << text;
  EXPECT_TRUE(has_line(text, "pullout_evictions_total{reason=\"gone\"} 0")) << text;
}

// /readyz of a replica: not ready while it syncs with the other replicas (it answers nothing then).
TEST(HealthState, AReplicaIsReadyOnlyOnceInStep) {
  HealthState h;
  h.config_loaded = true;
  h.dds_ready = true;
  h.workers_running = true;
  h.beat();
  bool ready = false;
  EXPECT_NE(h.readiness(ready).find("in step"), std::string::npos);
  EXPECT_TRUE(ready);
  h.in_step = false;
  const std::string body = h.readiness(ready);
  EXPECT_FALSE(ready) << body;
  EXPECT_EQ(body.rfind("not ready\n", 0), 0u) << body;
  EXPECT_NE(body.find("not yet in step with the other replicas"), std::string::npos) << body;
}

}  // namespace
}  // namespace pullout::service
