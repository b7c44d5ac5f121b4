// Short lists of vertex or face indices, as the collapse gathers them around a vertex:
// a dozen or so entries, where plain scans beat sorts and binary searches, whose
// branches the processor cannot predict; a hub's long list is sorted instead.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace oocsimp {

// The lists around a vertex hold a dozen or so entries: insertion sort beats
// std::sort's setup there; long lists (a high-valence vertex) take std::sort.
template <class T>
void sort_small(std::vector<T>* v) {
  T* a = v->data();
  const std::size_t n = v->size();
  if (n > 32) {
    std::sort(a, a + n);
    return;
  }
  for (std::size_t i = 1; i < n; ++i) {
    const T x = a[i];
    std::size_t j = i;
    for (; j > 0 && a[j - 1] > x; --j) a[j] = a[j - 1];
    a[j] = x;
  }
}

// A list of up to this many vertices (a ring around a vertex: a dozen or so) is
// scanned, without early exit, where a sort or a binary search would mispredict; a
// longer one (a hub's hundreds or thousands) is sorted (keep_distinct, fan_shape).
constexpr std::size_t kScannedList = 32;

// Drops repeats from a short list, keeping each value's first place, by scans without
// early exit (a dozen or so values: no branch to mispredict); a long one (a hub's
// hundreds) is sorted instead. Returns whether it was sorted.
inline bool keep_distinct(std::vector<std::uint32_t>* list) {
  if (list->size() > kScannedList) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
    return true;
  }
  std::uint32_t* x = list->data();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < list->size(); ++i) {
    bool seen = false;
    for (std::size_t j = 0; j < kept; ++j) seen |= x[j] == x[i];
    x[kept] = x[i];
    kept += !seen;
  }
  list->resize(kept);
  return false;
}

}  // namespace oocsimp
