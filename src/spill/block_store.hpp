// One block per tile in a temporary file, written once and then memory-mapped: the
// out-of-core home of data that later passes read and update in place.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "oocsimp/temp_file.hpp"

namespace oocsimp {

/// Tiles' blocks of bytes in one temporary file. Each tile's block is written once
/// (put, from any thread) at the end of the file; map() then maps the whole file
/// shared and read-write, so a block is used in place and changes to it go to the
/// file: the kernel pages blocks in and out as they are used, and none of it counts
/// as heap. Blocks start at 8-byte boundaries.
class BlockStore {
 public:
  BlockStore(const std::string& temp_dir, const std::string& name, std::uint32_t tiles);
  ~BlockStore();
  BlockStore(const BlockStore&) = delete;
  BlockStore& operator=(const BlockStore&) = delete;

  /// Writes `bytes` bytes at `data` as the block of `tile` (once per tile, before
  /// map()). Thread-safe. Throws IoError naming the folder and the space needed when
  /// the disk is full.
  void put(std::uint32_t tile, const void* data, std::size_t bytes);
  /// Maps the file; put() may not be called afterwards. Throws IoError.
  void map();
  /// The block of `tile` after map(), writable; nullptr for a tile without one.
  unsigned char* block(std::uint32_t tile) const;
  std::size_t block_size(std::uint32_t tile) const { return sizes_[tile]; }
  /// Bytes written to the file.
  std::uint64_t bytes_on_disk() const { return end_; }

 private:
  std::unique_ptr<TempFile> file_;
  std::string dir_;
  std::vector<std::uint64_t> offsets_, sizes_;
  std::mutex mutex_;  // guards end_
  std::uint64_t end_ = 0;
  unsigned char* base_ = nullptr;
};

}  // namespace oocsimp
