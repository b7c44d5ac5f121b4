#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>

#include "oocsimp/progress.hpp"

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

}  // namespace oocsimp
