// One block per tile, written once, then used in place: in anonymous memory while
// the blocks fit an allowance, memory-mapped from a temporary file beyond it. The
// out-of-core home of data that later passes read and update in place.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "io/temp_file.hpp"
#include "spill/memory_slabs.hpp"

namespace oocsimp {

/// Tiles' blocks of bytes. Each tile's block is written once (put, from any
/// thread): into memory while the blocks held there stay within `memory_allowance`
/// bytes, else at the end of a temporary file (created with its first block). map()
/// then maps the file shared and read-write, so a block is used in place and changes
/// to it go to the file: the kernel pages file blocks in and out as they are used,
/// and none of them counts as heap. Blocks start at 8-byte boundaries. Which blocks
/// stay in memory depends on the order of the puts; nothing else does.
class BlockStore {
 public:
  BlockStore(const std::string& temp_dir, const std::string& name, std::uint32_t tiles,
             std::uint64_t memory_allowance = 0);
  ~BlockStore();
  BlockStore(const BlockStore&) = delete;
  BlockStore& operator=(const BlockStore&) = delete;

  /// Stores `bytes` bytes at `data` as the block of `tile` (once per tile, before
  /// map()). Thread-safe. Throws IoError naming the folder and the space needed when
  /// the disk is full.
  void put(std::uint32_t tile, const void* data, std::size_t bytes);
  /// Maps the file, if any; put() may not be called afterwards. Throws IoError.
  void map();
  /// The block of `tile` after map(), writable; nullptr for a tile without one.
  unsigned char* block(std::uint32_t tile) const;
  std::size_t block_size(std::uint32_t tile) const { return sizes_[tile]; }
  /// Bytes written to the file.
  std::uint64_t bytes_on_disk() const { return end_; }
  /// Bytes of the blocks held in memory (in all, discard() aside).
  std::uint64_t bytes_in_memory() const { return memory_bytes_; }
  /// Frees the memory blocks and unmaps the file, for an owner done with the blocks
  /// (block() then gives nullptr).
  void discard();

 private:
  void write_to_file(std::uint32_t tile, const void* data, std::size_t bytes);

  std::unique_ptr<TempFile> file_;  // created with the first block that goes to it
  std::string dir_, name_;
  std::vector<std::uint64_t> offsets_, sizes_;
  std::vector<unsigned char*> memory_;  // per tile, its block when held in memory (in slabs_)
  MemorySlabs slabs_;
  std::uint64_t memory_allowance_;
  std::mutex mutex_;  // guards file_, end_ and memory_bytes_
  std::uint64_t end_ = 0;
  std::uint64_t memory_bytes_ = 0;
  unsigned char* base_ = nullptr;
};

}  // namespace oocsimp
