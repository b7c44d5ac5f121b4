// Thick edges and points: Low & Tan 1997 §2 step 5 and §3.3. A triangle whose corners
// fall in two clusters becomes an edge between them, one in a single cluster a point;
// the sums here give their thickness, and select_thick_primitives keeps those that
// no surviving triangle already shows.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "cluster/fixed_point_sums.hpp"
#include "common/flat_hash_map.hpp"
#include "common/vec3_math.hpp"
#include "oocsimp/mesh.hpp"

namespace oocsimp {

/// Count, sum and second moments of a set of points, relative to an origin the caller
/// fixes (the cell's corner: small values, so the spread does not cancel away). The
/// mean and the spread about any line follow from them, so one pass suffices, and
/// sums added in a fixed order are the same for any thread count.
struct PointMoments {
  double n = 0;
  Vec3d sum;
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  void add(const Vec3d& u) {
    n += 1;
    sum += u;
    xx += u.x * u.x;
    xy += u.x * u.y;
    xz += u.x * u.z;
    yy += u.y * u.y;
    yz += u.y * u.z;
    zz += u.z * u.z;
  }
  void add(const PointMoments& o) {
    n += o.n;
    sum += o.sum;
    xx += o.xx;
    xy += o.xy;
    xz += o.xz;
    yy += o.yy;
    yz += o.yz;
    zz += o.zz;
  }
  /// The mean point (relative to the origin); n > 0.
  Vec3d mean() const { return sum / n; }
  /// The mean squared distance from the mean along unit direction d (d = 0: the mean
  /// squared distance from the mean).
  double spread_along(const Vec3d& d) const;
  double spread() const;
};

/// The corners that the triangles collapsing to one cluster pair have in each of the
/// two clusters: `a` in the pair's first cluster, `b` in its second.
struct EdgeMoments {
  PointMoments a, b;
  void add(const EdgeMoments& o) {
    a.add(o.a);
    b.add(o.b);
  }
};

/// The thickness of the edge between clusters A and B, D_A + D_B (Low & Tan 1997
/// §3.3.1): D_A is how far A's corners V_A lie from the line L through P_A and P_B,
/// the means of V_A and V_B. The paper takes the mean perpendicular distance; this is
/// the root mean square, which follows from the moments (one pass) and equals the mean
/// when the corners are equally far from L, as on a cylinder's rings (2r for radius r).
/// `origin_a` and `origin_b` are the origins of the two moments. Corners count once
/// per triangle (V_A with multiplicity). With P_A = P_B there is no line, and D is the
/// RMS distance from the common mean.
double edge_thickness(const PointMoments& a, const Vec3d& origin_a, const PointMoments& b, const Vec3d& origin_b);

/// The width of a point (Low & Tan are silent): twice the RMS distance of its
/// cluster's vertices from their mean, the diameter of a sphere. A point's cluster
/// holds nothing but the small closed part that collapsed into it (anything else would
/// leave an edge or a triangle there), so these are that part's vertices.
/// `count`, `sum` and `squares` (sum of |v|^2) are relative to one origin.
double point_width(double count, const Vec3d& sum, double squares);

/// One thick-edge candidate: clusters a and b and the edge's thickness (edge_thickness).
struct EdgeCandidate {
  std::uint32_t a = 0, b = 0;
  float thickness = 0;
};

/// The survivors of Low & Tan 1997 §2 step 5, where the paper is silent about
/// duplicates: an edge is kept once per cluster pair, unless a surviving triangle has
/// that pair as a side; a point is kept once per cluster, unless the cluster is a
/// corner of a surviving triangle or edge. `triangles` are cluster triples (3 per
/// triangle), `edges` the candidates in output order, `point_clusters` the clusters
/// some triangle collapsed into with their widths. The results use cluster numbers.
ThickPrimitives select_thick_primitives(const std::vector<std::uint32_t>& triangles,
                                        const std::vector<EdgeCandidate>& edges,
                                        const std::vector<std::pair<std::uint32_t, float>>& point_clusters,
                                        std::size_t cluster_count);

/// The moments in double.
inline PointMoments moments_value(const FixedMoments& f) {
  PointMoments m;
  m.n = double(f.n);
  m.sum = f.sum.value();
  m.xx = f.xx.value();
  m.xy = f.xy.value();
  m.xz = f.xz.value();
  m.yy = f.yy.value();
  m.yz = f.yz.value();
  m.zz = f.zz.value();
  return m;
}

/// Floating cells: one tile's (or the stitch's) share of the triangles that collapse
/// to the edge between clusters a < b (input indices of their centres), their corners'
/// moments in cell units relative to each cluster's centre, in fixed point so that
/// shares add up the same in any order. a == b: a triangle that crossed tiles and
/// collapsed into cluster a (a thick point's candidate; no moments).
struct EdgeShare {
  std::uint64_t a = 0, b = 0;
  FixedMoments in_a, in_b;
  bool point() const { return a == b; }
};

/// Adds the corners of a triangle over clusters `cluster[3]` (two distinct, or one)
/// to the share of its edge in `shares` (found through `at`, by cluster pair), each
/// corner's offset from its cluster's centre `offset[k]` in cell units.
class EdgeShareTable {
 public:
  void add(const std::uint64_t cluster[3], const Vec3d offset[3]) {
    const std::uint64_t lo = std::min({cluster[0], cluster[1], cluster[2]});
    const std::uint64_t hi = std::max({cluster[0], cluster[1], cluster[2]});
    const auto [i, fresh] = at_.try_insert({lo, hi});
    if (fresh) shares_.push_back({lo, hi, {}, {}});
    EdgeShare& s = shares_[i];
    if (lo == hi) return;
    for (int k = 0; k < 3; ++k) (cluster[k] == lo ? s.in_a : s.in_b).add(offset[k]);
  }
  std::vector<EdgeShare>& shares() { return shares_; }
  void clear() {
    at_.clear();
    shares_.clear();
  }

 private:
  struct PairHash {
    std::uint64_t operator()(const std::pair<std::uint64_t, std::uint64_t>& p) const {
      return p.first * 0x9E3779B97F4A7C15ull ^ p.second;
    }
  };
  FlatHashSet<std::pair<std::uint64_t, std::uint64_t>, PairHash> at_;
  std::vector<EdgeShare> shares_;
};

/// The key of an unordered cluster pair.
inline std::uint64_t cluster_pair_key(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
}

}  // namespace oocsimp
