// The service's heap settings (pullout/process_heap.hpp).
#include "pullout/process_heap.hpp"

#include <stdlib.h>

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitizerAllocator = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitizerAllocator = true;
#else
constexpr bool kSanitizerAllocator = false;
#endif
#else
constexpr bool kSanitizerAllocator = false;
#endif

// Restores GLIBC_TUNABLES as it was.
class TunablesEnv : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* v = std::getenv("GLIBC_TUNABLES");
    had_ = v != nullptr;
    if (had_) saved_ = v;
  }
  void TearDown() override {
    if (had_) {
      ::setenv("GLIBC_TUNABLES", saved_.c_str(), 1);
    } else {
      ::unsetenv("GLIBC_TUNABLES");
    }
  }

 private:
  bool had_{false};
  std::string saved_;
};

TEST_F(TunablesEnv, AnOperatorsMallocTunableIsLeftAlone) {
  ::setenv("GLIBC_TUNABLES", "glibc.malloc.trim_threshold=131072", 1);
  EXPECT_EQ(pullout::tune_process_heap(), pullout::HeapTuning::kLeftToTunables);
  ::setenv("GLIBC_TUNABLES", "glibc.rtld.nns=2:glibc.malloc.arena_max=2", 1);
  EXPECT_EQ(pullout::tune_process_heap(), pullout::HeapTuning::kLeftToTunables);
}

TEST_F(TunablesEnv, OtherTunablesOrNoneApplyTheSettings) {
  // ASan's allocator has no mallopt settings: it refuses them, and the service says so.
  const pullout::HeapTuning expected =
      kSanitizerAllocator ? pullout::HeapTuning::kRefused : pullout::HeapTuning::kApplied;
  ::setenv("GLIBC_TUNABLES", "glibc.rtld.nns=2", 1);
  EXPECT_EQ(pullout::tune_process_heap(), expected);
  ::unsetenv("GLIBC_TUNABLES");
  EXPECT_EQ(pullout::tune_process_heap(), expected);
}

}  // namespace
