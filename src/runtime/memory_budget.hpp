// The run against its memory budget, which bounds the whole process and not only the
// tables: the tables a method is about to build must fit next to the anonymous memory
// the run holds, or the run stops with a UsageError (exit 2) rather than exceed the
// budget.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>

#include "oocsimp/error.hpp"
#include "oocsimp/names.hpp"  // default_memory_budget
#include "runtime/memory_usage.hpp"

// Under AddressSanitizer the process's anonymous memory is mostly shadow memory and
// quarantined blocks, which say nothing of what the run holds: there only the
// computed needs are checked against the budget.
#if defined(__SANITIZE_ADDRESS__)
#define OOCSIMP_MEASURED_MEMORY_MEANINGFUL 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define OOCSIMP_MEASURED_MEMORY_MEANINGFUL 0
#endif
#endif
#ifndef OOCSIMP_MEASURED_MEMORY_MEANINGFUL
#define OOCSIMP_MEASURED_MEMORY_MEANINGFUL 1
#endif

namespace oocsimp {

/// `bytes` in whole MiB, rounded up, as text without a unit (io/temp_file.hpp's
/// mib_text writes "12.3 MiB").
inline std::string whole_mib(std::uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20); }

/// The bytes a budget option asks for: itself, or default_memory_budget() for 0 (the
/// options' "0 = a quarter of physical memory"). The one place that default applies.
inline std::uint64_t budget_bytes(std::uint64_t option) { return option ? option : default_memory_budget(); }

/// The budget of a run and the process's anonymous memory it does not cover.
class MemoryBudget {
 public:
  MemoryBudget() = default;  // unbounded
  /// A budget of `bytes`, taken when the run begins: with `counts_process` it bounds
  /// the whole process's anonymous memory, else only what the run adds to what the
  /// process held before it.
  MemoryBudget(std::uint64_t bytes, bool counts_process)
      : bytes_(bytes), host_(counts_process ? 0 : current_anon_bytes()) {}

  std::uint64_t bytes() const { return bytes_; }
  /// Anonymous bytes the run holds now (all the process's, less what it held before
  /// the run if that is not the run's).
  std::uint64_t held() const {
    if (!OOCSIMP_MEASURED_MEMORY_MEANINGFUL) return 0;
    const std::uint64_t now = current_anon_bytes();
    return now - std::min(now, host_);
  }
  /// Whether `more` bytes fit next to `held`.
  bool fits(std::uint64_t held, std::uint64_t more) const { return bytes_ == 0 || held + more <= bytes_; }
  /// Throws UsageError unless `more` bytes fit next to `held`: "options.memory_budget
  /// B MiB cannot hold WHAT: N MiB or more next to the H MiB the run holds; ADVICE".
  void check(std::uint64_t held, std::uint64_t more, const std::string& what, const std::string& advice) const {
    if (fits(held, more)) return;
    throw UsageError("options.memory_budget", "options.memory_budget " + whole_mib(bytes_) + " MiB cannot hold " +
                                                  what + ": " + whole_mib(more) + " MiB or more next to the " +
                                                  whole_mib(held) + " MiB the run holds; " + advice);
  }

 private:
  std::uint64_t bytes_ = 0;  // 0: unbounded
  std::uint64_t host_ = 0;
};

}  // namespace oocsimp
