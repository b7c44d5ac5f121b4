// Principal curvatures of a patch of surface from a few sums over its faces, the
// cell-scale estimator of curvature clustering (Hua et al. §3.4 estimate "the principal
// curvature for every cell"; docs/curvature.md, "The cell-scale estimate").
//
// A face's unit normal n is constant over it. Over a patch, the area-weighted
// covariance of the normals' tangent part with the faces' centroids is the shape
// operator L (the Gauss map's differential, dn = L dx) times the centroids' tangent
// covariance P: Cov(n_t, x_t) = L P. The sums below give both, so L is the
// least-squares slope of the normal along the patch: a jet of order 1 of the normal
// field, the normal-field counterpart of the jet fits of Cazals & Pouget 2003. On a
// sphere (n = x / R) and on a cylinder the relation is exact at any patch size, so no
// constant needs calibrating; elsewhere it is the patch's mean shape operator.
#pragma once

#include <cstdint>

#include "common/vec3_math.hpp"

namespace oocsimp {

/// Area-weighted sums over the faces of a patch, positions relative to a corner the
/// owner keeps: area A, sum A c (c the centroid), sum A c c^T, sum A n and sum A n c^T
/// (n the unit normal, so A n is half the cross product of two edges). 22 doubles.
struct PatchMoments {
  double area = 0;
  Vec3d first;                                            // sum A c
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;  // sum A c c^T
  Vec3d normal;                                           // sum A n
  double nx[9] = {};                                      // sum A n_i c_j at [3 i + j]

  /// A face with centroid `centroid` and area vector `area_vector` (A n). A face of
  /// zero area adds nothing; the caller skips non-finite ones.
  void add_face(const Vec3d& centroid, const Vec3d& area_vector);
  /// The face a, b, c (wound counter-clockwise seen from outside).
  void add_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c);
  /// Another patch's sums, whose corner lies at `shift` from this one's.
  void add(const PatchMoments& o, const Vec3d& shift);
};

/// How a patch's estimate was found.
enum class PatchFit : std::uint8_t {
  slope,   ///< the normal's slope along the patch
  empty,   ///< no area (or sums that are not finite): 0 and 0
  single,  ///< one face, or centroids all at one point: no spread to read, 0 and 0
  folded,  ///< the normals cancel (a closed or folded piece, a soup wound both ways): 0 and 0
};

struct PatchCurvature {
  double k1 = 0, k2 = 0;  ///< k1 >= k2, positive where convex seen along the normal
  PatchFit fit = PatchFit::empty;
};

/// The principal curvatures of the patch whose sums are `m`: the eigenvalues of the
/// symmetric L that solves L P + P L = C + C^T in the tangent plane of the mean
/// normal, with C the tangent block of Cov(n, c) and P that of Cov(c, c). Never NaN.
PatchCurvature patch_curvature(const PatchMoments& m);

}  // namespace oocsimp
