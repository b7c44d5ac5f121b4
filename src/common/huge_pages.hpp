// Large arrays backed by transparent huge pages where the system grants them on
// request (madvise mode): the first touch of each fresh 4 KiB page is a fault, slow
// enough in virtual machines that an array of tens of MiB spends tens of
// milliseconds in them, all in one thread; huge pages take 512 times fewer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
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

/// An allocator whose resize() leaves plain elements uninitialised (default-
/// initialised): for arrays every element of which is written before it is read,
/// where clearing them first would cost a pass over memory, on one thread.
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept(noexcept(U())) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/// A vector whose resize() leaves plain elements uninitialised.
template <class T>
using UninitialisedVector = std::vector<T, UninitialisedAllocator<T>>;

}  // namespace oocsimp
