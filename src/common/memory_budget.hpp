// The whole process against --mem (issue 10, "the budget is the process's"): the
// tables a method is about to build must fit next to the anonymous memory the process
// holds, or the run stops with a UsageError (exit 2) rather than exceed the budget.
#pragma once

#include <cstdint>
#include <string>

#include "oocsimp/error.hpp"

namespace oocsimp {

/// `bytes` in whole MiB, rounded up, as text.
inline std::string mib_text(std::uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20); }

/// Throws UsageError unless `bytes` more than the `held` bytes fit in `budget`:
/// "--mem B MiB cannot hold WHAT: ... need N MiB or more ...; ADVICE".
inline void check_memory_budget(std::uint64_t budget, std::uint64_t held, std::uint64_t bytes, const std::string& what,
                                const std::string& advice) {
  if (held + bytes <= budget) return;
  throw UsageError("--mem " + mib_text(budget) + " MiB cannot hold " + what + ": " + mib_text(bytes) +
                   " MiB or more next to the " + mib_text(held) + " MiB the process holds; " + advice);
}

}  // namespace oocsimp
