// Open-addressing hash map from packed cell keys to dense records.
#pragma once

#include <cstdint>
#include <algorithm>
#include <cstring>
#include <vector>

#include "grid/paged_array.hpp"

namespace oocsimp {

/// Maps 64-bit cell keys to records stored densely in insertion order, so records
/// can be walked (and merged) in a deterministic order. Linear probing over a
/// power-of-two slot table of 32-bit record indices; keys and records live in pages
/// (PagedArray), so growth never copies them and the overshoot is one page.
template <class Record>
class CellMap {
 public:
  explicit CellMap(std::size_t initial_slots = 1024) { rehash(initial_slots); }

  /// The index of `key`'s record, inserting a value-initialised one when absent.
  std::uint32_t insert(std::uint64_t key) {
    std::size_t s = slot_of(key);
    for (;;) {
      std::uint32_t e = slots_[s];
      if (e == 0) break;
      if (keys_[e - 1] == key) return e - 1;
      s = (s + 1) & mask_;
    }
    std::uint32_t idx = std::uint32_t(keys_.size());
    keys_.push_back(key);
    records_.emplace_back();
    slots_[s] = idx + 1;
    if (keys_.size() * 2 > slots_.size()) rehash(slots_.size() * 2);
    return idx;
  }
  /// The index of `key`'s record, or -1.
  std::int64_t find(std::uint64_t key) const {
    std::size_t s = slot_of(key);
    for (;;) {
      std::uint32_t e = slots_[s];
      if (e == 0) return -1;
      if (keys_[e - 1] == key) return e - 1;
      s = (s + 1) & mask_;
    }
  }
  std::size_t size() const { return keys_.size(); }
  std::uint64_t key(std::size_t i) const { return keys_[i]; }
  Record& record(std::size_t i) { return records_[i]; }
  const Record& record(std::size_t i) const { return records_[i]; }
  /// Empties the map but keeps its capacity.
  void clear() {
    if (keys_.size() * 8 < slots_.size()) {
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
    records_.clear();
  }
  /// Frees the hash index, keeping keys and records; only key(), record() and
  /// size() may be used afterwards.
  void release_index() { std::vector<std::uint32_t>().swap(slots_); }
  /// Heap bytes held.
  std::size_t bytes() const {
    return keys_.capacity() * sizeof(std::uint64_t) + records_.capacity() * sizeof(Record) +
           slots_.capacity() * sizeof(std::uint32_t);
  }

 private:
  std::size_t slot_of(std::uint64_t key) const { return std::size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  void rehash(std::size_t n) {
    std::size_t cap = 16;
    int bits = 4;
    while (cap < n) {
      cap *= 2;
      ++bits;
    }
    slots_.assign(cap, 0u);
    mask_ = cap - 1;
    shift_ = 64 - bits;
    for (std::size_t i = 0; i < keys_.size(); ++i) {
      std::size_t s = slot_of(keys_[i]);
      while (slots_[s] != 0) s = (s + 1) & mask_;
      slots_[s] = std::uint32_t(i + 1);
    }
  }

  PagedArray<std::uint64_t> keys_;
  PagedArray<Record> records_;
  std::vector<std::uint32_t> slots_;
  std::size_t mask_ = 0;
  int shift_ = 60;
};

}  // namespace oocsimp
