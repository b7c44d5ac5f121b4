// Integer coordinates of cubes of a grid anchored at the origin, unbounded.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "oocsimp/mesh_input.hpp"

namespace oocsimp {

/// The cube [x*size, (x+1)*size) x ... of a grid anchored at the origin. Used where
/// the grid must not depend on the bounding box (floating cells, tiles).
struct GridCoord {
  std::int64_t x = 0, y = 0, z = 0;
  bool operator==(const GridCoord& o) const { return x == o.x && y == o.y && z == o.z; }
  bool operator!=(const GridCoord& o) const { return !(*this == o); }
  bool operator<(const GridCoord& o) const { return x != o.x ? x < o.x : y != o.y ? y < o.y : z < o.z; }

  static std::int64_t axis(double v, double size) { return std::int64_t(std::floor(v / size)); }
  static GridCoord of(const Vec3d& p, double size) { return {axis(p.x, size), axis(p.y, size), axis(p.z, size)}; }
};

struct GridCoordHash {
  std::size_t operator()(const GridCoord& k) const {
    std::uint64_t h = std::uint64_t(k.x) * 0x9E3779B97F4A7C15ull ^ std::uint64_t(k.y) * 0xC2B2AE3D27D4EB4Full ^
                      std::uint64_t(k.z) * 0x165667B19E3779F9ull;
    return std::size_t(h ^ (h >> 31));
  }
};

}  // namespace oocsimp

namespace oocsimp {

/// A set of grid cubes (open addressing, linear probing, no allocation per lookup).
class GridCoordSet {
 public:
  GridCoordSet() { slots_.assign(64, Slot{}); }
  bool contains(const GridCoord& c) const {
    for (std::size_t s = GridCoordHash()(c) & (slots_.size() - 1);; s = (s + 1) & (slots_.size() - 1)) {
      if (!slots_[s].used) return false;
      if (slots_[s].cell == c) return true;
    }
  }
  void insert(const GridCoord& c) {
    if (2 * (count_ + 1) > slots_.size()) grow();
    std::size_t s = GridCoordHash()(c) & (slots_.size() - 1);
    while (slots_[s].used && !(slots_[s].cell == c)) s = (s + 1) & (slots_.size() - 1);
    if (!slots_[s].used) {
      slots_[s] = {c, true};
      ++count_;
    }
  }
  /// Inserts c and its 26 neighbours.
  void insert_block(const GridCoord& c) {
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) insert({c.x + dx, c.y + dy, c.z + dz});
  }
  bool empty() const { return count_ == 0; }

 private:
  struct Slot {
    GridCoord cell;
    bool used = false;
  };
  void grow() {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(2 * old.size(), Slot{});
    count_ = 0;
    for (const Slot& s : old)
      if (s.used) insert(s.cell);
  }
  std::vector<Slot> slots_;
  std::size_t count_ = 0;
};

}  // namespace oocsimp
