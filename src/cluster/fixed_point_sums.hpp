// Cluster sums that do not depend on how the input was cut into tiles or threads
// (docs/design.md, "Sums that do not depend on the partition").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "common/vec3_math.hpp"
#include "io/mesh_input.hpp"
#include "cluster/quadric.hpp"

namespace oocsimp {

// A sum of doubles in 32.32 fixed point: integer addition is associative, so the
// total does not depend on how the terms were grouped into tiles or threads. Terms
// are in cell units (coordinates relative to the cluster's centre, divided by the
// cell size), where cluster sums stay far below 2^31; overflow is checked anyway.
struct Fixed {
  std::int64_t v = 0;
  static constexpr double kScale = 4294967296.0;  // 2^32
  static std::int64_t of(double x) {
    double s = x * kScale;
    // Round to nearest, ties to even: adding and taking away 1.5 * 2^52 does it in
    // two additions where |s| < 2^51 (nearly always: it is a library call otherwise).
    constexpr double kRound = 6755399441055744.0;  // 1.5 * 2^52
    if (std::fabs(s) < 2251799813685248.0)
      s = (s + kRound) - kRound;
    else
      s = std::nearbyint(s);
    if (!(std::fabs(s) < 9.2e18)) throw std::overflow_error("floating cells: cluster sum out of fixed-point range");
    return std::int64_t(s);
  }
  void add(std::int64_t x) {
    if (__builtin_add_overflow(v, x, &v)) throw std::overflow_error("floating cells: cluster sum overflows");
  }
  double value() const { return double(v) / kScale; }
};

// A quadric's A and b (Quadric's a00 ... b2) summed in fixed point; the constant is
// not needed to solve for the minimiser, so it is not kept.
struct FixedQuadric {
  Fixed a00, a01, a02, a11, a12, a22;
  Fixed b0, b1, b2;

  void add(const Quadric& q) {
    a00.add(Fixed::of(q.a00));
    a01.add(Fixed::of(q.a01));
    a02.add(Fixed::of(q.a02));
    a11.add(Fixed::of(q.a11));
    a12.add(Fixed::of(q.a12));
    a22.add(Fixed::of(q.a22));
    b0.add(Fixed::of(q.b0));
    b1.add(Fixed::of(q.b1));
    b2.add(Fixed::of(q.b2));
  }
  void add(const FixedQuadric& o) {
    a00.add(o.a00.v);
    a01.add(o.a01.v);
    a02.add(o.a02.v);
    a11.add(o.a11.v);
    a12.add(o.a12.v);
    a22.add(o.a22.v);
    b0.add(o.b0.v);
    b1.add(o.b1.v);
    b2.add(o.b2.v);
  }
  /// The sums as a Quadric (c = 0).
  Quadric value() const {
    Quadric q;
    q.a00 = a00.value();
    q.a01 = a01.value();
    q.a02 = a02.value();
    q.a11 = a11.value();
    q.a12 = a12.value();
    q.a22 = a22.value();
    q.b0 = b0.value();
    q.b1 = b1.value();
    q.b2 = b2.value();
    return q;
  }
};

/// A sum of positions in fixed point.
struct FixedVec3 {
  Fixed x, y, z;

  void add(const Vec3d& p) {
    x.add(Fixed::of(p.x));
    y.add(Fixed::of(p.y));
    z.add(Fixed::of(p.z));
  }
  void add(const FixedVec3& o) {
    x.add(o.x.v);
    y.add(o.y.v);
    z.add(o.z.v);
  }
  Vec3d value() const { return {x.value(), y.value(), z.value()}; }
};

/// Count, sum and second moments of points in fixed point (PointMoments, whose
/// value() this gives back), each point added on its own so that the sums do not
/// depend on the partition.
struct FixedMoments {
  std::uint64_t n = 0;
  FixedVec3 sum;
  Fixed xx, xy, xz, yy, yz, zz;

  void add(const Vec3d& u) {
    ++n;
    sum.add(u);
    xx.add(Fixed::of(u.x * u.x));
    xy.add(Fixed::of(u.x * u.y));
    xz.add(Fixed::of(u.x * u.z));
    yy.add(Fixed::of(u.y * u.y));
    yz.add(Fixed::of(u.y * u.z));
    zz.add(Fixed::of(u.z * u.z));
  }
  void add(const FixedMoments& o) {
    n += o.n;
    sum.add(o.sum);
    xx.add(o.xx.v);
    xy.add(o.xy.v);
    xz.add(o.xz.v);
    yy.add(o.yy.v);
    yz.add(o.yz.v);
    zz.add(o.zz.v);
  }
};

// What a cluster accumulates, relative to its centre and in cell units: the sum of
// its members' vertex quadrics, the sum of their positions and of their squared
// lengths (a thick point's width), their count, and how many triangles collapsed
// inside it (a thick point's candidate).
struct ClusterRecord {
  Vec3d centre;
  FixedQuadric quadric_sum;
  FixedVec3 offset_sum;
  Fixed offset_squares;
  std::uint64_t members = 0;
  std::uint64_t collapsed = 0;
  std::uint64_t locked = 0;  ///< 1 when the centre is a locked vertex (its cluster is its point)

  /// Adds a member vertex: its quadric and its offset from the centre, both in cell units.
  void add_vertex(const Quadric& q, const Vec3d& offset_in_cells) {
    quadric_sum.add(q);
    offset_sum.add(offset_in_cells);
    offset_squares.add(Fixed::of(dot(offset_in_cells, offset_in_cells)));
    ++members;
  }
  /// Merges another share of the same cluster.
  void add(const ClusterRecord& o) {
    quadric_sum.add(o.quadric_sum);
    offset_sum.add(o.offset_sum);
    offset_squares.add(o.offset_squares.v);
    members += o.members;
    collapsed += o.collapsed;
    locked |= o.locked;
  }
  /// The summed quadric (relative to the centre, in cell units; c = 0).
  Quadric quadric() const { return quadric_sum.value(); }
  /// The members' mean offset from the centre, in cell units (0 for no members).
  Vec3d mean() const { return offset_sum.value() / double(std::max<std::uint64_t>(members, 1)); }
};

// One tile's share of a cluster, spilled by centre index and merged in assemble().
struct PartialCluster {
  std::uint64_t centre;  // input index of the centre
  ClusterRecord sums;
};

}  // namespace oocsimp
