// Sorting large arrays by an unsigned integer key in linear time: a tile of the
// collapse's passes sorts hundreds of thousands of corners and vertices by their input
// ids, where std::sort's compares and mispredicted branches took a few percent of a run.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/huge_pages.hpp"

namespace oocsimp {

/// Sorts `items` by key(item), an unsigned integer, ascending; items of equal keys keep
/// their order (stable). Least significant digit first, 11 bits a pass over the keys'
/// span (max - min), so that ids spread over 2^22 take two passes, through a second
/// array of the same size, freed on return. Small arrays go to std::stable_sort.
template <class T, class Key>
void radix_sort(std::vector<T>* items, Key key) {
  constexpr std::size_t kSmall = 2048;
  constexpr int kBits = 11;
  constexpr std::size_t kBuckets = std::size_t(1) << kBits;
  const std::size_t n = items->size();
  if (n < kSmall) {
    std::stable_sort(items->begin(), items->end(), [&](const T& a, const T& b) { return key(a) < key(b); });
    return;
  }
  std::uint64_t lo = key((*items)[0]), hi = lo;
  for (const T& x : *items) {
    const std::uint64_t k = key(x);
    lo = std::min(lo, k);
    hi = std::max(hi, k);
  }
  int bits = 0;
  for (std::uint64_t span = hi - lo; span != 0; span >>= 1) ++bits;
  if (bits == 0) return;  // one key: already in order
  std::vector<T> scratch;
  resize_filled(&scratch, n);
  std::vector<std::size_t> start(kBuckets);
  for (int shift = 0; shift < bits; shift += kBits) {
    const auto digit = [&](const T& x) { return std::size_t(((key(x) - lo) >> shift) & (kBuckets - 1)); };
    std::fill(start.begin(), start.end(), std::size_t(0));
    for (const T& x : *items) ++start[digit(x)];
    std::size_t at = 0;
    for (std::size_t& s : start) at += std::exchange(s, at);
    T* out = scratch.data();
    for (const T& x : *items) out[start[digit(x)]++] = x;
    items->swap(scratch);
  }
}

}  // namespace oocsimp
