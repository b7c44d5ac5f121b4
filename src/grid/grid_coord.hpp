// Integer coordinates of cubes of a grid anchored at the origin, unbounded.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/mesh_input.hpp"

namespace oocsimp {

/// The cube [x*size, (x+1)*size) x ... of a grid anchored at the origin. Used where
/// the grid must not depend on the bounding box (floating cells, tiles).
struct GridCoord {
  std::int64_t x = 0, y = 0, z = 0;
  bool operator==(const GridCoord& o) const { return x == o.x && y == o.y && z == o.z; }
  bool operator!=(const GridCoord& o) const { return !(*this == o); }
  bool operator<(const GridCoord& o) const { return x != o.x ? x < o.x : y != o.y ? y < o.y : z < o.z; }

  /// floor(v / size) as an integer. Without SSE4.1 std::floor is a library call, and
  /// this runs several times per vertex and per lookup: truncate and step down for
  /// negative non-integers instead (the same value wherever it fits an int64).
  static std::int64_t axis(double v, double size) {
    double q = v / size;
    if (!(std::fabs(q) < 9.0e18)) return std::int64_t(std::floor(q));
    std::int64_t i = std::int64_t(q);
    return i - std::int64_t(double(i) > q);
  }
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
