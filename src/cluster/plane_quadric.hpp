// A triangle's plane quadric, computed the same way by both clustering methods
// (Garland & Heckbert 1997; Theoharis et al. 2008, "Graphics & Visualization:
// Principles and Algorithms", ch. 6 ("Model Representation and Simplification"),
// section "Quadratic error-metric").
#pragma once

#include "common/vec3_math.hpp"
#include "cluster/quadric.hpp"

namespace oocsimp {

/// A triangle's plane: the unnormalised normal m = e1 x e2 of its edges from one
/// corner, and |m|, twice the area (in the units of the edges squared).
struct TrianglePlane {
  Vec3d m;
  double len = 0;
  /// Zero area (or a non-finite edge): the triangle has no plane and adds nothing.
  bool degenerate() const { return !(len > 0); }
};

/// The plane of a triangle with edges e1 = q - p and e2 = r - p.
inline TrianglePlane triangle_plane(const Vec3d& e1, const Vec3d& e2) {
  Vec3d m = cross(e1, e2);
  return {m, length(m)};
}

/// Adds the area-weighted plane quadric area * (n n^T, (n.P) n, (n.P)^2), with unit
/// normal n, to `q`, given d = m.P for a point P of the plane in q's frame: with
/// |m| = 2 area, area * n n^T = m m^T / (2 |m|). The plane must not be degenerate.
inline void add_plane_quadric(Quadric* q, const TrianglePlane& plane, double d) {
  q->add_plane(plane.m, 0.5 / plane.len, d);
}

/// What the area-weighted plane quadric of a triangle (add_plane_quadric) gives at
/// `x`, without building it: area times the squared distance of x from the plane
/// through `corner` (any of the triangle's corners), (m.(x - corner))^2 / (2 |m|).
/// 0 for a degenerate triangle.
inline double plane_quadric_error(const TrianglePlane& plane, const Vec3d& corner, const Vec3d& x) {
  if (plane.degenerate()) return 0;
  const double d = dot(plane.m, x - corner);
  return d * d * (0.5 / plane.len);
}

/// Garland & Heckbert 1997 §6.1: what a boundary edge u -> w of a face with unit
/// normal `face` adds to both its ends: the plane through the edge perpendicular to
/// the face, so that moving off the outline costs as moving off the surface does, and
/// the face's own plane, so that the two measure the distance to the edge's line (an
/// outline keeps its relief as well as its course). Each is weighted by `weight` times
/// the squared edge length. Empty for an edge of no length.
inline Quadric boundary_edge_quadric(const Vec3d& u, const Vec3d& w, const Vec3d& face, double weight) {
  Quadric line;
  const Vec3d e = w - u;
  const Vec3d m = cross(e, face);
  const double m_length = length(m);  // |e|: the normal is a unit vector perpendicular to e
  if (!(m_length > 0)) return line;
  const Vec3d unit = m / m_length;
  line.add_plane(unit, weight * squared_length(e), dot(unit, u));
  line.add_plane(face, weight * squared_length(e), dot(face, u));
  return line;
}

}  // namespace oocsimp
