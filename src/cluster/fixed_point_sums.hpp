// Cluster sums that do not depend on how the input was cut into tiles or threads
// (cluster/floating_cells_design.md, "Sums that do not depend on the partition").
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "oocsimp/mesh_input.hpp"

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
    if (std::fabs(s) < 2251799813685248.0) s = (s + kRound) - kRound;
    else s = std::nearbyint(s);
    if (!(std::fabs(s) < 9.2e18)) throw std::overflow_error("floating cells: cluster sum out of fixed-point range");
    return std::int64_t(s);
  }
  void add(std::int64_t x) {
    if (__builtin_add_overflow(v, x, &v)) throw std::overflow_error("floating cells: cluster sum overflows");
  }
  double value() const { return double(v) / kScale; }
};

// What a cluster accumulates: the quadric (A and b; the constant is not needed to
// solve), the sum of member positions and the member count, relative to its centre.
struct ClusterRecord {
  Vec3d centre;
  Fixed sum[12];  // a00 a01 a02 a11 a12 a22 b0 b1 b2, mx my mz
  std::uint64_t members = 0;
  void add(const ClusterRecord& o) {
    for (int i = 0; i < 12; ++i) sum[i].add(o.sum[i].v);
    members += o.members;
  }
};

// One tile's share of a cluster, spilled by centre index and merged in assemble().
struct PartialCluster {
  std::uint64_t centre;  // input index of the centre
  ClusterRecord sums;
};

}  // namespace oocsimp
