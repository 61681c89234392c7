// Linked into the planning benchmarks: the heap set up as pullout_service sets it
// (pullout/process_heap.hpp), before main(), so that they measure what the service pays. To
// measure glibc's defaults instead, set a glibc.malloc tunable, e.g.
// GLIBC_TUNABLES=glibc.malloc.trim_threshold=131072 (the default), which leaves the heap as it is.
#include "pullout/process_heap.hpp"

namespace {
[[maybe_unused]] const pullout::HeapTuning kHeapTuning = pullout::tune_process_heap();
}  // namespace
