// The process's memory and the clock, as the runs report and budget them.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

namespace oocsimp {

/// Current anonymous resident memory of this process in bytes (RssAnon).
std::uint64_t current_anon_bytes();
/// MemAvailable of /proc/meminfo: memory the kernel can give without swapping,
/// page cache included (0 where unknown).
std::uint64_t available_memory_bytes();
/// Peak resident memory of this process in bytes (VmHWM: anonymous and file-backed).
std::uint64_t peak_rss_bytes();
/// Monotonic seconds.
double now_seconds();

/// The largest anonymous RSS of the process while it lives: the kernel keeps a peak
/// of the whole resident set only (VmHWM, mapped input included), so a thread
/// samples RssAnon every 20 ms.
class PeakAnonSampler {
 public:
  PeakAnonSampler();
  ~PeakAnonSampler();
  PeakAnonSampler(const PeakAnonSampler&) = delete;
  PeakAnonSampler& operator=(const PeakAnonSampler&) = delete;
  /// The largest anonymous RSS seen so far, now included.
  std::uint64_t peak() const;

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;  // guarded by mutex_
  std::atomic<std::uint64_t> peak_{0};
  std::thread thread_;
};

}  // namespace oocsimp
