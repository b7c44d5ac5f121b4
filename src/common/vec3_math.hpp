// Component-wise arithmetic on Vec3d for the library's internals (the public Vec3d in
// include/oocsimp/mesh_input.hpp stays plain data).
//
// Each operation is the standard expression, written out once with a fixed order of
// operations: rewriting `a.y * b.z - a.z * b.y` as cross(a, b) gives the same bits, so
// code whose results reach the output may use these freely. The operations are
// exactly what they say: v / s divides each coordinate by s (it does not multiply by
// 1 / s), dot() sums x, y, z left to right.
#pragma once

#include <algorithm>
#include <cmath>

#include "oocsimp/geometry.hpp"

namespace oocsimp {

inline Vec3d operator+(const Vec3d& a, const Vec3d& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3d operator-(const Vec3d& a, const Vec3d& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3d operator-(const Vec3d& a) { return {-a.x, -a.y, -a.z}; }
inline Vec3d operator*(const Vec3d& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3d operator*(double s, const Vec3d& a) { return {s * a.x, s * a.y, s * a.z}; }
inline Vec3d operator/(const Vec3d& a, double s) { return {a.x / s, a.y / s, a.z / s}; }
inline Vec3d& operator+=(Vec3d& a, const Vec3d& b) {
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
inline Vec3d& operator-=(Vec3d& a, const Vec3d& b) {
  a.x -= b.x;
  a.y -= b.y;
  a.z -= b.z;
  return a;
}

inline double dot(const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double squared_length(const Vec3d& a) { return dot(a, a); }
inline double length(const Vec3d& a) { return std::sqrt(squared_length(a)); }
inline double squared_distance(const Vec3d& a, const Vec3d& b) { return squared_length(a - b); }
inline double distance(const Vec3d& a, const Vec3d& b) { return length(a - b); }
/// Exact equality of the coordinates.
inline bool same_point(const Vec3d& a, const Vec3d& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/// Per coordinate std::min(a, b) / std::max(a, b) (so a NaN in b is ignored, one in a kept).
inline Vec3d min(const Vec3d& a, const Vec3d& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
inline Vec3d max(const Vec3d& a, const Vec3d& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}

}  // namespace oocsimp
