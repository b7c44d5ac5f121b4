// oocsimp — progress on stderr and peak memory sampling.
#pragma once

#include <atomic>
#include <mutex>
#include <cstdint>
#include <string>
#include <thread>

namespace oocsimp {

/// Reports one phase at a time on stderr: a bar with percent, rate and ETA when
/// stderr is a terminal; otherwise (batch logs) "oocsimp: NAME started", a plain line
/// every few seconds and "oocsimp: NAME done in ..."; nothing when quiet. A background thread also samples the
/// process's anonymous resident memory so the peak can be reported (see peak_anon_bytes()).
class ProgressReporter {
 public:
  explicit ProgressReporter(bool quiet);
  ~ProgressReporter();

  /// Starts a phase named `name` whose work is `total` units of `unit` ("B", "tri").
  void begin(const std::string& name, std::uint64_t total, const char* unit);
  /// Sets the phase's total when it becomes known after begin().
  void set_total(std::uint64_t total) { total_.store(total, std::memory_order_relaxed); }
  /// Sets the units done in the current phase (thread-safe, cheap).
  void set(std::uint64_t done) { done_.store(done, std::memory_order_relaxed); }
  /// Ends the current phase (prints its final line).
  void end();
  /// The largest anonymous RSS seen so far, in bytes.
  std::uint64_t peak_anon_bytes() const;

 private:
  void loop();
  void print(bool final_line);

  bool quiet_;
  bool tty_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::uint64_t> total_{0};
  std::atomic<std::uint64_t> peak_anon_{0};
  std::atomic<bool> active_{false};
  std::mutex mutex_;  // guards name_, unit_ and the printing state
  std::string name_;
  const char* unit_ = "";
  double phase_start_ = 0;
  double last_print_ = 0;
  std::thread thread_;
};

/// One phase on a reporter that may be null: begun on construction, ended on
/// destruction (also when the phase fails).
class ProgressPhase {
 public:
  ProgressPhase(ProgressReporter* progress, const char* name, std::uint64_t total, const char* unit)
      : progress_(progress) {
    if (progress_) progress_->begin(name, total, unit);
  }
  ~ProgressPhase() {
    if (progress_) progress_->end();
  }
  ProgressPhase(const ProgressPhase&) = delete;
  ProgressPhase& operator=(const ProgressPhase&) = delete;
  void set(std::uint64_t done) {
    if (progress_) progress_->set(done);
  }
  /// Adds `n` units done from any thread.
  void advance(std::uint64_t n) { set(done_.fetch_add(n, std::memory_order_relaxed) + n); }

 private:
  ProgressReporter* progress_;
  std::atomic<std::uint64_t> done_{0};
};

/// Current anonymous resident memory of this process in bytes (RssAnon).
std::uint64_t current_anon_bytes();
/// MemAvailable of /proc/meminfo: memory the kernel can give without swapping,
/// page cache included (0 where unknown).
std::uint64_t available_memory_bytes();
/// Peak resident memory of this process in bytes (VmHWM: anonymous and file-backed).
std::uint64_t peak_rss_bytes();
/// Monotonic seconds.
double now_seconds();

}  // namespace oocsimp
