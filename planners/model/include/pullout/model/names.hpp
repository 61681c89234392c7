// Stable lower-case names of the model's enumerations, used in logs, JSON, scenario and config
// files. Parsing is exact (no case folding); an unknown name gives std::nullopt.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "pullout/model/types.hpp"

namespace pullout {

namespace detail {
template <typename E, std::size_t N>
constexpr const char* name_of(const std::array<std::pair<E, const char*>, N>& table, E value) {
  for (const auto& [e, name] : table) {
    if (e == value) return name;
  }
  return "invalid";
}
template <typename E, std::size_t N>
std::optional<E> value_of(const std::array<std::pair<E, const char*>, N>& table, std::string_view name) {
  for (const auto& [e, n] : table) {
    if (name == n) return e;
  }
  return std::nullopt;
}

inline constexpr std::array<std::pair<PlannerType, const char*>, 6> kPlannerNames{{
    {PlannerType::kNone, "none"},
    {PlannerType::kShift, "shift"},
    {PlannerType::kGeometric, "geometric"},
    {PlannerType::kClothoid, "clothoid"},
    {PlannerType::kStop, "stop"},
    {PlannerType::kFreespace, "freespace"},
}};
inline constexpr std::array<std::pair<ExecutionState, const char*>, 8> kStateNames{{
    {ExecutionState::kIdle, "idle"},
    {ExecutionState::kPlanning, "planning"},
    {ExecutionState::kRejected, "rejected"},
    {ExecutionState::kNoPath, "no_path"},
    {ExecutionState::kExecuting, "executing"},
    {ExecutionState::kCompleted, "completed"},
    {ExecutionState::kWaitingApproval, "waiting_approval"},
    {ExecutionState::kWaitingSafety, "waiting_safety"},
}};
inline constexpr std::array<std::pair<ObjectClass, const char*>, 8> kClassNames{{
    {ObjectClass::kUnknown, "unknown"},
    {ObjectClass::kCar, "car"},
    {ObjectClass::kTruck, "truck"},
    {ObjectClass::kBus, "bus"},
    {ObjectClass::kTrailer, "trailer"},
    {ObjectClass::kMotorcycle, "motorcycle"},
    {ObjectClass::kBicycle, "bicycle"},
    {ObjectClass::kPedestrian, "pedestrian"},
}};
inline constexpr std::array<std::pair<TurnSignal, const char*>, 3> kTurnSignalNames{{
    {TurnSignal::kNone, "none"},
    {TurnSignal::kLeft, "left"},
    {TurnSignal::kRight, "right"},
}};
inline constexpr std::array<std::pair<SearchPolicy, const char*>, 2> kPolicyNames{{
    {SearchPolicy::kPlannerPriority, "planner_priority"},
    {SearchPolicy::kDistancePriority, "distance_priority"},
}};
inline constexpr std::array<std::pair<LaneSubtype, const char*>, 2> kSubtypeNames{{
    {LaneSubtype::kRoad, "road"},
    {LaneSubtype::kRoadShoulder, "road_shoulder"},
}};
inline constexpr std::array<std::pair<AttemptOutcome, const char*>, 10> kOutcomeNames{{
    {AttemptOutcome::kSuccess, "success"},
    {AttemptOutcome::kCollision, "collision"},
    {AttemptOutcome::kLaneDeparture, "lane_departure"},
    {AttemptOutcome::kNoGeometry, "no_geometry"},
    {AttemptOutcome::kStartInvalid, "start_invalid"},
    {AttemptOutcome::kGoalInvalid, "goal_invalid"},
    {AttemptOutcome::kTimeout, "timeout"},
    {AttemptOutcome::kCancelled, "cancelled"},
    {AttemptOutcome::kNodeLimit, "node_limit"},
    {AttemptOutcome::kNoPath, "no_path"},
}};
}  // namespace detail

inline const char* to_string(PlannerType v) { return detail::name_of(detail::kPlannerNames, v); }
inline const char* to_string(ExecutionState v) { return detail::name_of(detail::kStateNames, v); }
inline const char* to_string(ObjectClass v) { return detail::name_of(detail::kClassNames, v); }
inline const char* to_string(TurnSignal v) { return detail::name_of(detail::kTurnSignalNames, v); }
inline const char* to_string(SearchPolicy v) { return detail::name_of(detail::kPolicyNames, v); }
inline const char* to_string(LaneSubtype v) { return detail::name_of(detail::kSubtypeNames, v); }
inline const char* to_string(AttemptOutcome v) { return detail::name_of(detail::kOutcomeNames, v); }

// "collision: object 7 (4/4 candidates)", or the outcome's name alone when there is no detail.
inline std::string describe(const PlannerAttempt& a) {
  std::string out = to_string(a.outcome);
  if (!a.detail.empty()) out += ": " + a.detail;
  return out;
}

inline std::optional<PlannerType> planner_type_from_string(std::string_view n) {
  return detail::value_of(detail::kPlannerNames, n);
}
inline std::optional<ObjectClass> object_class_from_string(std::string_view n) {
  return detail::value_of(detail::kClassNames, n);
}
inline std::optional<SearchPolicy> search_policy_from_string(std::string_view n) {
  return detail::value_of(detail::kPolicyNames, n);
}
inline std::optional<LaneSubtype> lane_subtype_from_string(std::string_view n) {
  return detail::value_of(detail::kSubtypeNames, n);
}

// ---- The planners a search can run (search_priority, request overrides), in their usual order.
// The one list of them: config reading, parameter and request validation and their messages use it.
inline constexpr std::array<PlannerType, 4> kSearchPlanners{PlannerType::kShift, PlannerType::kGeometric,
                                                            PlannerType::kClothoid, PlannerType::kFreespace};
inline constexpr bool is_search_planner(PlannerType p) {
  for (const PlannerType q : kSearchPlanners) {
    if (q == p) return true;
  }
  return false;
}
// ---- end of the planner list

}  // namespace pullout
