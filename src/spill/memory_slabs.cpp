#include "spill/memory_slabs.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <new>

namespace oocsimp {

namespace {
const std::size_t kPage = std::size_t(::sysconf(_SC_PAGESIZE));
}  // namespace

unsigned char* MemorySlabs::allocate(std::size_t bytes) {
  bytes = (bytes + 7) & ~std::size_t(7);
  std::lock_guard<std::mutex> lock(mutex_);
  if (bytes > left_) {
    // A new slab; the rest of the last one is never touched, so never resident.
    const std::size_t size = std::max(kSlabBytes, (bytes + kPage - 1) / kPage * kPage);
    void* p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    maps_.emplace_back(p, size);
    next_ = static_cast<unsigned char*>(p);
    populated_ = next_;
    left_ = size;
  }
  unsigned char* at = next_;
  next_ += bytes;
  left_ -= bytes;
  // Fault the pages about to be written in, kPopulateBytes at a time: one call
  // instead of a page fault per page (this shortens binning, whose serial stage
  // copies the blocks). Where the kernel has no MADV_POPULATE_WRITE (before Linux
  // 5.14) the pages fault in as they are written.
  if (populate_ && next_ > populated_) {
    const std::size_t to_end = std::size_t(next_ + left_ - populated_);  // whole pages: so is a slab
    const std::size_t ahead = std::max(kPopulateBytes, std::size_t(next_ - populated_));
    const std::size_t n = std::min((ahead + kPage - 1) / kPage * kPage, to_end);
#ifdef MADV_POPULATE_WRITE
    ::madvise(populated_, n, MADV_POPULATE_WRITE);
#endif
    populated_ += n;
  }
  return at;
}

void MemorySlabs::release() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [p, size] : maps_) ::munmap(p, size);
  maps_.clear();
  next_ = nullptr;
  populated_ = nullptr;
  left_ = 0;
}

}  // namespace oocsimp
