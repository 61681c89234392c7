// The stop condition: each limit, the reason it reports, how limits combine, and budgets that used
// to overflow the clock conversion (NaN, 1e300 ms).
#include "pullout/search/stop_condition.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <limits>
#include <stdexcept>
#include <string>

namespace pullout {
namespace {

using Clock = StopCondition::Clock;

TEST(StopCondition, NoLimitNeverStops) {
  const StopCondition stop;
  EXPECT_EQ(stop.check(), StopReason::kNone);
  EXPECT_FALSE(stop.should_stop());
  EXPECT_FALSE(stop.has_cancel_flag());
}

TEST(StopCondition, ZeroOrNegativeBudgetHasExpired) {
  EXPECT_EQ(StopCondition::after_ms(0.0).check(), StopReason::kDeadline);
  EXPECT_EQ(StopCondition::after_ms(-5.0).check(), StopReason::kDeadline);
  EXPECT_EQ(StopCondition::after_ms(-std::numeric_limits<double>::infinity()).check(), StopReason::kDeadline);
  EXPECT_EQ(StopCondition::at(Clock::now()).check(), StopReason::kDeadline);
}

TEST(StopCondition, HugeOrNonFiniteBudgetMeansNoLimit) {
  // 1e300 ms overflowed the conversion to nanoseconds (undefined behaviour; in practice a deadline
  // in the past, so the search stopped at once).
  for (double ms : {1e300, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN(),
                    StopCondition::kMaxBudgetMs * 2.0}) {
    const StopCondition stop = StopCondition::after_ms(ms);
    EXPECT_EQ(stop.check(), StopReason::kNone) << ms;
    EXPECT_EQ(stop.deadline(), Clock::time_point::max()) << ms;
    EXPECT_EQ(StopCondition().with_budget_ms(ms).budget_end(), Clock::time_point::max()) << ms;
  }
  // The largest finite budget is a real, far deadline.
  const StopCondition far = StopCondition::after_ms(StopCondition::kMaxBudgetMs);
  EXPECT_EQ(far.check(), StopReason::kNone);
  EXPECT_LT(far.deadline(), Clock::time_point::max());
  EXPECT_GT(far.deadline(), Clock::now());
}

TEST(StopCondition, CancelFlagIsReadOnEveryCheck) {
  std::atomic<bool> cancel{false};
  const StopCondition stop = StopCondition().with_cancel(&cancel);
  EXPECT_TRUE(stop.has_cancel_flag());
  EXPECT_EQ(stop.check(), StopReason::kNone);
  cancel = true;
  EXPECT_EQ(stop.check(), StopReason::kCancelled);
  cancel = false;
  EXPECT_EQ(stop.check(), StopReason::kNone);
}

TEST(StopCondition, BudgetKeepsTheDeadlineAndTheCancelFlag) {
  std::atomic<bool> cancel{false};
  const StopCondition caller = StopCondition::after_ms(1e9).with_cancel(&cancel);
  const StopCondition own = caller.with_budget_ms(0.0);
  EXPECT_EQ(caller.check(), StopReason::kNone);  // the caller's condition is unchanged
  EXPECT_EQ(own.check(), StopReason::kBudget);
  EXPECT_EQ(own.deadline(), caller.deadline());
  EXPECT_TRUE(own.has_cancel_flag());
  cancel = true;
  EXPECT_EQ(own.check(), StopReason::kCancelled);  // cancellation is reported first
  EXPECT_EQ(caller.check(), StopReason::kCancelled);
}

TEST(StopCondition, ExpiredDeadlineIsReportedBeforeTheBudget) {
  // Both passed: the caller's deadline wins, so a planner seeing kBudget knows the caller's
  // limits still hold.
  EXPECT_EQ(StopCondition::after_ms(0.0).with_budget_ms(0.0).check(), StopReason::kDeadline);
  EXPECT_EQ(StopCondition::after_ms(0.0).with_budget_ms(1e9).check(), StopReason::kDeadline);
}

TEST(StopCondition, TheEarlierBudgetWins) {
  EXPECT_EQ(StopCondition().with_budget_ms(0.0).with_budget_ms(1e9).check(), StopReason::kBudget);
  EXPECT_EQ(StopCondition().with_budget_ms(1e9).with_budget_ms(0.0).check(), StopReason::kBudget);
  EXPECT_EQ(StopCondition().with_budget_ms(1e9).check(), StopReason::kNone);
}

TEST(StopCondition, ASecondCancelFlagIsAProgrammingError) {
  std::atomic<bool> a{false};
  std::atomic<bool> b{false};
  const StopCondition stop = StopCondition().with_cancel(&a);
  EXPECT_NO_THROW(stop.with_cancel(&a));       // the same flag again
  EXPECT_NO_THROW(stop.with_cancel(nullptr));  // nothing added
  EXPECT_THROW(stop.with_cancel(&b), std::logic_error);
}

TEST(StopCondition, ReasonNames) {
  EXPECT_EQ(std::string(to_string(StopReason::kNone)), "none");
  EXPECT_EQ(std::string(to_string(StopReason::kDeadline)), "deadline");
  EXPECT_EQ(std::string(to_string(StopReason::kCancelled)), "cancelled");
  EXPECT_EQ(std::string(to_string(StopReason::kBudget)), "budget");
}

}  // namespace
}  // namespace pullout
