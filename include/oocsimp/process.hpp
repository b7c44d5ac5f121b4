// Process-wide settings for a program that runs oocsimp: the allocator's and the
// signals'. The library sets none of them itself; the CLI calls these.
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>

namespace oocsimp {

/// Fixes glibc's mmap threshold at 4 MiB: the floating method's tiles allocate and
/// free buffers of 0.1-10 MiB on every thread, and glibc's dynamic threshold would
/// soon serve even the largest from its per-thread arenas, which keep freed memory.
/// Call once at start-up, before other threads allocate.
OOCSIMP_API void tune_allocator_for_tiles();

/// Lets glibc keep up to a sixty-fourth of `budget_bytes` (at most 256 MiB) freed at
/// the top of each arena, where it gives back all above 128 KiB by default: the
/// collapse's tiles then reuse the buffers of the tile before them instead of
/// faulting fresh pages in. Budgets under 512 MiB keep glibc's default. Call once the
/// run's budget is known, before the run.
OOCSIMP_API void keep_freed_heap(std::uint64_t budget_bytes);

/// Gives the allocator's free memory back to the system (malloc_trim): freed memory
/// in the per-thread arenas otherwise counts against the budget. For
/// SimplifyOptions::release_memory.
OOCSIMP_API void release_free_heap();

/// Installs SIGINT, SIGTERM, SIGHUP and SIGQUIT handlers that delete all registered
/// temporary files and then terminate the process with the conventional status
/// (128 + signal), and ignores SIGXFSZ and SIGPIPE, so that a write beyond a file-size
/// limit (ulimit -f) fails with EFBIG, and one into a pipe or FIFO whose reader has gone
/// with EPIPE, and the run cleans up and exits 4 instead of being killed. A SIGBUS from reading a memory-mapped input
/// that shrank during the run (truncated by another process) deletes them too and exits 4 with "oocsimp: FILE: input
/// changed during the run"; any other SIGBUS is a crash after the clean-up.
OOCSIMP_API void install_signal_cleanup();

}  // namespace oocsimp
