#include "spill/memory_slabs.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <new>

#include "common/huge_pages.hpp"

namespace oocsimp {

namespace {
const std::size_t kPage = std::size_t(::sysconf(_SC_PAGESIZE));
constexpr std::size_t kHugePage = std::size_t(2) << 20;

// An anonymous mapping of `size` bytes (a multiple of kHugePage) that starts on a
// huge page, with huge pages asked for: a larger one mapped, its ends cut off.
void* map_huge(std::size_t size) {
  void* raw = ::mmap(nullptr, size + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto at = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t begin = (at + kHugePage - 1) & ~(kHugePage - 1);
  if (begin > at) ::munmap(raw, begin - at);
  ::munmap(reinterpret_cast<void*>(begin + size), at + kHugePage - begin);  // begin - at < kHugePage
  advise_huge_pages(reinterpret_cast<void*>(begin), size);
  return reinterpret_cast<void*>(begin);
}
}  // namespace

unsigned char* MemorySlabs::allocate(std::size_t bytes) {
  bytes = (bytes + 7) & ~std::size_t(7);
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t unit = huge_ ? kHugePage : kPage;
  if (bytes > left_) {
    // A new slab; the rest of the last one is never touched, so never resident.
    const std::size_t size = std::max(kSlabBytes, (bytes + unit - 1) / unit * unit);
    void* p =
        huge_ ? map_huge(size) : ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    maps_.emplace_back(p, size);
    next_ = static_cast<unsigned char*>(p);
    populated_ = next_;
    left_ = size;
  }
  unsigned char* at = next_;
  next_ += bytes;
  left_ -= bytes;
  // Fault the pages about to be written in, kPopulateBytes (or a huge page) at a time:
  // one call instead of a page fault per page (this shortens binning, whose serial
  // stage copies the blocks).
  if (populate_ && next_ > populated_) {
    const std::size_t to_end = std::size_t(next_ + left_ - populated_);  // whole pages: so is a slab
    const std::size_t ahead = std::max(huge_ ? kHugePage : kPopulateBytes, std::size_t(next_ - populated_));
    const std::size_t n = std::min((ahead + unit - 1) / unit * unit, to_end);
    populate_pages(populated_, n);
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
