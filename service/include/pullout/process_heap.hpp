// The heap of a planning process: large blocks kept for reuse between requests.
//
// Each request builds its lane index, costmap (1e6 cells at 100 m x 100 m and 0.1 m) and the
// costmap's tables afresh, and frees them when done. With glibc's defaults, blocks of a few
// megabytes come from mmap or from heap memory that is handed back to the kernel once free
// (trimmed), so the next request touches fresh pages and pays a page fault for each 4 KiB. On a
// virtual machine that is most of the costmap's build: bench_checker's BM_CostmapAddObstacles
// (100 m at 0.1 m, 193 polygons) takes 10.8 ms of CPU with the defaults and 4.2 ms with these
// settings, the same run (bench/RESULTS.md).
//
// tune_process_heap() serves blocks up to 32 MiB from the heap and keeps up to 64 MiB of free
// memory at the top of each heap mapped instead of trimming it. Memory stays bounded: the
// process keeps the pages of its largest request, and no more than 64 MiB of free memory per
// heap (glibc keeps one per thread that allocates, up to 8 per core).
// An operator who sets any glibc.malloc tunable in GLIBC_TUNABLES keeps those settings: nothing
// is changed then.
#pragma once

#include <malloc.h>

#include <cstdlib>
#include <cstring>

namespace pullout {

inline constexpr int kHeapMmapThresholdBytes = 32 << 20;
inline constexpr int kHeapTrimThresholdBytes = 64 << 20;

enum class HeapTuning { kApplied, kLeftToTunables, kRefused };

// Call once, early in main(), before any thread starts.
inline HeapTuning tune_process_heap() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, "glibc.malloc.") != nullptr) return HeapTuning::kLeftToTunables;
  const bool ok = mallopt(M_MMAP_THRESHOLD, kHeapMmapThresholdBytes) == 1 &&
                  mallopt(M_TRIM_THRESHOLD, kHeapTrimThresholdBytes) == 1;
  return ok ? HeapTuning::kApplied : HeapTuning::kRefused;
}

}  // namespace pullout
