// Parts of a table filled on first use, once, by whichever thread asks first (the costmap's lazy
// distance transform and summed-area tables).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <thread>
#include <utility>
#include <vector>

namespace pullout {

// A std::allocator whose value-less construct() leaves the element uninitialised: a vector of
// numbers resized with it neither writes nor touches the pages of its new elements (a lazily
// filled table pays for the parts it fills only).
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  using value_type = T;
  UninitialisedAllocator() = default;
  template <class U>
  explicit UninitialisedAllocator(const UninitialisedAllocator<U>& /*unused*/) {}
  template <class U>
  struct rebind {  // NOLINT(readability-identifier-naming): the allocator requirements' name
    using other = UninitialisedAllocator<U>;
  };
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0) {
      ::new (static_cast<void*>(p)) U;
    } else {
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
  }
};

template <class T>
using UninitialisedVector = std::vector<T, UninitialisedAllocator<T>>;

// One flag per part: empty, being filled, ready. Thread safe: ensure() runs a part's fill once; a
// caller that finds another thread filling it waits for it (a fill takes microseconds).
class FillFlags {
 public:
  FillFlags() = default;
  explicit FillFlags(std::size_t count) : count_(count), state_(std::make_unique<std::atomic<std::uint8_t>[]>(count)) {
    for (std::size_t i = 0; i < count_; ++i) state_[i].store(kEmpty, std::memory_order_relaxed);
  }
  // A copy has the parts ready that are ready in `other` (their data is the owner's to copy);
  // a part being filled counts as empty.
  FillFlags(const FillFlags& other) : FillFlags(other.count_) {
    for (std::size_t i = 0; i < count_; ++i) {
      if (other.ready(i)) state_[i].store(kReady, std::memory_order_relaxed);
    }
  }
  FillFlags& operator=(const FillFlags& other) {
    if (this != &other) *this = FillFlags(other);
    return *this;
  }
  FillFlags(FillFlags&& other) noexcept = default;
  FillFlags& operator=(FillFlags&& other) noexcept = default;
  ~FillFlags() = default;

  std::size_t size() const { return count_; }
  bool ready(std::size_t i) const { return state_[i].load(std::memory_order_acquire) == kReady; }
  std::size_t count_ready() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < count_; ++i) n += ready(i) ? 1 : 0;
    return n;
  }

  // Runs fill() for part i unless it ran already. If it throws, the part stays empty.
  template <class Fill>
  void ensure(std::size_t i, Fill&& fill) const {
    if (ready(i)) return;
    std::uint8_t expected = kEmpty;
    if (state_[i].compare_exchange_strong(expected, kFilling, std::memory_order_acquire)) {
      try {
        fill();
      } catch (...) {
        state_[i].store(kEmpty, std::memory_order_release);
        throw;
      }
      state_[i].store(kReady, std::memory_order_release);
      return;
    }
    while (!ready(i)) {
      // Filled by another thread; or emptied again by a fill that threw: then this caller fills it.
      if (state_[i].load(std::memory_order_acquire) == kEmpty) {
        ensure(i, std::forward<Fill>(fill));
        return;
      }
      std::this_thread::yield();
    }
  }

 private:
  static constexpr std::uint8_t kEmpty = 0;
  static constexpr std::uint8_t kFilling = 1;
  static constexpr std::uint8_t kReady = 2;

  std::size_t count_{0};
  std::unique_ptr<std::atomic<std::uint8_t>[]> state_;
};

}  // namespace pullout
