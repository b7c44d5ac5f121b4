#include "cluster/quadric.hpp"

#include <algorithm>
#include <cmath>

#include "cluster/plane_quadric.hpp"
#include "common/symmetric_eigen.hpp"

namespace oocsimp {

void Quadric::add_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& r) {
  TrianglePlane plane = triangle_plane(q - p, r - p);
  if (plane.degenerate()) return;
  add_plane_quadric(this, plane, dot(plane.m, p));
}

Vec3d minimize_quadric(const Quadric& q, const Vec3d& anchor, const Vec3d& lo, const Vec3d& hi, double rel_threshold) {
  // Lindstrom (2000), after Garland: x = x0 + A^+ (b - A x0) with the pseudo-inverse
  // truncated at rel_threshold * largest eigenvalue. Directions the quadric does
  // not constrain keep x0's coordinate, so flat and linear cells stay near the mean.
  double m[3][3] = {{q.a00, q.a01, q.a02}, {q.a01, q.a11, q.a12}, {q.a02, q.a12, q.a22}};
  double v[3][3];
  jacobi3(m, v);
  double lam[3] = {m[0][0], m[1][1], m[2][2]};
  double lmax = std::max({std::fabs(lam[0]), std::fabs(lam[1]), std::fabs(lam[2])});
  double x0[3] = {anchor.x, anchor.y, anchor.z};
  double r[3] = {q.b0 - (q.a00 * x0[0] + q.a01 * x0[1] + q.a02 * x0[2]),
                 q.b1 - (q.a01 * x0[0] + q.a11 * x0[1] + q.a12 * x0[2]),
                 q.b2 - (q.a02 * x0[0] + q.a12 * x0[1] + q.a22 * x0[2])};
  double x[3] = {x0[0], x0[1], x0[2]};
  if (lmax > 0) {
    for (int k = 0; k < 3; ++k) {
      if (lam[k] <= rel_threshold * lmax) continue;
      double proj = (v[0][k] * r[0] + v[1][k] * r[1] + v[2][k] * r[2]) / lam[k];
      for (int i = 0; i < 3; ++i) x[i] += v[i][k] * proj;
    }
  }
  return {std::clamp(x[0], lo.x, hi.x), std::clamp(x[1], lo.y, hi.y), std::clamp(x[2], lo.z, hi.z)};
}

}  // namespace oocsimp
