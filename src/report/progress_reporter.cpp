#include "oocsimp/progress_reporter.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>

namespace oocsimp {

namespace {
constexpr double kPollSeconds = 0.02;
constexpr double kTtyRefresh = 0.2;
constexpr double kLogInterval = 5.0;  // plain lines for batch logs

double now_seconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}
}  // namespace

ProgressReporter::ProgressReporter(bool quiet) : quiet_(quiet), tty_(::isatty(2) == 1) {
  if (!quiet_) thread_ = std::thread([this] { loop(); });
}

ProgressReporter::~ProgressReporter() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

ProgressCallback ProgressReporter::callback() {
  return [this](const Progress& p) {
    switch (p.event) {
      case Progress::Event::begin:
        begin(p.phase, p.total, p.unit, p.detail);
        break;
      case Progress::Event::advance:
        if (p.total) set_total(p.total);
        set(p.done);
        break;
      case Progress::Event::end:
        end(p.detail);
        break;
    }
    return true;
  };
}

void ProgressReporter::begin(const std::string& name, std::uint64_t total, const char* unit, const char* detail) {
  std::lock_guard<std::mutex> lock(mutex_);
  name_ = name;
  unit_ = unit;
  detail_ = detail ? detail : "";
  total_ = total;
  done_ = 0;
  phase_start_ = now_seconds();
  active_ = true;
  // Batch logs (and whoever watches them) see when each phase starts, not only when
  // it ends.
  if (!quiet_ && !tty_) {
    std::fprintf(stderr, "oocsimp: %s started%s%s\n", name_.c_str(), detail_.empty() ? "" : ": ", detail_.c_str());
    std::fflush(stderr);
  }
}

void ProgressReporter::end(const char* detail) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!active_) return;
  if (detail) detail_ = detail;
  if (total_ > 0) done_ = total_.load();
  print(true);
  active_ = false;
}

void ProgressReporter::loop() {
  double last_sample_print = now_seconds();
  while (!stop_) {
    double t = now_seconds();
    if (active_ && t - last_sample_print >= (tty_ ? kTtyRefresh : kLogInterval)) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (active_) print(false);
      last_sample_print = t;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(kPollSeconds));
  }
}

// Called with mutex_ held.
void ProgressReporter::print(bool final_line) {
  if (quiet_) return;
  double t = now_seconds();
  double elapsed = t - phase_start_;
  std::uint64_t done = done_.load(), total = total_.load();
  double rate = elapsed > 0 ? double(done) / elapsed : 0;
  double frac = total > 0 ? double(done) / double(total) : 0;
  if (frac > 1) frac = 1;
  char rate_text[32];
  double r = rate;
  const char* prefix = "";
  if (r >= 1e9) {
    r /= 1e9;
    prefix = "G";
  } else if (r >= 1e6) {
    r /= 1e6;
    prefix = "M";
  } else if (r >= 1e3) {
    r /= 1e3;
    prefix = "k";
  }
  std::snprintf(rate_text, sizeof rate_text, "%.1f %s%s/s", r, prefix, unit_);
  double eta = (rate > 0 && total > done) ? double(total - done) / rate : 0;
  // A phase without a total has no percentage nor ETA, and until it has counted
  // something no rate either: only the elapsed time is true for it.
  std::string counted;
  if (done > 0) counted = std::string(total > 0 ? "" : std::to_string(done) + " " + unit_ + ", ") + rate_text;
  // What the phase says of itself (a pass's triangles in, then in and out), after
  // the counts.
  const std::string said = detail_.empty() ? "" : "  " + detail_;
  if (tty_) {
    constexpr int kWidth = 30;
    int filled = int(frac * kWidth);
    char bar[kWidth + 1];
    for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '-';
    bar[kWidth] = '\0';
    if (total == 0)
      std::fprintf(stderr, "\r\033[K%-16s %s%s%.2fs%s%s", name_.c_str(), counted.c_str(), counted.empty() ? "" : "  ",
                   elapsed, said.c_str(), final_line ? "\n" : "");
    else if (final_line)
      std::fprintf(stderr, "\r\033[K%-16s [%s] 100%%  %s  %.2fs%s\n", name_.c_str(), bar, rate_text, elapsed,
                   said.c_str());
    else if (done == 0)
      std::fprintf(stderr, "\r\033[K%-16s [%s]   0%%  %.2fs%s", name_.c_str(), bar, elapsed, said.c_str());
    else
      std::fprintf(stderr, "\r\033[K%-16s [%s] %3d%%  %s  ETA %.0fs%s", name_.c_str(), bar, int(frac * 100), rate_text,
                   eta, said.c_str());
  } else {
    const char* colon = detail_.empty() ? "" : ": ";
    if (final_line && counted.empty())
      std::fprintf(stderr, "oocsimp: %s done in %.2fs%s%s\n", name_.c_str(), elapsed, colon, detail_.c_str());
    else if (final_line)
      std::fprintf(stderr, "oocsimp: %s done in %.2fs (%s)%s%s\n", name_.c_str(), elapsed, counted.c_str(), colon,
                   detail_.c_str());
    else if (total == 0 || done == 0)
      std::fprintf(stderr, "oocsimp: %s %s%s%.0fs so far\n", name_.c_str(), counted.c_str(),
                   counted.empty() ? "" : ", ", elapsed);
    else
      std::fprintf(stderr, "oocsimp: %s %d%% (%s, ETA %.0fs)\n", name_.c_str(), int(frac * 100), rate_text, eta);
  }
  std::fflush(stderr);
}

}  // namespace oocsimp
