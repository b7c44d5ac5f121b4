// Anonymous memory for the spill blocks held in memory, in large mappings of its own.
#pragma once

#include <cstddef>
#include <mutex>
#include <utility>
#include <vector>

namespace oocsimp {

/// A bump allocator over anonymous mappings of at least kSlabBytes, freed all at
/// once. Blocks held for a whole phase and then dropped together do not belong in
/// malloc's arenas: there they lie between the run's other allocations, and
/// malloc_trim gave back only part of them once freed (much of them stayed resident
/// into the assembly). A mapping goes back whole.
class MemorySlabs {
 public:
  static constexpr std::size_t kSlabBytes = std::size_t(8) << 20;
  /// Pages are faulted in this much at a time, ahead of the blocks written: the
  /// most that is resident and unused.
  static constexpr std::size_t kPopulateBytes = std::size_t(1) << 20;

  /// `populate`: fault pages in ahead of the blocks (blocks written whole, at once);
  /// without it, a page is resident only once written (buffers filled bit by bit,
  /// many of them partly). `huge` (with `populate`): slabs over 2 MiB pages, faulted
  /// in a huge page ahead; first writes to fresh memory ran many times faster over them
  /// (docs/benchmarks.md, "Fresh memory"), for up to a huge page more resident ahead.
  explicit MemorySlabs(bool populate = true, bool huge = false) : populate_(populate), huge_(populate && huge) {}
  MemorySlabs(const MemorySlabs&) = delete;
  MemorySlabs& operator=(const MemorySlabs&) = delete;
  ~MemorySlabs() { release(); }

  /// `bytes` bytes, 8-byte aligned, valid until release(). Thread-safe. Throws
  /// std::bad_alloc. Pages are only resident once written.
  unsigned char* allocate(std::size_t bytes);
  /// Unmaps everything allocate() gave (not while another thread allocates).
  void release();

 private:
  std::mutex mutex_;
  std::vector<std::pair<void*, std::size_t>> maps_;
  unsigned char* next_ = nullptr;
  unsigned char* populated_ = nullptr;  // pages before it are faulted in
  std::size_t left_ = 0;
  bool populate_ = true;
  bool huge_ = false;
};

}  // namespace oocsimp
