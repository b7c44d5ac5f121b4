#include "runtime/progress_phase.hpp"

#include <chrono>
#include <utility>

#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

constexpr std::int64_t kReportIntervalNs = 50'000'000;

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

ProgressPhase::ProgressPhase(const ProgressCallback& callback, std::string name, std::uint64_t total, const char* unit,
                             std::string detail)
    : callback_(callback ? &callback : nullptr),
      name_(std::move(name)),
      unit_(unit),
      detail_(std::move(detail)),
      total_(total) {
  if (!callback_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!call(Progress::Event::begin)) cancelled_ = true;
  check();
}

ProgressPhase::~ProgressPhase() {
  if (!callback_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    call(Progress::Event::end);  // too late to cancel: the phase is over
  } catch (...) {
    // A callback that throws at the end of a phase cannot stop a destructor.
  }
}

void ProgressPhase::check() const {
  if (cancelled_.load(std::memory_order_relaxed)) throw Cancelled();
}

void ProgressPhase::report_if_due() {
  const std::int64_t now = steady_ns();
  if (now >= next_report_ns_.load(std::memory_order_relaxed)) {
    // One thread reports; the others go on with their work.
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (lock.owns_lock() && now >= next_report_ns_.load(std::memory_order_relaxed)) {
      next_report_ns_.store(now + kReportIntervalNs, std::memory_order_relaxed);
      if (!call(Progress::Event::advance)) cancelled_ = true;
    }
  }
  check();
}

bool ProgressPhase::call(Progress::Event event) {
  Progress p;
  p.event = event;
  p.phase = name_.c_str();
  p.unit = unit_;
  p.detail = detail_.c_str();
  p.done = done_.load(std::memory_order_relaxed);
  p.total = total_.load(std::memory_order_relaxed);
  if (event == Progress::Event::end && p.total > 0) p.done = p.total;
  return (*callback_)(p);
}

}  // namespace oocsimp
