#include "spill/block_store.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {
std::uint64_t padded(std::uint64_t bytes) { return (bytes + 7) & ~std::uint64_t(7); }
}  // namespace

BlockStore::BlockStore(const std::string& temp_dir, const std::string& name, std::uint32_t tiles,
                       std::uint64_t memory_allowance)
    : dir_(temp_dir),
      name_(name),
      offsets_(tiles, 0),
      sizes_(tiles, 0),
      memory_(tiles, nullptr),
      memory_allowance_(memory_allowance) {
  // Without an allowance every block goes to the file: create it now, so that a
  // folder that cannot hold it is reported before any work.
  if (memory_allowance_ == 0) file_ = std::make_unique<TempFile>(dir_, "oocsimp-" + name_ + "-");
}

BlockStore::~BlockStore() { discard(); }

void BlockStore::discard() {
  if (base_) ::munmap(base_, std::size_t(end_));
  base_ = nullptr;
  std::fill(memory_.begin(), memory_.end(), nullptr);
  slabs_.release();
}

void BlockStore::put(std::uint32_t tile, const void* data, std::size_t bytes) {
  sizes_[tile] = bytes;
  bool in_memory;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    in_memory = memory_bytes_ + padded(bytes) <= memory_allowance_;
    if (in_memory) memory_bytes_ += padded(bytes);
  }
  if (!in_memory) return write_to_file(tile, data, bytes);
  if (bytes == 0) return;
  memory_[tile] = slabs_.allocate(bytes);  // 8-byte aligned
  std::memcpy(memory_[tile], data, bytes);
}

void BlockStore::write_to_file(std::uint32_t tile, const void* data, std::size_t bytes) {
  std::uint64_t at;
  int fd;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!file_) file_ = std::make_unique<TempFile>(dir_, "oocsimp-" + name_ + "-");
    fd = file_->fd();
    at = end_;
    end_ += padded(bytes);
  }
  offsets_[tile] = at;
  auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t offset = at;
  for (std::size_t n = bytes; n > 0;) {
    ssize_t w = ::pwrite(fd, p, n, off_t(offset));
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) {
      int e = errno;
      throw IoError(dir_ + ": cannot write the tile block file (" + std::to_string(offset) + " bytes written, " +
                    std::to_string(n) + " more needed): " + std::strerror(e));
    }
    p += w;
    n -= std::size_t(w);
    offset += std::uint64_t(w);
  }
}

void BlockStore::map() {
  if (end_ == 0) return;
  // The padding of the last block is not written: extend the file over it, so every
  // mapped page is backed by the file.
  if (::ftruncate(file_->fd(), off_t(end_)) != 0)
    throw IoError(system_error_text(file_->path(), "cannot size the tile block file", errno));
  void* p = ::mmap(nullptr, std::size_t(end_), PROT_READ | PROT_WRITE, MAP_SHARED, file_->fd(), 0);
  if (p == MAP_FAILED) throw IoError(system_error_text(file_->path(), "cannot map the tile block file", errno));
  base_ = static_cast<unsigned char*>(p);
}

unsigned char* BlockStore::block(std::uint32_t tile) const {
  if (!sizes_[tile]) return nullptr;
  if (memory_[tile]) return memory_[tile];
  return base_ ? base_ + offsets_[tile] : nullptr;
}

}  // namespace oocsimp
