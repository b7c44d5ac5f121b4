// oocsimp — the plain geometry types of the public API: a point and a box.
#pragma once

#include "oocsimp/export.hpp"

#include <cmath>

namespace oocsimp {

/// A point or vector in model units.
struct Vec3d {
  double x = 0, y = 0, z = 0;
};

/// Whether all three coordinates are finite. Vertices that are not are kept in the
/// position array (so indices stay valid) but take no part in anything: the bounding
/// box, the grid and the vertex passes skip them, and the triangle stream drops the
/// triangles that use them.
inline bool is_finite(const Vec3d& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

/// Axis-aligned bounding box; empty when min > max.
struct OOCSIMP_API Box3d {
  Vec3d min{1e300, 1e300, 1e300};
  Vec3d max{-1e300, -1e300, -1e300};
  bool empty() const { return min.x > max.x; }
  /// Length of the diagonal; 0 when empty.
  double diagonal() const;
  void add(const Vec3d& p);
  void add(const Box3d& b);
};

}  // namespace oocsimp
