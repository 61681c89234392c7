// When a search must stop, and why: the one stop condition every search in the core takes.
//
// A StopCondition combines up to three limits, any of which ends the search:
//  - a deadline: the caller's planning budget (a request's deadline_ms), a steady-clock time point;
//  - a cancellation flag: set by the owner of the search (a newer request of the vehicle, shutdown);
//  - a planner's own budget (e.g. freespace_planner.time_limit), added by the planner itself with
//    with_budget(), so that the caller's deadline and cancellation travel on unchanged.
// As OMPL's PlannerTerminationCondition composes with plannerOrTerminationCondition, combining
// never drops a limit: with_budget() and with_cancel() return a condition that stops when this one
// stops or at the new limit.
//
// check() tells why the search must stop (StopReason::kNone: go on). It costs one relaxed atomic
// load and at most one steady-clock read; searches call it between units of work (candidates,
// every few expansions). When several limits are reached at once, cancellation is reported first,
// then the deadline, then the budget: a caller seeing kBudget knows its own limits still hold.
//
// Budgets in milliseconds are clamped: NaN, +inf and anything above kMaxBudgetMs mean "no limit";
// zero or negative means "already expired". No budget overflows the clock.
//
// Thread safety: a StopCondition is a small value, safe to copy and to check from several threads;
// the cancellation flag must outlive every condition that refers to it.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <stdexcept>

namespace pullout {

enum class StopReason : std::uint8_t {
  kNone = 0,       // no limit reached: the search goes on
  kDeadline = 1,   // the caller's deadline passed
  kCancelled = 2,  // the cancellation flag is set
  kBudget = 3,     // the planner's own budget (with_budget) ran out
};

inline const char* to_string(StopReason r) {
  switch (r) {
    case StopReason::kNone:
      return "none";
    case StopReason::kDeadline:
      return "deadline";
    case StopReason::kCancelled:
      return "cancelled";
    case StopReason::kBudget:
      return "budget";
  }
  return "invalid";
}

class StopCondition {
 public:
  using Clock = std::chrono::steady_clock;
  // [ms] Budgets above this (about 31 years) mean "no limit"; it keeps now + budget in range.
  static constexpr double kMaxBudgetMs = 1e12;

  // Never stops.
  StopCondition() = default;

  // Stops at `deadline` (reason kDeadline).
  static StopCondition at(Clock::time_point deadline) {
    StopCondition c;
    c.deadline_ = deadline;
    return c;
  }
  // Stops `budget_ms` from now (reason kDeadline); see the clamping rule above.
  static StopCondition after_ms(double budget_ms) { return at(end_after_ms(budget_ms)); }

  // This condition, also stopped when `*flag` is true (reason kCancelled). Null adds nothing.
  // A condition holds one flag: adding a different second one is a programming error
  // (std::logic_error), as silently keeping only one of them would lose a cancellation.
  StopCondition with_cancel(const std::atomic<bool>* flag) const {
    StopCondition c = *this;
    if (flag == nullptr || flag == cancel_) return c;
    if (cancel_ != nullptr) throw std::logic_error("StopCondition::with_cancel: a cancellation flag is already set");
    c.cancel_ = flag;
    return c;
  }
  // This condition, also stopped `budget_ms` from now (reason kBudget), keeping the deadline and
  // the cancellation flag; the earlier of two budgets wins.
  StopCondition with_budget_ms(double budget_ms) const {
    StopCondition c = *this;
    c.budget_end_ = std::min(budget_end_, end_after_ms(budget_ms));
    return c;
  }

  // Why the search must stop now; kNone to go on.
  StopReason check() const {
    if (cancel_ != nullptr && cancel_->load(std::memory_order_relaxed)) return StopReason::kCancelled;
    if (deadline_ == kNever && budget_end_ == kNever) return StopReason::kNone;
    const Clock::time_point now = Clock::now();
    if (now >= deadline_) return StopReason::kDeadline;
    if (now >= budget_end_) return StopReason::kBudget;
    return StopReason::kNone;
  }
  bool should_stop() const { return check() != StopReason::kNone; }

  bool has_cancel_flag() const { return cancel_ != nullptr; }
  Clock::time_point deadline() const { return deadline_; }      // time_point::max(): none
  Clock::time_point budget_end() const { return budget_end_; }  // time_point::max(): none

 private:
  static constexpr Clock::time_point kNever = Clock::time_point::max();

  static Clock::time_point end_after_ms(double budget_ms) {
    const Clock::time_point now = Clock::now();
    if (!(budget_ms > 0.0)) return budget_ms <= 0.0 ? now : kNever;  // NaN: no limit
    if (!(budget_ms <= kMaxBudgetMs)) return kNever;                 // +inf, huge
    const auto budget =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(budget_ms));
    return budget >= kNever - now ? kNever : now + budget;
  }

  Clock::time_point deadline_{kNever};
  Clock::time_point budget_end_{kNever};
  const std::atomic<bool>* cancel_{nullptr};
};

}  // namespace pullout
