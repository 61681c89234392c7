// A stop condition for searches: a steady-clock deadline, optionally combined with a cancel flag.
// Every search in the core takes one and checks it between candidates (cheap: one clock read).
#pragma once

#include <atomic>
#include <chrono>

namespace pullout {

class Deadline {
 public:
  using Clock = std::chrono::steady_clock;

  // No limit.
  Deadline() = default;
  explicit Deadline(Clock::time_point at, const std::atomic<bool>* cancel = nullptr) : at_(at), cancel_(cancel) {}

  static Deadline after(std::chrono::nanoseconds budget, const std::atomic<bool>* cancel = nullptr) {
    return Deadline(Clock::now() + budget, cancel);
  }
  static Deadline after_ms(double budget_ms, const std::atomic<bool>* cancel = nullptr) {
    return after(std::chrono::nanoseconds(static_cast<long long>(budget_ms * 1e6)), cancel);
  }

  bool expired() const {
    if (cancel_ != nullptr && cancel_->load(std::memory_order_relaxed)) return true;
    return at_ != Clock::time_point::max() && Clock::now() >= at_;
  }
  bool cancelled() const { return cancel_ != nullptr && cancel_->load(std::memory_order_relaxed); }
  Clock::time_point at() const { return at_; }

 private:
  Clock::time_point at_{Clock::time_point::max()};
  const std::atomic<bool>* cancel_{nullptr};
};

}  // namespace pullout
