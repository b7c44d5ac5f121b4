#include "io/content_hash.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

constexpr std::uint64_t kPrime1 = 0x9E3779B185EBCA87ull, kPrime2 = 0xC2B2AE3D27D4EB4Full,
                        kPrime3 = 0x165667B19E3779F9ull, kPrime4 = 0x85EBCA77C2B2AE63ull,
                        kPrime5 = 0x27D4EB2F165667C5ull;

std::uint64_t rotl(std::uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

std::uint64_t read64(const unsigned char* p) {
  std::uint64_t v;
  std::memcpy(&v, p, 8);
  return v;  // little-endian hosts only, as the rest of oocsimp's binary spills
}

std::uint32_t read32(const unsigned char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

std::uint64_t xxh_round(std::uint64_t acc, std::uint64_t input) { return rotl(acc + input * kPrime2, 31) * kPrime1; }

std::uint64_t merge_round(std::uint64_t acc, std::uint64_t lane) {
  return (acc ^ xxh_round(0, lane)) * kPrime1 + kPrime4;
}

}  // namespace

void ContentHash::add(const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  total_ += bytes;
  if (pending_bytes_ > 0) {
    std::size_t k = std::min(bytes, sizeof pending_ - pending_bytes_);
    std::memcpy(pending_ + pending_bytes_, p, k);
    pending_bytes_ += k;
    p += k;
    bytes -= k;
    if (pending_bytes_ < sizeof pending_) return;
    for (int i = 0; i < 4; ++i) lane_[i] = xxh_round(lane_[i], read64(pending_ + 8 * i));
    pending_bytes_ = 0;
  }
  for (; bytes >= 32; p += 32, bytes -= 32)
    for (int i = 0; i < 4; ++i) lane_[i] = xxh_round(lane_[i], read64(p + 8 * i));
  std::memcpy(pending_, p, bytes);
  pending_bytes_ = bytes;
}

std::uint64_t ContentHash::digest() const {
  std::uint64_t h;
  if (total_ >= 32) {
    h = rotl(lane_[0], 1) + rotl(lane_[1], 7) + rotl(lane_[2], 12) + rotl(lane_[3], 18);
    for (int i = 0; i < 4; ++i) h = merge_round(h, lane_[i]);
  } else {
    h = kPrime5;  // seed 0
  }
  h += total_;
  const unsigned char* p = pending_;
  std::size_t n = pending_bytes_;
  for (; n >= 8; p += 8, n -= 8) h = rotl(h ^ xxh_round(0, read64(p)), 27) * kPrime1 + kPrime4;
  if (n >= 4) {
    h = rotl(h ^ (std::uint64_t(read32(p)) * kPrime1), 23) * kPrime2 + kPrime3;
    p += 4;
    n -= 4;
  }
  for (; n > 0; ++p, --n) h = rotl(h ^ (*p * kPrime5), 11) * kPrime1;
  h ^= h >> 33;
  h *= kPrime2;
  h ^= h >> 29;
  h *= kPrime3;
  h ^= h >> 32;
  return h;
}

std::uint64_t content_hash(const void* data, std::size_t bytes) {
  ContentHash h;
  h.add(data, bytes);
  return h.digest();
}

FileDigest file_digest(const std::string& path, const std::atomic<bool>* stop) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(system_error_text(path, "cannot open", errno));
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_SEQUENTIAL);
  std::vector<unsigned char> buf(std::size_t(1) << 20);
  ContentHash h;
  FileDigest d;
  while (!(stop && stop->load())) {
    ssize_t r = ::read(fd, buf.data(), buf.size());
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      int e = errno;
      ::close(fd);
      throw IoError(system_error_text(path, "read failed", e));
    }
    if (r == 0) break;
    h.add(buf.data(), std::size_t(r));
    d.size += std::uint64_t(r);
  }
  ::close(fd);
  d.hash = h.digest();
  return d;
}

}  // namespace oocsimp
