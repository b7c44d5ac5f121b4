// The quadric error metric (Garland & Heckbert; Theoharis et al. 2008, "Graphics &
// Visualization: Principles and Algorithms", ch. 6 ("Model Representation and
// Simplification"), section "Quadratic error-metric").
//
// The squared distance to a plane n·x + d = 0 (|n| = 1) is x^T (n n^T) x + 2 d n·x + d^2.
// A quadric stores the sums of these terms, weighted by triangle area, as
// E(x) = x^T A x - 2 b^T x + c with A symmetric (6 unique entries).
#pragma once

#include "io/mesh_input.hpp"

namespace oocsimp {

struct Quadric {
  // A = [a00 a01 a02; a01 a11 a12; a02 a12 a22]
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  double b0 = 0, b1 = 0, b2 = 0;
  double c = 0;

  /// Adds the area-weighted plane quadric of triangle (p, q, r). A triangle of zero
  /// area adds nothing.
  void add_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& r);
  /// Adds w * (m m^T, d m, d^2): the plane quadric of a triangle with unnormalised
  /// normal m through a point P with d = m.P, weighted by w = 1 / (2 |m|) so that the
  /// total is area * (squared distance). One triangle's plane can so be added in
  /// several frames (P shifted) without recomputing its normal.
  void add_plane(const Vec3d& m, double w, double d) {
    a00 += w * m.x * m.x;
    a01 += w * m.x * m.y;
    a02 += w * m.x * m.z;
    a11 += w * m.y * m.y;
    a12 += w * m.y * m.z;
    a22 += w * m.z * m.z;
    b0 += w * d * m.x;
    b1 += w * d * m.y;
    b2 += w * d * m.z;
    c += w * d * d;
  }
  // Inline: the edge collapse costs every edge with these, several times a pass.
  void add(const Quadric& o) {
    a00 += o.a00;
    a01 += o.a01;
    a02 += o.a02;
    a11 += o.a11;
    a12 += o.a12;
    a22 += o.a22;
    b0 += o.b0;
    b1 += o.b1;
    b2 += o.b2;
    c += o.c;
  }
  /// Adds w times `o` (w >= 0 keeps it a sum of squared distances).
  void add_scaled(const Quadric& o, double w) {
    a00 += w * o.a00;
    a01 += w * o.a01;
    a02 += w * o.a02;
    a11 += w * o.a11;
    a12 += w * o.a12;
    a22 += w * o.a22;
    b0 += w * o.b0;
    b1 += w * o.b1;
    b2 += w * o.b2;
    c += w * o.c;
  }
  /// The same planes moved by `offset`: E'(x + offset) = E(x), so that a quadric
  /// summed in a frame with origin o serves points in model units with offset o.
  Quadric translated(const Vec3d& offset) const {
    // (x - o)^T A (x - o) - 2 b^T (x - o) + c = x^T A x - 2 (b + A o)^T x + (o^T A o + 2 b^T o + c).
    Quadric q = *this;
    const double ox = a00 * offset.x + a01 * offset.y + a02 * offset.z;
    const double oy = a01 * offset.x + a11 * offset.y + a12 * offset.z;
    const double oz = a02 * offset.x + a12 * offset.y + a22 * offset.z;
    q.b0 += ox;
    q.b1 += oy;
    q.b2 += oz;
    q.c += offset.x * ox + offset.y * oy + offset.z * oz + 2 * (b0 * offset.x + b1 * offset.y + b2 * offset.z);
    return q;
  }
  /// E(x): the area-weighted sum of squared distances from x to the planes.
  double error(const Vec3d& x) const {
    const double ax = a00 * x.x + a01 * x.y + a02 * x.z;
    const double ay = a01 * x.x + a11 * x.y + a12 * x.z;
    const double az = a02 * x.x + a12 * x.y + a22 * x.z;
    return x.x * ax + x.y * ay + x.z * az - 2 * (b0 * x.x + b1 * x.y + b2 * x.z) + c;
  }
};

/// The point that minimises `q`, found robustly: A is eigen-decomposed and directions
/// whose eigenvalue is below `rel_threshold` times the largest are left free
/// (Lindstrom's truncated pseudo-inverse), so the answer is the minimiser closest to
/// `anchor` (the cell's mean vertex). A flat cell thus gives the anchor projected onto
/// its plane, a linear one the projection onto its line. The result is clamped to the
/// box [lo, hi].
Vec3d minimize_quadric(const Quadric& q, const Vec3d& anchor, const Vec3d& lo, const Vec3d& hi,
                       double rel_threshold = 1e-3);

}  // namespace oocsimp
