// oocsimp — progress on a terminal or in a batch log (target oocsimp::progress_ui, not
// part of the core library): what the command line shows.
#pragma once

#include "oocsimp/export.hpp"

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "oocsimp/progress.hpp"

namespace oocsimp {

/// Shows the phases a ProgressCallback hears on stderr: a bar with percent, rate and
/// ETA when stderr is a terminal; otherwise (batch logs) "oocsimp: NAME started", a
/// plain line every few seconds and "oocsimp: NAME done in ..."; nothing when quiet.
/// A thread of its own refreshes the line, so the library's threads never print.
class OOCSIMP_API ProgressReporter {
 public:
  explicit ProgressReporter(bool quiet);
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

  /// The callback to give the library (it never cancels); valid while the reporter lives.
  ProgressCallback callback();

  /// Starts a phase named `name` whose work is `total` units of `unit` ("B", "tri"),
  /// with what it says of itself (Progress::detail; may be null).
  void begin(const std::string& name, std::uint64_t total, const char* unit, const char* detail = nullptr);
  /// Sets the phase's total when it becomes known after begin().
  void set_total(std::uint64_t total) { total_.store(total, std::memory_order_relaxed); }
  /// Sets the units done in the current phase (thread-safe, cheap).
  void set(std::uint64_t done) { done_.store(done, std::memory_order_relaxed); }
  /// Ends the current phase (prints its final line, with `detail` when given).
  void end(const char* detail = nullptr);

 private:
  void loop();
  void print(bool final_line);

  bool quiet_;
  bool tty_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::uint64_t> total_{0};
  std::atomic<bool> active_{false};
  std::mutex mutex_;  // guards name_, unit_ and the printing state
  std::string name_;
  std::string detail_;
  const char* unit_ = "";
  double phase_start_ = 0;
  std::thread thread_;
};

}  // namespace oocsimp
