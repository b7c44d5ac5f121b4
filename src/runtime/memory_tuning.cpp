#include "oocsimp/oocsimp.hpp"

#include <malloc.h>

namespace oocsimp {

void tune_allocator_for_tiles() {
  // A fixed threshold maps the tiles' large buffers and unmaps them on free, so the
  // heap follows what is in use. Measured on the 10M sphere, --mem 64M, 2 threads
  // (peak anonymous / system seconds): dynamic 124 MiB / 1.3 s, 256 KiB 90 MiB / 4.0 s
  // (every tile faults its buffers in afresh), 4 MiB 89 MiB / 2.5 s.
  ::mallopt(M_MMAP_THRESHOLD, 4 << 20);
}

void release_free_heap() { ::malloc_trim(0); }

}  // namespace oocsimp
