// The set of surviving output triangles, kept in first-insertion order.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "grid/paged_array.hpp"

namespace oocsimp {

/// Stores triangles over cell indices (< 2^31), each unordered triple once: the first
/// insertion fixes the orientation, later ones (in any orientation) are ignored.
/// A triangle is kept as its sorted triple plus one bit for the orientation (whether
/// the inserted order was an odd permutation of the sorted one): 12 bytes.
class TriangleSet {
 public:
  TriangleSet() { rehash(1 << 12); }

  /// Adds (a, b, c) unless a triangle with the same three cells exists; returns
  /// whether it was added.
  bool insert(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if ((a | b | c) & kOddBit) throw std::length_error("more than 2^31 cells");
    Key k = {a, b, c};
    std::sort(k.begin(), k.end());
    // (a, b, c) is an even permutation of the sorted triple iff it is one of its rotations.
    bool even = (a == k[0] && b == k[1]) || (a == k[1] && b == k[2]) || (a == k[2] && b == k[0]);
    std::size_t slot = slot_of(k);
    for (;;) {
      std::uint32_t e = slots_[slot];
      if (e == 0) break;
      const Key& o = keys_[e - 1];
      if ((o[0] & ~kOddBit) == k[0] && o[1] == k[1] && o[2] == k[2]) return false;
      slot = (slot + 1) & mask_;
    }
    slots_[slot] = std::uint32_t(keys_.size() + 1);
    if (!even) k[0] |= kOddBit;
    keys_.push_back(k);
    if (keys_.size() * 2 > slots_.size()) rehash(slots_.size() * 2);
    return true;
  }
  std::size_t size() const { return keys_.size(); }
  /// Triangle i (cell indices) in the orientation of its first insertion.
  std::array<std::uint32_t, 3> operator[](std::size_t i) const {
    const Key& k = keys_[i];
    if (k[0] & kOddBit) return {k[0] & ~kOddBit, k[2], k[1]};
    return k;
  }
  /// Frees the hash index; insert() must not be called afterwards.
  void release_index() { std::vector<std::uint32_t>().swap(slots_); }

 private:
  using Key = std::array<std::uint32_t, 3>;
  static constexpr std::uint32_t kOddBit = 0x80000000u;

  std::size_t slot_of(const Key& s) const {
    std::uint64_t h = ((s[0] & ~kOddBit) * 0x9E3779B97F4A7C15ull) ^ (std::uint64_t(s[1]) * 0xC2B2AE3D27D4EB4Full) ^
                      (std::uint64_t(s[2]) * 0x165667B19E3779F9ull);
    h ^= h >> 29;
    return std::size_t(h & mask_);
  }
  void rehash(std::size_t n) {
    slots_.assign(n, 0u);
    mask_ = n - 1;
    for (std::size_t i = 0; i < keys_.size(); ++i) {
      std::size_t slot = slot_of(keys_[i]);
      while (slots_[slot] != 0) slot = (slot + 1) & mask_;
      slots_[slot] = std::uint32_t(i + 1);
    }
  }

  PagedArray<Key> keys_;  // sorted triple, kOddBit set in [0] for odd orientation
  std::vector<std::uint32_t> slots_;
  std::size_t mask_ = 0;
};

}  // namespace oocsimp
