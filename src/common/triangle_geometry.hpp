// Point, box and triangle geometry: the surface distance (metrics/) and the curvature
// estimator (curvature/) read these.
//
// Everything is inline and allocation-free: these run once per (sample, triangle)
// pair in the hot loops of surface_distance.cpp.
#pragma once

#include <algorithm>
#include <cmath>

#include "common/vec3_math.hpp"
#include "oocsimp/geometry.hpp"

namespace oocsimp {
namespace metrics {

/// Area of triangle (a, b, c); exactly 0 for a degenerate one, which is then not part
/// of the measured surface (it gets no samples and is never a closest triangle).
inline double triangle_area(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  return 0.5 * length(cross(b - a, c - a));
}

/// Box3d::add for hot loops, where the out-of-line call shows.
inline void expand(Box3d& box, const Vec3d& p) {
  box.min = min(box.min, p);
  box.max = max(box.max, p);
}

inline Box3d triangle_box(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Box3d box;
  box.min = min(a, min(b, c));
  box.max = max(a, max(b, c));
  return box;
}

/// Squared distance from p to the box (0 inside). Monotone in every coordinate of
/// the box under rounding, so a box that holds a point is never farther than it.
__attribute__((always_inline)) inline double point_box_distance2(const Vec3d& p, const Box3d& box) {
  double dx = std::max(std::max(box.min.x - p.x, p.x - box.max.x), 0.0);
  double dy = std::max(std::max(box.min.y - p.y, p.y - box.max.y), 0.0);
  double dz = std::max(std::max(box.min.z - p.z, p.z - box.max.z), 0.0);
  return dx * dx + dy * dy + dz * dz;
}

/// Squared distance between two boxes (0 when they overlap). Never more than
/// point_box_distance2(p, a) for a point p inside b, as computed.
inline double box_box_distance2(const Box3d& a, const Box3d& b) {
  double dx = std::max(std::max(a.min.x - b.max.x, b.min.x - a.max.x), 0.0);
  double dy = std::max(std::max(a.min.y - b.max.y, b.min.y - a.max.y), 0.0);
  double dz = std::max(std::max(a.min.z - b.max.z, b.min.z - a.max.z), 0.0);
  return dx * dx + dy * dy + dz * dz;
}

/// The point of triangle (a, b, c) closest to p: Ericson, Real-Time Collision
/// Detection (2005), section 5.1.5 — find the Voronoi region of p (vertex, edge or
/// face) from the signs of barycentric sub-determinants and project onto it.
inline Vec3d closest_point_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Vec3d ab = b - a, ac = c - a, ap = p - a;
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  Vec3d bp = p - b;
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  Vec3d cp = p - c;
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  double sum = va + vb + vc;
  // Only a sliver whose sub-determinants all round to 0 gets here with sum == 0;
  // its closest point is then (to rounding) its first corner.
  if (!(sum > 0)) return a;
  return a + vb / sum * ab + vc / sum * ac;
}

/// Squared distance from p to triangle (a, b, c) whose box is `box`. It is clamped
/// from below by the distance to the box: the true distance is never smaller, and
/// the clamp makes "skip when point_box_distance2 >= bound" an exact test under
/// rounding too, which keeps minima independent of the order pairs are visited in.
inline double point_triangle_distance2(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                                       const Box3d& box) {
  return std::max(squared_distance(p, closest_point_on_triangle(p, a, b, c)), point_box_distance2(p, box));
}

/// Velho 1999 eq. 4: the compactness 4 sqrt(3) a / (l1^2 + l2^2 + l3^2) of triangle
/// (a, b, c), 1 for an equilateral triangle and 0 for one of no area (or no size).
inline double compactness(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const double sides = squared_distance(a, b) + squared_distance(b, c) + squared_distance(c, a);
  if (!(sides > 0)) return 0;
  return 2 * std::sqrt(3.0) * length(cross(b - a, c - a)) / sides;
}

}  // namespace metrics
}  // namespace oocsimp
