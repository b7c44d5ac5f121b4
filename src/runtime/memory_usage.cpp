#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>

#include "runtime/memory_usage.hpp"

#include "oocsimp/names.hpp"  // default_memory_budget

namespace oocsimp {

namespace {

// Reads a "Key:   N kB" line of a /proc file (/proc/self/status), in bytes.
std::uint64_t status_field(const char* key, const char* file = "/proc/self/status") {
  int fd = ::open(file, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  char buf[8192];
  ssize_t n = ::read(fd, buf, sizeof buf - 1);
  ::close(fd);
  if (n <= 0) return 0;
  buf[n] = '\0';
  const char* p = std::strstr(buf, key);
  if (!p) return 0;
  p += std::strlen(key);
  unsigned long long kb = 0;
  if (std::sscanf(p, ": %llu", &kb) != 1) return 0;
  return std::uint64_t(kb) * 1024;
}

}  // namespace

std::uint64_t current_anon_bytes() { return status_field("RssAnon"); }
std::uint64_t peak_rss_bytes() { return status_field("VmHWM"); }
std::uint64_t available_memory_bytes() { return status_field("MemAvailable", "/proc/meminfo"); }

double now_seconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

namespace {

void raise_to(std::atomic<std::uint64_t>& peak, std::uint64_t value) {
  std::uint64_t p = peak.load();
  while (value > p && !peak.compare_exchange_weak(p, value)) {
  }
}

}  // namespace

PeakAnonSampler::PeakAnonSampler() : peak_(current_anon_bytes()) {
  thread_ = std::thread([this] {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      raise_to(peak_, current_anon_bytes());
      wake_.wait_for(lock, std::chrono::milliseconds(20));
    }
  });
}

PeakAnonSampler::~PeakAnonSampler() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

std::uint64_t PeakAnonSampler::peak() const {
  const std::uint64_t now = current_anon_bytes();
  const std::uint64_t p = peak_.load();
  return now > p ? now : p;
}

std::uint64_t default_memory_budget() {
  long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return std::uint64_t(1) << 30;
  return std::uint64_t(pages) * std::uint64_t(page) / 4;
}

}  // namespace oocsimp
