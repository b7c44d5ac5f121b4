// A 64-bit content checksum (XXH64), fed in pieces of any size: what tells a file
// apart from another of the same size and times (--keep-tmp resumes, kept files).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

namespace oocsimp {

/// XXH64 (Collet, xxHash specification, seed 0) over everything passed to add(): the
/// digest depends only on the bytes, not on how they were split into calls.
class ContentHash {
 public:
  void add(const void* data, std::size_t bytes);
  std::uint64_t digest() const;

 private:
  std::uint64_t lane_[4] = {0x9E3779B185EBCA87ull + 0xC2B2AE3D27D4EB4Full, 0xC2B2AE3D27D4EB4Full, 0,
                            0 - 0x9E3779B185EBCA87ull};
  unsigned char pending_[32] = {};  // a partial stripe
  std::size_t pending_bytes_ = 0;
  std::uint64_t total_ = 0;
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
