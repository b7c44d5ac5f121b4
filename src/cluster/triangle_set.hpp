// The set of surviving output triangles, kept in first-insertion order.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>

#include "common/flat_hash_map.hpp"

namespace oocsimp {

/// Stores triangles over cell indices (< 2^31), each unordered triple once: the first
/// insertion fixes the orientation, later ones (in any orientation) are ignored.
/// A triangle is kept as its sorted triple plus one bit for the orientation (whether
/// the inserted order was an odd permutation of the sorted one): 12 bytes.
class TriangleSet {
 public:
  /// Adds (a, b, c) unless a triangle with the same three cells exists; returns
  /// whether it was added.
  bool insert(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if ((a | b | c) & kOddBit) throw std::length_error("more than 2^31 cells");
    Key k = sorted(a, b, c);
    // (a, b, c) is an even permutation of the sorted triple iff it is one of its rotations.
    bool even = (a == k[0] && b == k[1]) || (a == k[1] && b == k[2]) || (a == k[2] && b == k[0]);
    if (!even) k[0] |= kOddBit;
    return set_.try_insert(k).second;
  }
  /// FlatHashMap::prefetch for the triangle (a, b, c), ahead of its insert().
  void prefetch(std::uint32_t a, std::uint32_t b, std::uint32_t c) const { set_.prefetch(sorted(a, b, c)); }
  std::size_t size() const { return set_.size(); }
  /// Triangle i (cell indices) in the orientation of its first insertion.
  std::array<std::uint32_t, 3> operator[](std::size_t i) const {
    const Key& k = set_.key(i);
    if (k[0] & kOddBit) return {k[0] & ~kOddBit, k[2], k[1]};
    return k;
  }
  /// Heap bytes held, and at most while `more` triangles are added (FlatHashMap).
  std::size_t bytes() const { return set_.bytes(); }
  std::size_t bytes_with(std::size_t more) const { return set_.bytes_with(more); }
  /// Grows the index now for `triangles` in all (FlatHashMap::reserve_index).
  void reserve_index(std::size_t triangles) { set_.reserve_index(triangles); }
  /// Frees the hash index; insert() must not be called afterwards.
  void release_index() { set_.release_index(); }

 private:
  using Key = std::array<std::uint32_t, 3>;  // sorted triple, kOddBit set in [0] for odd orientation
  static constexpr std::uint32_t kOddBit = 0x80000000u;

  static Key sorted(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    Key k = {a, b, c};
    std::sort(k.begin(), k.end());
    return k;
  }

  // Hash and equality of the three cells, whatever the orientation bit.
  struct SameCellsHash {
    std::uint64_t operator()(const Key& k) const {
      return (std::uint64_t(k[0] & ~kOddBit) * 0x9E3779B97F4A7C15ull) ^ (std::uint64_t(k[1]) * 0xC2B2AE3D27D4EB4Full) ^
             (std::uint64_t(k[2]) * 0x165667B19E3779F9ull);
    }
  };
  struct SameCells {
    bool operator()(const Key& x, const Key& y) const {
      return ((x[0] ^ y[0]) & ~kOddBit) == 0 && x[1] == y[1] && x[2] == y[2];
    }
  };

  FlatHashSet<Key, SameCellsHash, SameCells> set_{1 << 12};
};

}  // namespace oocsimp
