// The cell-scale curvature estimate; see patch_moments.hpp and docs/curvature.md.
#include "cluster/patch_moments.hpp"

#include <cmath>

#include "cluster/plane_quadric.hpp"

namespace oocsimp {

namespace {

// The mean unit normal of a patch that is a height field over its tangent plane is
// long: a cap of a sphere 90 degrees across still gives 0.71. Below half, the normals
// face too many ways for a slope along a plane to mean anything.
constexpr double kLeastCoherence = 0.5;
// A ridge on the centroids' covariance, relative to its trace: it keeps the solve
// finite where the centroids lie along a line (a strip one face wide), and there adds
// nothing across it, where the normal has no spread to read either.
constexpr double kRidge = 1e-6;
// Centroids whose spread is below this, relative to the patch's extent squared (its
// area and its mean's distance from the corner), are one point: the rounding of
// the covariance would be all that is left of it.
constexpr double kLeastSpread = 1e-10;

double solve_det3(const double m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

}  // namespace

void PatchMoments::add_face(const Vec3d& c, const Vec3d& an) {
  const double a = length(an);
  if (!(a > 0)) return;
  area += a;
  first += c * a;
  xx += a * c.x * c.x;
  xy += a * c.x * c.y;
  xz += a * c.x * c.z;
  yy += a * c.y * c.y;
  yz += a * c.y * c.z;
  zz += a * c.z * c.z;
  normal += an;
  const double n[3] = {an.x, an.y, an.z};
  for (int i = 0; i < 3; ++i) {
    nx[3 * i] += n[i] * c.x;
    nx[3 * i + 1] += n[i] * c.y;
    nx[3 * i + 2] += n[i] * c.z;
  }
}

void PatchMoments::add_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const TrianglePlane plane = triangle_plane(b - a, c - a);
  if (plane.degenerate()) return;
  add_face((a + b + c) / 3.0, plane.m * 0.5);
}

void PatchMoments::add(const PatchMoments& o, const Vec3d& t) {
  // With c' = c + t: sum A c' = f + A t; sum A c' c'^T = M + f t^T + t f^T + A t t^T;
  // sum A n c'^T = X + N t^T.
  const Vec3d& f = o.first;
  area += o.area;
  first += f + t * o.area;
  xx += o.xx + 2 * f.x * t.x + o.area * t.x * t.x;
  xy += o.xy + f.x * t.y + t.x * f.y + o.area * t.x * t.y;
  xz += o.xz + f.x * t.z + t.x * f.z + o.area * t.x * t.z;
  yy += o.yy + 2 * f.y * t.y + o.area * t.y * t.y;
  yz += o.yz + f.y * t.z + t.y * f.z + o.area * t.y * t.z;
  zz += o.zz + 2 * f.z * t.z + o.area * t.z * t.z;
  normal += o.normal;
  const double n[3] = {o.normal.x, o.normal.y, o.normal.z};
  for (int i = 0; i < 3; ++i) {
    nx[3 * i] += o.nx[3 * i] + n[i] * t.x;
    nx[3 * i + 1] += o.nx[3 * i + 1] + n[i] * t.y;
    nx[3 * i + 2] += o.nx[3 * i + 2] + n[i] * t.z;
  }
}

PatchCurvature patch_curvature(const PatchMoments& m) {
  PatchCurvature out;
  const double area = m.area;
  if (!(area > 0) || !std::isfinite(area)) return out;
  const Vec3d mean = m.first / area;
  const Vec3d nbar = m.normal / area;
  const double coherence = length(nbar);
  if (!std::isfinite(coherence) || !is_finite(mean)) return out;
  if (!(coherence >= kLeastCoherence)) {
    out.fit = PatchFit::folded;
    return out;
  }
  // The tangent frame of the mean normal: t0 across the axis it is least along.
  const Vec3d nu = nbar / coherence;
  const Vec3d ax = std::fabs(nu.x) <= std::fabs(nu.y) && std::fabs(nu.x) <= std::fabs(nu.z) ? Vec3d{1, 0, 0}
                   : std::fabs(nu.y) <= std::fabs(nu.z)                                     ? Vec3d{0, 1, 0}
                                                                                            : Vec3d{0, 0, 1};
  Vec3d t[2];
  t[0] = cross(nu, ax);
  t[0] = t[0] / length(t[0]);
  t[1] = cross(nu, t[0]);
  // Covariances about the means: P of the centroids, C of the normals with them.
  const double mu[3] = {mean.x, mean.y, mean.z}, nb[3] = {nbar.x, nbar.y, nbar.z};
  const double second[3][3] = {{m.xx, m.xy, m.xz}, {m.xy, m.yy, m.yz}, {m.xz, m.yz, m.zz}};
  double P[3][3], C[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      P[i][j] = second[i][j] / area - mu[i] * mu[j];
      C[i][j] = m.nx[3 * i + j] / area - nb[i] * mu[j];
    }
  auto form = [&](const double M[3][3], const Vec3d& a, const Vec3d& b) {
    const double av[3] = {a.x, a.y, a.z}, bv[3] = {b.x, b.y, b.z};
    double s = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s += av[i] * M[i][j] * bv[j];
    return s;
  };
  const double p00 = form(P, t[0], t[0]), p01 = form(P, t[0], t[1]), p11 = form(P, t[1], t[1]);
  const double trace = p00 + p11;
  if (!(trace > kLeastSpread * (area + dot(mean, mean))) || !std::isfinite(trace)) {
    out.fit = PatchFit::single;
    return out;
  }
  const double ridge = kRidge * trace;
  const double p = p00 + ridge, q = p01, r = p11 + ridge;
  // L = [[a, b], [b, c]] from L P + P L = C + C^T, C's entries (tangent part of n
  // against tangent part of c).
  const double c00 = form(C, t[0], t[0]), c01 = form(C, t[0], t[1]), c10 = form(C, t[1], t[0]),
               c11 = form(C, t[1], t[1]);
  const double M[3][3] = {{2 * p, 2 * q, 0}, {q, p + r, q}, {0, 2 * q, 2 * r}};
  const double rhs[3] = {2 * c00, c01 + c10, 2 * c11};
  const double det = solve_det3(M);
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) {
    out.fit = PatchFit::single;
    return out;
  }
  double x[3];
  for (int k = 0; k < 3; ++k) {
    double Mk[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Mk[i][j] = j == k ? rhs[i] : M[i][j];
    x[k] = solve_det3(Mk) / det;
  }
  const double half_sum = 0.5 * (x[0] + x[2]), half_diff = 0.5 * (x[0] - x[2]);
  const double spread = std::sqrt(half_diff * half_diff + x[1] * x[1]);
  if (!std::isfinite(half_sum) || !std::isfinite(spread)) {
    out.fit = PatchFit::single;
    return out;
  }
  out.k1 = half_sum + spread;
  out.k2 = half_sum - spread;
  out.fit = PatchFit::slope;
  return out;
}

}  // namespace oocsimp
