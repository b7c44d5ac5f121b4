#include "oocsimp/process.hpp"

#include <malloc.h>

#include <algorithm>
#include <cstdint>

namespace oocsimp {

void tune_allocator_for_tiles() {
  // A fixed threshold maps the tiles' large buffers and unmaps them on free, so the
  // heap follows what is in use. The dynamic threshold let the peak grow; a low fixed
  // one (such as 256 KiB) cost system time, every tile faulting its buffers in afresh;
  // 4 MiB keeps the low peak at a smaller system cost.
  ::mallopt(M_MMAP_THRESHOLD, 4 << 20);
}

void keep_freed_heap(std::uint64_t budget_bytes) {
  // glibc gives the top of an arena back to the system once 128 KiB of it are free
  // (its default, fixed by tune_allocator_for_tiles's M_MMAP_THRESHOLD): every tile of
  // the collapse's passes then faulted its buffers in afresh, a large share of a
  // run's CPU in the kernel (docs/benchmarks.md, "The collapse core", page faults).
  // A sixty-fourth of the budget per arena (at most 256 MiB) keeps a tile's buffers
  // for the next tile on that thread. A budget under 512 MiB keeps the default: there
  // the few MiB kept in each arena are a share of the budget that its tightest runs
  // need.
  constexpr std::uint64_t kLeastBudget = std::uint64_t(512) << 20;
  if (budget_bytes < kLeastBudget) return;
  const std::uint64_t keep = std::min<std::uint64_t>(budget_bytes / 64, std::uint64_t(256) << 20);
  ::mallopt(M_TRIM_THRESHOLD, int(keep));
}

void release_free_heap() { ::malloc_trim(0); }

}  // namespace oocsimp
