// The uniform cell grid shared by the clustering methods.
#pragma once

#include <cmath>
#include <cstdint>

#include "oocsimp/geometry.hpp"
#include "oocsimp/options.hpp"

namespace oocsimp {

/// A cubic grid anchored at `origin` with cells of side `cell` (model units).
/// Cell coordinates are packed into 21 bits per axis, so a grid is at most
/// 2^21 - 1 cells along each axis.
struct GridSpec {
  Vec3d origin;
  double cell = 1;
  std::uint32_t dims[3] = {1, 1, 1};

  static constexpr std::uint32_t kMaxDim = kMaxGridDivisions;

  /// Packed key of the cell holding p: x | y << 21 | z << 42. Points on the far
  /// boundary of the box go to the last cell.
  std::uint64_t key(const Vec3d& p) const { return key_relative(relative(p)); }
  /// p - origin: the coordinates every pass computes cells and quadrics in, so the
  /// same input value always lands in the same cell.
  Vec3d relative(const Vec3d& p) const { return {p.x - origin.x, p.y - origin.y, p.z - origin.z}; }
  /// key() for a point already made relative to the origin.
  std::uint64_t key_relative(const Vec3d& d) const {
    return axis(d.x, 0) | (axis(d.y, 1) << 21) | (axis(d.z, 2) << 42);
  }
  /// The lower corner of the cell with key k, relative to the origin.
  Vec3d cell_min_relative(std::uint64_t k) const {
    return {cell * double(k & kMaxDim), cell * double((k >> 21) & kMaxDim), cell * double((k >> 42) & kMaxDim)};
  }

  /// A grid over `bounds` with cells of side `cell`. Throws UsageError when the
  /// grid would exceed kMaxDim cells along an axis or `cell` is not positive.
  static GridSpec with_cell(const Box3d& bounds, double cell);
  /// A grid with `n` cells along the longest axis of `bounds`.
  static GridSpec with_divisions(const Box3d& bounds, std::uint32_t n);

 private:
  // floor(d / cell) clamped to the grid; truncation is the floor for q > 0 and
  // avoids std::floor's library call (no SSE4.1) in the per-vertex loop.
  std::uint64_t axis(double d, int a) const {
    double q = d / cell;
    if (!(q > 0)) return 0;  // also catches NaN
    if (q >= double(dims[a])) return dims[a] - 1;
    return std::uint64_t(q);
  }
};

}  // namespace oocsimp
