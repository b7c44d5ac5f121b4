// The run's cap on worker threads (an option's `threads`, 0 = all cores).
#pragma once

#include <tbb/global_control.h>

#include <memory>

namespace oocsimp {

/// Caps TBB's parallelism at `threads` while the result lives; null (no cap) for 0.
inline std::unique_ptr<tbb::global_control> limit_threads(unsigned threads) {
  if (threads == 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
}

}  // namespace oocsimp
