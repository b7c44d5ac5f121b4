// A vector for arrays every element of which is written before it is read.
#pragma once

#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace oocsimp {

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
