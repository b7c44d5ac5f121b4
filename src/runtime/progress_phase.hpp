// A phase of a run as the caller's ProgressCallback hears it (oocsimp/progress.hpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "oocsimp/progress.hpp"

namespace oocsimp {

/// Begun when constructed, ended when destroyed (also when the phase fails). Counts
/// reported from any thread reach the callback at once the first time, then at most
/// every 50 ms, one call at a time. When the callback returns false the phase is cancelled: that report, and
/// every later one or check(), throws Cancelled. With an empty callback every member
/// is a test of one pointer.
class ProgressPhase {
 public:
  /// `detail`: what the phase says of itself beside its counts (Progress::detail).
  ProgressPhase(const ProgressCallback& callback, std::string name, std::uint64_t total, const char* unit,
                std::string detail = "");
  ~ProgressPhase();
  ProgressPhase(const ProgressPhase&) = delete;
  ProgressPhase& operator=(const ProgressPhase&) = delete;

  /// Sets the phase's total when it becomes known after the start.
  void set_total(std::uint64_t total) {
    if (callback_) total_.store(total, std::memory_order_relaxed);
  }
  /// Sets the units done (any thread).
  void set(std::uint64_t done) {
    if (!callback_) return;
    done_.store(done, std::memory_order_relaxed);
    report_if_due();
  }
  /// Adds `n` units done (any thread).
  void advance(std::uint64_t n) {
    if (!callback_) return;
    done_.fetch_add(n, std::memory_order_relaxed);
    report_if_due();
  }
  /// Sets what the phase says of itself from the next report on, its end included.
  void set_detail(const std::string& detail) {
    if (!callback_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    detail_ = detail;
  }
  /// Throws Cancelled when the callback has asked to stop.
  void check() const;

 private:
  void report_if_due();
  bool call(Progress::Event event);  // with mutex_ held; false: the callback asked to stop

  const ProgressCallback* callback_;  // null when the caller gave none
  const std::string name_;
  const char* unit_;
  std::string detail_;  // guarded by mutex_
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::uint64_t> total_{0};
  std::atomic<std::int64_t> next_report_ns_{0};
  std::atomic<bool> cancelled_{false};
  std::mutex mutex_;
};

}  // namespace oocsimp
