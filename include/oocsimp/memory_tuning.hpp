// Process-wide allocator settings for a program that runs oocsimp: the library sets
// none itself (the CLI calls these; see SimplifyOptions::release_memory).
#pragma once

namespace oocsimp {

/// Fixes glibc's mmap threshold at 4 MiB: the floating method's tiles allocate and
/// free buffers of 0.1-10 MiB on every thread, and glibc's dynamic threshold would
/// soon serve even the largest from its per-thread arenas, which keep freed memory.
/// Call once at start-up, before other threads allocate.
void tune_allocator_for_tiles();

/// Gives the allocator's free memory back to the system (malloc_trim): freed memory
/// in the per-thread arenas otherwise counts against the budget. For
/// SimplifyOptions::release_memory.
void release_free_heap();

}  // namespace oocsimp
