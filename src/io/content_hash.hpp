// A 64-bit content checksum (XXH64, from Debian's libxxhash-dev, used header-only),
// fed in pieces of any size: what tells a file apart from another of the same size and
// times (--keep-tmp resumes, kept files).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#define XXH_INLINE_ALL
#include <xxhash.h>

namespace oocsimp {

/// XXH64 (seed 0) over everything passed to add(): the digest depends only on the
/// bytes, not on how they were split into calls.
class ContentHash {
 public:
  ContentHash() { XXH64_reset(&state_, 0); }
  void add(const void* data, std::size_t bytes) { XXH64_update(&state_, data, bytes); }
  std::uint64_t digest() const { return XXH64_digest(&state_); }

 private:
  XXH64_state_t state_;
};

/// XXH64 of `bytes` bytes at `data`.
std::uint64_t content_hash(const void* data, std::size_t bytes);

/// A file's size and the XXH64 of its bytes, read front to back. Throws IoError
/// naming the file when it cannot be opened or read. When `*stop` becomes true the
/// read ends early and the result means nothing.
struct FileDigest {
  std::uint64_t size = 0;
  std::uint64_t hash = 0;
  bool operator==(const FileDigest& o) const { return size == o.size && hash == o.hash; }
  bool operator!=(const FileDigest& o) const { return !(*this == o); }
};
FileDigest file_digest(const std::string& path, const std::atomic<bool>* stop = nullptr);

}  // namespace oocsimp
