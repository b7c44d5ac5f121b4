// The set of surviving output triangles, kept in first-insertion order.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace oocsimp {

/// Stores triangles over cell indices, each unordered triple once: the first
/// insertion fixes the orientation, later ones (in any orientation) are ignored.
class TriangleSet {
 public:
  TriangleSet() { rehash(1 << 12); }

  /// Adds (a, b, c) unless a triangle with the same three cells exists; returns
  /// whether it was added.
  bool insert(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    std::uint32_t s[3] = {a, b, c};
    std::sort(s, s + 3);
    std::size_t slot = slot_of(s);
    for (;;) {
      std::uint32_t e = slots_[slot];
      if (e == 0) break;
      const std::uint32_t* t = &tris_[3 * (e - 1)];
      std::uint32_t u[3] = {t[0], t[1], t[2]};
      std::sort(u, u + 3);
      if (u[0] == s[0] && u[1] == s[1] && u[2] == s[2]) return false;
      slot = (slot + 1) & mask_;
    }
    slots_[slot] = std::uint32_t(tris_.size() / 3 + 1);
    tris_.insert(tris_.end(), {a, b, c});
    if (tris_.size() / 3 * 2 > slots_.size()) rehash(slots_.size() * 2);
    return true;
  }
  /// 3 cell indices per triangle, in insertion order.
  const std::vector<std::uint32_t>& triangles() const { return tris_; }

 private:
  std::size_t slot_of(const std::uint32_t* s) const {
    std::uint64_t h = (std::uint64_t(s[0]) * 0x9E3779B97F4A7C15ull) ^ (std::uint64_t(s[1]) * 0xC2B2AE3D27D4EB4Full) ^
                      (std::uint64_t(s[2]) * 0x165667B19E3779F9ull);
    h ^= h >> 29;
    return std::size_t(h & mask_);
  }
  void rehash(std::size_t n) {
    slots_.assign(n, 0u);
    mask_ = n - 1;
    for (std::size_t i = 0; i < tris_.size() / 3; ++i) {
      std::uint32_t s[3] = {tris_[3 * i], tris_[3 * i + 1], tris_[3 * i + 2]};
      std::sort(s, s + 3);
      std::size_t slot = slot_of(s);
      while (slots_[slot] != 0) slot = (slot + 1) & mask_;
      slots_[slot] = std::uint32_t(i + 1);
    }
  }

  std::vector<std::uint32_t> tris_;
  std::vector<std::uint32_t> slots_;
  std::size_t mask_ = 0;
};

}  // namespace oocsimp
