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

/// Reserves room for `count` elements in an empty vector, over huge pages; a vector
/// that holds elements or room enough already is left as it is.
template <class T, class Allocator>
void reserve_huge(std::vector<T, Allocator>* v, std::size_t count) {
  if (!v->empty() || v->capacity() >= count) return;
  std::vector<T, Allocator>().swap(*v);
  v->reserve(count);
  advise_huge_pages(v->data(), count * sizeof(T));
}

}  // namespace oocsimp
