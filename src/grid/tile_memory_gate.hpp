// Tiles admitted to work while their working sets fit a share of --mem together.
//
// Tiles are planned from a sample of the vertices, but an uneven input (a dense part
// in a sparse scan, the generated parts mesh) puts many times the planned triangles in
// its fullest tiles. Two such tiles on two threads at once would take the process past
// --mem. The gate lets a tile start only while the working sets of the tiles in work,
// its own included, stay within the share; a tile larger than the whole share runs
// alone. Given the run's budget, it also waits while what the process holds (measured:
// the spills, borders and scratch the share does not cover, and the allocator's free
// pages) and the tiles in work would not fit it. Which thread works on which tile, and
// when, changes no output.
#pragma once

#include <tbb/task_arena.h>

#include <condition_variable>
#include <cstdint>
#include <mutex>

#include "runtime/memory_budget.hpp"

namespace oocsimp {

/// A tile's working set per triangle record while it is graded or clustered (its
/// records, local mesh, graded vertices, block and sums). Taken from the peak
/// anonymous memory of one-thread runs whose fullest tiles differed in size (the
/// difference over the difference in records: about 160 bytes per record), rounded up
/// for the grading's own peak.
constexpr std::uint64_t kTileBytesPerRecord = 200;

class TileMemoryGate {
 public:
  /// `share`: bytes the tiles in work may take together. `budget` (may be null): the
  /// run's, which the memory held and the tiles in work must fit. `release` (may be
  /// null): gives the allocator's free pages back (SimplifyOptions::release_memory).
  explicit TileMemoryGate(std::uint64_t share, const MemoryBudget* budget = nullptr, void (*release)() = nullptr)
      : share_(share), budget_(budget), release_(release) {}

  /// Runs f() once a tile of `bytes` fits next to the tiles in work (at once when no
  /// tile is in work). f runs isolated: a thread waiting inside it for nested
  /// parallel work takes no other tile, which could wait at this gate for f's own
  /// share and never return.
  template <class F>
  void run(std::uint64_t bytes, F&& f) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      fits_.wait(lock, [&] { return (in_work_ == 0 || in_work_ + bytes <= share_) && fits_budget(bytes); });
      in_work_ += bytes;
    }
    struct Release {
      TileMemoryGate& gate;
      std::uint64_t bytes;
      ~Release() {
        {
          std::lock_guard<std::mutex> lock(gate.mutex_);
          gate.in_work_ -= bytes;
        }
        gate.fits_.notify_all();
      }
    } release{*this, bytes};
    tbb::this_task_arena::isolate([&] { f(); });
  }

 private:
  // What the process holds counts the tiles in work as far as they have grown: their
  // whole estimates are added on top, which errs on the side of waiting. Freed tiles
  // leave pages in the allocator's per-thread arenas, which a thread starting the next
  // tile in another arena would not reuse: they are given back before a tile is
  // refused, and a tile with none in work starts anyway.
  bool fits_budget(std::uint64_t bytes) {
    if (!budget_ || budget_->fits(budget_->held(), in_work_ + bytes)) return true;
    if (release_) release_();
    return budget_->fits(budget_->held(), in_work_ + bytes) || in_work_ == 0;
  }

  std::uint64_t share_;
  const MemoryBudget* budget_;
  void (*release_)();
  std::uint64_t in_work_ = 0;
  std::mutex mutex_;
  std::condition_variable fits_;
};

}  // namespace oocsimp
