#include "spill/block_store.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "oocsimp/error.hpp"

namespace oocsimp {

BlockStore::BlockStore(const std::string& temp_dir, const std::string& name, std::uint32_t tiles)
    : file_(std::make_unique<TempFile>(temp_dir, "oocsimp-" + name + "-")),
      dir_(temp_dir),
      offsets_(tiles, 0),
      sizes_(tiles, 0) {}

BlockStore::~BlockStore() {
  if (base_) ::munmap(base_, std::size_t(end_));
}

void BlockStore::put(std::uint32_t tile, const void* data, std::size_t bytes) {
  std::uint64_t at;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    at = end_;
    end_ += (std::uint64_t(bytes) + 7) & ~std::uint64_t(7);
  }
  offsets_[tile] = at;
  sizes_[tile] = bytes;
  auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t offset = at;
  for (std::size_t n = bytes; n > 0;) {
    ssize_t w = ::pwrite(file_->fd(), p, n, off_t(offset));
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
  return base_ && sizes_[tile] ? base_ + offsets_[tile] : nullptr;
}

}  // namespace oocsimp
