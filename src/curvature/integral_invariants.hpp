// Principal curvatures by integral invariants (Hua et al. §3.4, after Pottmann et al.
// 2007): the covariance of a neighbourhood of p cut by the solid the surface bounds
// has two eigenvalues whose expansions in the radius r carry the principal
// curvatures (eq. 11-12 for the ball B_r(p), 15-16 for the sphere S_r(p)); eq. 13-14
// and 17-18 invert them.
//
// What the paper leaves open, and what is chosen here:
// - The solid is taken locally: within the ball, the side of the surface opposite its
//   normal at p, the surface read as a height field over p's tangent plane
//   (LocalHeightField). A closed mesh gives the paper's solid; open surfaces and soups
//   get the same estimate where the surface around p covers the disk.
// - The ball's moments are the half ball below the tangent plane, exactly, plus the
//   columns between the plane and the surface, integrated over the disk by a Gauss
//   rule in the radius and an even one in the angle; the sphere's are its lower
//   hemisphere plus the band between the equator and where the surface meets the
//   sphere, integrated in closed form along each of a set of azimuths (on a sphere
//   the area element is r dphi dz). Only the small part is integrated numerically.
// - Of the covariance's eigenvectors the one nearest the normal is the normal
//   direction; the other two give M1 and M2.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "oocsimp/curvature.hpp"  // CurvatureNeighbourhood
#include "oocsimp/geometry.hpp"

namespace oocsimp {

/// k1 >= k2; positive where the surface is convex seen along its outward normal.
struct PrincipalCurvatures {
  double k1 = 0, k2 = 0;
};

/// Where the surface crosses a vertical line of p's frame: its height, and whether
/// its outward normal points up there (above it is outside the solid).
struct SurfaceCrossing {
  double z = 0;
  bool outward_up = true;
};

/// The surface around p in p's tangent frame (p at the origin, z along the outward
/// normal) over the disk of radius r: where it crosses each vertical line.
class LocalHeightField {
 public:
  /// The surface over the disk of radius r lies within this times r of p while it
  /// bends by less than about 1/r (its height at the rim below r/2): what a caller
  /// gathers.
  static constexpr double kHeightFieldReach = 1.125;
  /// The most crossings one line reports (a surface folded over itself many times
  /// within the ball; beyond this, the lowest are kept).
  static constexpr int kMostCrossings = 16;

  /// The ball's quadrature lines (ball_curvatures): at the nodes of a Gauss-Legendre
  /// rule of this many points in the radius, and this many even angles.
  static constexpr int kBallRadii = 6;
  static constexpr int kBallAngles = 24;
  static constexpr int kBallLines = kBallRadii * kBallAngles;

  /// Which lines the field answers for: the ball's quadrature lines only, whose
  /// crossings are found as each triangle is added (ball_line()), or any line
  /// (crossings(), height(): the sphere's azimuths move with the surface).
  enum class Lines { of_the_ball, any };
  /// Empties the field for a disk of radius `radius`.
  void reset(double radius, Lines lines = Lines::any);
  /// Adds triangle (a, b, c), in the frame, wound counter-clockwise seen from outside.
  void add_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c);
  /// The surface's crossings of the vertical line through (x, y), lowest first, into
  /// `out` (room for kMostCrossings); returns their count. Only for Lines::any.
  int crossings(double x, double y, SurfaceCrossing* out) const;
  /// A quadrature line of the ball (Lines::of_the_ball): radial node i and angle j
  /// at index i * kBallAngles + j, its place, and its crossings, lowest first.
  struct BallLine {
    double x = 0, y = 0;
    int count = 0;
    SurfaceCrossing crossings[kMostCrossings];
  };
  bool has_ball_lines() const { return lines_ == Lines::of_the_ball; }
  const BallLine& ball_line(int index) const { return ball_lines_[std::size_t(index)]; }
  /// Whether point q lies in the solid by the triangle nearest it (of those nearly
  /// as near, the one q faces most squarely): for a vertical line that meets no
  /// triangle, where the surface leaves the ball above or below it.
  bool inside(const Vec3d& q) const;
  /// Whether a sheet facing up passes over (x, y); *z gets the height of the one
  /// nearest the tangent plane.
  bool height(double x, double y, double* z) const;
  double radius() const { return radius_; }

 private:
  struct Projected {
    double ax, ay, ux, uy, vx, vy;  // corner a and the edges a->b, a->c
    double za, zu, zv;              // height at a and its changes along the edges
    double inverse_area2;           // 1 / (u x v): negative where the outward normal points down
  };
  static constexpr int kBuckets = 8;  // per side of the square around the disk
  // The ball's lines are found by bucket too, finer ones: a triangle then meets the
  // lines of fewer buckets.
  static constexpr int kLineBuckets = 16;
  int bucket(double coordinate) const;
  int line_bucket(double coordinate) const {
    // Clamped before the conversion: a coordinate far off (or not a number) stays in range.
    const double b = (coordinate - lo_) * per_line_bucket_;
    return b >= 0 ? (b < kLineBuckets - 1 ? int(b) : kLineBuckets - 1) : 0;
  }
  // Whether the vertical line through (x, y) meets t; *c gets the crossing.
  static bool meets(const Projected& t, double x, double y, SurfaceCrossing* c);
  // Inserts c into the n crossings at `out`, by height; past capacity the highest goes.
  static void insert_crossing(const SurfaceCrossing& c, SurfaceCrossing* out, int* n);
  void place_ball_lines();
  double radius_ = 0, lo_ = 0, bucket_size_ = 1, per_line_bucket_ = 1;
  Lines lines_ = Lines::any;
  // The ball's lines: where they are and what they meet, and by bucket (CSR) for
  // the radius they were placed at.
  std::array<BallLine, kBallLines> ball_lines_;
  double lines_radius_ = 0;
  std::array<std::uint16_t, kLineBuckets * kLineBuckets + 1> line_bucket_start_{};
  std::array<std::uint16_t, kBallLines> line_bucket_lines_{};
  struct Corners {
    Vec3d a, b, c;
  };
  // What inside() reads of a triangle besides its corners: its normal (the cross
  // product of its edges from a) and that normal's length, and its bounding box, a
  // lower bound of the distance to it that spares most closest-point searches. Worked
  // out for every triangle at the field's first inside(), which most fields never call.
  struct CornerShape {
    Vec3d normal;
    double normal_length = 0;
    Vec3d lo, hi;
  };
  std::vector<Projected> triangles_;
  std::vector<Corners> corners_;                    // every triangle added, edge-on ones too
  mutable std::vector<CornerShape> corner_shapes_;  // empty until the first inside()
  std::vector<std::uint32_t> bucket_lists_[kBuckets * kBuckets];
};

/// Hua et al. eq. 13-14: the principal curvatures from the covariance of B_r(p) cut by
/// the solid: along each vertical line, below a crossing whose outward normal points
/// up and above one whose normal points down (so a surface folded over itself within
/// the ball counts each layer). A line that meets no triangle is in or out as a whole
/// (LocalHeightField::inside) when the surface is `closed` around p (no outline
/// within the gathered reach); else it makes the estimate fail (false).
bool ball_curvatures(const LocalHeightField& heights, bool closed, PrincipalCurvatures* out);

/// Hua et al. eq. 17-18: the same from the sphere S_r(p) cut by the solid, below the
/// sheet facing up that meets the sphere nearest the tangent plane along each
/// azimuth. False where an azimuth meets none.
bool sphere_curvatures(const LocalHeightField& heights, PrincipalCurvatures* out);

/// The fallback where the surface does not cover the disk (an outline, a hole, a
/// soup): z = a x^2 + b xy + c y^2 + d x + e y fitted by least squares to `points` in
/// p's frame, and the eigenvalues of its Hessian. False for fewer than 5 points or a
/// singular fit.
bool quadratic_fit_curvatures(const std::vector<Vec3d>& points, PrincipalCurvatures* out);

}  // namespace oocsimp
