// Sorting large arrays by an unsigned integer key in linear time: a tile of the
// collapse's passes sorts hundreds of thousands of corners and vertices by their input
// ids, and each pass its edges by cost, where std::sort's compares and mispredicted
// branches took a few percent of a run.
#pragma once

#include <tbb/parallel_for.h>

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

namespace radix_detail {

// One level of msd_radix_sort: [first, last) by the 8 bits below the highest bit in
// which its keys differ (key's, or tie's where all of key's are equal), then each
// bucket alike. Buckets are sorted in parallel when `parallel`.
template <class T, class Key, class TieKey, class Less>
void msd_level(T* first, T* last, const Key& key, const TieKey& tie, const Less& less, bool on_tie, bool parallel) {
  constexpr std::ptrdiff_t kSmall = 256;
  if (last - first < kSmall) {
    std::sort(first, last, less);
    return;
  }
  const auto key_of = [&](const T& x) -> std::uint64_t { return on_tie ? tie(x) : key(x); };
  std::uint64_t lo = key_of(*first), hi = lo;
  for (const T* p = first; p != last; ++p) {
    const std::uint64_t k = key_of(*p);
    lo = std::min(lo, k);
    hi = std::max(hi, k);
  }
  if (lo == hi) {
    if (on_tie)
      std::sort(first, last, less);  // equal by both keys: `less` says
    else
      msd_level(first, last, key, tie, less, true, parallel);
    return;
  }
  int bits = 0;
  for (std::uint64_t span = hi - lo; span != 0; span >>= 1) ++bits;
  const int shift = std::max(bits - 8, 0);
  const auto digit = [&](const T& x) { return std::size_t((key_of(x) - lo) >> shift); };
  std::size_t start[257] = {}, next[256];
  for (const T* p = first; p != last; ++p) ++start[digit(*p) + 1];
  for (std::size_t d = 0; d < 256; ++d) start[d + 1] += start[d];
  std::copy(start, start + 256, next);
  // Each item swapped straight into its bucket's next free place (the cycles of the
  // permutation), so no second array is needed.
  for (std::size_t d = 0; d < 256; ++d)
    while (next[d] < start[d + 1]) {
      T x = first[next[d]];
      for (std::size_t e = digit(x); e != d; e = digit(x)) std::swap(x, first[next[e]++]);
      first[next[d]++] = x;
    }
  const auto bucket = [&](std::size_t d) {
    if (start[d + 1] - start[d] > 1) msd_level(first + start[d], first + start[d + 1], key, tie, less, on_tie, false);
  };
  if (parallel)
    tbb::parallel_for(std::size_t(0), std::size_t(256), bucket);
  else
    for (std::size_t d = 0; d < 256; ++d) bucket(d);
}

}  // namespace radix_detail

/// Sorts [first, last) by `less`, a strict weak order, given two unsigned integer keys
/// that follow it: key(x) < key(y) implies less(x, y), and where the keys are equal,
/// tie(x) < tie(y) implies less(x, y). Most significant digit first, 8 bits a level
/// below the highest bit in which a range's keys differ, in place (the American flag
/// sort of McIlroy, Bostic & McIlroy 1993, "Engineering radix sort"), so that it needs
/// no second array; ranges of a few hundred, and items equal by both keys, are sorted
/// by std::sort with `less`. The result is std::sort's for a strict total order. The
/// buckets below the first level are sorted on TBB's threads.
template <class T, class Key, class TieKey, class Less>
void msd_radix_sort(T* first, T* last, Key key, TieKey tie, Less less) {
  radix_detail::msd_level(first, last, key, tie, less, false, true);
}

}  // namespace oocsimp
