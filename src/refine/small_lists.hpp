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

// A list of up to this many vertices (a ring around a vertex: a dozen or so) is made
// distinct in a small table on the stack (SmallVertexSet); a longer one (a hub's
// hundreds or thousands) is sorted (keep_distinct, fan_shape).
constexpr std::size_t kScannedList = 32;

// A set of up to kScannedList vertex indices, open-addressed in a table on the stack:
// a dozen or so lookups where a scan of the list for each value costs a hundred
// compares. Insertion order is kept by the caller's list, not here.
class SmallVertexSet {
 public:
  SmallVertexSet() { std::fill(slot_, slot_ + kSlots, kEmpty); }
  /// Adds u; false when it was there already.
  bool insert(std::uint32_t u) {
    std::uint32_t h = home(u);
    while (slot_[h] != kEmpty) {
      if (slot_[h] == u) return false;
      h = (h + 1) & (kSlots - 1);
    }
    slot_[h] = u;
    return true;
  }
  bool contains(std::uint32_t u) const {
    for (std::uint32_t h = home(u); slot_[h] != kEmpty; h = (h + 1) & (kSlots - 1))
      if (slot_[h] == u) return true;
    return false;
  }

 private:
  // Twice kScannedList's slots keep the table at most half full, so probes are short.
  static constexpr std::uint32_t kSlots = 64;
  static constexpr std::uint32_t kEmpty = ~std::uint32_t(0);
  // Fibonacci hashing: neighbouring indices spread over the table.
  static std::uint32_t home(std::uint32_t u) { return (u * 0x9E3779B1u) >> 26; }
  static_assert(2 * kScannedList <= kSlots, "the table holds a short list at most half full");

  std::uint32_t slot_[kSlots];
};

// Numbers the distinct vertices of a short list 0, 1, 2, ... in order of first
// appearance, in an open-addressed table on the stack (as SmallVertexSet).
class SmallVertexSlots {
 public:
  SmallVertexSlots() { std::fill(key_, key_ + kSlots, kEmpty); }
  /// u's number; a vertex not seen yet gets the next one.
  std::uint32_t slot(std::uint32_t u) {
    std::uint32_t h = (u * 0x9E3779B1u) >> 26;
    while (key_[h] != kEmpty) {
      if (key_[h] == u) return value_[h];
      h = (h + 1) & (kSlots - 1);
    }
    key_[h] = u;
    value_[h] = size_;
    return size_++;
  }
  /// The distinct vertices numbered so far.
  std::uint32_t size() const { return size_; }

 private:
  static constexpr std::uint32_t kSlots = 64;
  static constexpr std::uint32_t kEmpty = ~std::uint32_t(0);
  static_assert(2 * kScannedList <= kSlots, "the table holds a short list at most half full");

  std::uint32_t key_[kSlots];
  std::uint32_t value_[kSlots];
  std::uint32_t size_ = 0;
};

// Drops repeats from a list, keeping each value's first place; a long one (more than
// kScannedList values: a hub's hundreds) is sorted instead. Returns whether it was
// sorted.
inline bool keep_distinct(std::vector<std::uint32_t>* list) {
  if (list->size() > kScannedList) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
    return true;
  }
  SmallVertexSet seen;
  std::uint32_t* x = list->data();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < list->size(); ++i)
    if (seen.insert(x[i])) x[kept++] = x[i];
  list->resize(kept);
  return false;
}

}  // namespace oocsimp
