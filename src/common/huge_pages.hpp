// Large arrays backed by transparent huge pages where the system grants them on
// request (madvise mode): the first touch of each fresh 4 KiB page is a fault, slow
// enough in virtual machines that an array of tens of MiB spends tens of
// milliseconds in them, all in one thread; huge pages take 512 times fewer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace oocsimp {

/// Asks for huge pages over the whole 2 MiB pages inside [data, data + bytes); a hint
/// only, for memory not yet touched.
inline void advise_huge_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const std::uintptr_t huge = std::uintptr_t(2) << 20;
  const auto at = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = (at + huge - 1) & ~(huge - 1), end = (at + bytes) & ~(huge - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// Faults the pages of [data, data + bytes) in by one call, for memory about to be
/// written whole: a fault per 4 KiB page cost about twice as much in a virtual machine
/// (docs/benchmarks.md, "Fresh memory"). A hint: where the kernel has no
/// MADV_POPULATE_WRITE (before Linux 5.14) the pages fault in as written.
inline void populate_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  const std::uintptr_t page = 4096;
  const auto at = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = at & ~(page - 1), end = at + bytes;
  if (bytes > 0) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// Reserves room for `count` elements in an empty vector, over huge pages; a vector
/// that holds elements or room enough already is left as it is.
template <class T, class Allocator>
void reserve_huge(std::vector<T, Allocator>* v, std::size_t count) {
  if (!v->empty() || v->capacity() >= count) return;
  std::vector<T, Allocator>().swap(*v);
  v->reserve(count);
  advise_huge_pages(v->data(), count * sizeof(T));
}

/// reserve_huge() for a vector about to hold all `count` elements at once (a resize
/// or a copy follows): its pages are also faulted in, by one call (populate_pages).
/// Only for a room that is filled whole: the pages count as resident at once.
template <class T, class Allocator>
void reserve_filled(std::vector<T, Allocator>* v, std::size_t count) {
  if (!v->empty() || v->capacity() >= count) return;
  reserve_huge(v, count);
  populate_pages(v->data(), count * sizeof(T));
}

/// An empty vector resized to `count` elements, its room faulted in first
/// (reserve_filled).
template <class T, class Allocator>
void resize_filled(std::vector<T, Allocator>* v, std::size_t count) {
  reserve_filled(v, count);
  v->resize(count);
}

}  // namespace oocsimp
