// The large generated families (every street spot, every shoulder of a map, thousands of random
// poses) run whole in scripts/test. Under AddressSanitizer (scripts/test-sanitize builds everything
// with -fsanitize=address,undefined) the same code is 3-10 times slower, and the sanitizers look
// for memory and undefined-behaviour errors in the code paths, which a sample of the cases takes
// as well: there the families run every kSanitizerStride-th case (a stride prime to every family
// dimension, so that the sample mixes each dimension's values), and the counts they assert are
// scaled with sampled_count().
#pragma once

#include <cstddef>

namespace pullout::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kUnderSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kUnderSanitizer = true;
#else
inline constexpr bool kUnderSanitizer = false;
#endif
#else
inline constexpr bool kUnderSanitizer = false;
#endif

inline constexpr std::size_t kSanitizerStride = kUnderSanitizer ? 7 : 1;

// Whether case `index` of a family runs in this build.
inline bool sampled(std::size_t index) { return index % kSanitizerStride == 0; }

// A count asserted over a whole family, for the sample this build runs (rounded down).
inline int sampled_count(int whole) { return whole / static_cast<int>(kSanitizerStride); }

}  // namespace pullout::test
