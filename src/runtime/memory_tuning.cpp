#include "oocsimp/oocsimp.hpp"

#include <malloc.h>

namespace oocsimp {

void tune_allocator_for_tiles() {
  // A fixed threshold maps the tiles' large buffers and unmaps them on free, so the
  // heap follows what is in use. The dynamic threshold let the peak grow; a low fixed
  // one (such as 256 KiB) cost system time, every tile faulting its buffers in afresh;
  // 4 MiB keeps the low peak at a smaller system cost.
  ::mallopt(M_MMAP_THRESHOLD, 4 << 20);
}

void release_free_heap() { ::malloc_trim(0); }

}  // namespace oocsimp
