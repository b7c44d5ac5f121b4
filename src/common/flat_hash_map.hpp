// The library's hash table: open addressing with linear probing, entries numbered and
// stored densely in insertion order.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/huge_pages.hpp"
#include "common/paged_array.hpp"

namespace oocsimp {

/// The Value of a FlatHashMap used as a set: nothing is stored per entry.
struct NoValue {};

/// Maps keys to values, numbering the keys 0, 1, 2, ... in order of first insertion.
/// Entries are stored densely in that order (key(i), value(i)), so walking them is
/// deterministic whatever the hash, and the numbers can serve as output indices.
///
/// Layout: a power-of-two table of 32-bit slots, each 0 (empty) or an entry number + 1,
/// probed linearly and kept at most half full; keys and values live in pages
/// (PagedArray), so growing never copies them and references to them stay valid.
/// Entries cannot be erased, only all cleared. Hash need not mix its bits: the table
/// multiplies its value by 2^64 / phi and takes the top bits (Fibonacci hashing,
/// Knuth, TAOCP vol. 3 §6.4). Equal must agree with Hash. With Value = NoValue the
/// map is a set and stores no values.
template <class Key, class Value = NoValue, class Hash = std::hash<Key>, class Equal = std::equal_to<Key>>
class FlatHashMap {
 public:
  static constexpr bool kStoresValues = !std::is_same<Value, NoValue>::value;

  /// Starts with at least `initial_slots` slots (so about half as many keys fit
  /// before the table grows).
  explicit FlatHashMap(std::size_t initial_slots = 16) { rehash(initial_slots); }

  /// The number of `key`, and whether it was inserted now (with a value-initialised value).
  std::pair<std::uint32_t, bool> try_insert(const Key& key) {
    std::size_t s = slot_of(key);
    for (;;) {
      std::uint32_t e = slots_[s];
      if (e == 0) break;
      if (equal_(keys_[e - 1], key)) return {e - 1, false};
      s = (s + 1) & mask_;
    }
    if (keys_.size() >= kMaxEntries) throw std::length_error("hash table: more than 2^32 - 2 entries");
    std::uint32_t number = std::uint32_t(keys_.size());
    keys_.push_back(key);
    if constexpr (kStoresValues) values_.emplace_back();
    slots_[s] = number + 1;
    if (keys_.size() * 2 > slots_.size()) rehash(slots_.size() * 2);
    return {number, true};
  }
  /// The number of `key`, inserting it when absent.
  std::uint32_t insert(const Key& key) { return try_insert(key).first; }
  /// Asks the processor to fetch `key`'s first slot ahead of a lookup, so that a loop
  /// over many keys waits on several cache misses at once rather than one at a time.
  void prefetch(const Key& key) const { __builtin_prefetch(&slots_[slot_of(key)]); }
  /// Grows the index now for `keys` entries in all, so that inserting up to that many
  /// rehashes no more (the numbering does not depend on the index's size).
  void reserve_index(std::size_t keys) {
    if (keys * 2 > slots_.size()) rehash(keys * 2);
  }
  /// The number of `key`, or -1 when absent.
  std::int64_t find(const Key& key) const {
    std::size_t s = slot_of(key);
    for (;;) {
      std::uint32_t e = slots_[s];
      if (e == 0) return -1;
      if (equal_(keys_[e - 1], key)) return e - 1;
      s = (s + 1) & mask_;
    }
  }

  std::size_t size() const { return keys_.size(); }
  /// Entry i's key (i < size()).
  const Key& key(std::size_t i) const { return keys_[i]; }
  /// Entry i's value (i < size()).
  Value& value(std::size_t i) {
    static_assert(kStoresValues, "a set stores no values");
    return values_[i];
  }
  const Value& value(std::size_t i) const {
    static_assert(kStoresValues, "a set stores no values");
    return values_[i];
  }

  /// Empties the map but keeps its capacity.
  void clear() {
    if (keys_.size() * 8 < slots_.size()) {
      // Few entries: clear their probe runs rather than the whole table.
      for (std::size_t i = 0; i < keys_.size(); ++i) {
        std::size_t s = slot_of(keys_[i]);
        while (slots_[s] != 0) {
          slots_[s] = 0;
          s = (s + 1) & mask_;
        }
      }
    } else {
      std::fill(slots_.begin(), slots_.end(), 0u);
    }
    keys_.clear();
    values_.clear();
  }
  /// Frees the hash index, keeping the entries: only size(), key() and value() may
  /// be used afterwards.
  void release_index() { std::vector<std::uint32_t>().swap(slots_); }
  /// Heap bytes held.
  std::size_t bytes() const {
    return keys_.capacity() * sizeof(Key) + (kStoresValues ? values_.capacity() * sizeof(Value) : 0) +
           slots_.capacity() * sizeof(std::uint32_t);
  }

  /// Heap bytes held at most while `more` new keys are inserted: their pages, and
  /// the old and the new slot table side by side during the last rehash.
  std::size_t bytes_with(std::size_t more) const {
    const std::size_t n = keys_.size() + more;
    const std::size_t pages = (n + decltype(keys_)::kPage - 1) / decltype(keys_)::kPage * decltype(keys_)::kPage;
    std::size_t slots = slots_.size(), peak = slots;
    while (n * 2 > slots) {
      peak = 3 * slots;  // rehash(): the old table is freed after the new one is filled
      slots *= 2;
    }
    return std::max(keys_.capacity(), pages) * sizeof(Key) +
           (kStoresValues ? std::max(values_.capacity(), pages) * sizeof(Value) : 0) +
           std::max(peak, slots) * sizeof(std::uint32_t);
  }

 private:
  static constexpr std::size_t kMaxEntries = 0xFFFFFFFEu;  // slot 0xFFFFFFFF would be number + 1 overflowing

  std::size_t slot_of(const Key& key) const {
    return std::size_t((std::uint64_t(hash_(key)) * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void rehash(std::size_t n) {
    std::size_t cap = 16;
    int bits = 4;
    while (cap < n) {
      cap *= 2;
      ++bits;
    }
    // The index is rebuilt from the entries, so the old one goes first; a large new one
    // sits on huge pages, whose first touch faults 512 times less often.
    std::vector<std::uint32_t>().swap(slots_);
    reserve_huge(&slots_, cap);
    slots_.assign(cap, 0u);
    mask_ = cap - 1;
    shift_ = 64 - bits;
    for (std::size_t i = 0; i < keys_.size(); ++i) {
      std::size_t s = slot_of(keys_[i]);
      while (slots_[s] != 0) s = (s + 1) & mask_;
      slots_[s] = std::uint32_t(i + 1);
    }
  }

  PagedArray<Key> keys_;
  PagedArray<Value> values_;  // empty for a set
  std::vector<std::uint32_t> slots_;
  std::size_t mask_ = 0;
  int shift_ = 60;
  Hash hash_;
  Equal equal_;
};

/// A set of keys numbered in insertion order.
template <class Key, class Hash = std::hash<Key>, class Equal = std::equal_to<Key>>
using FlatHashSet = FlatHashMap<Key, NoValue, Hash, Equal>;

}  // namespace oocsimp
