#include "cluster/thick_primitives.hpp"

#include <algorithm>
#include <cmath>

namespace oocsimp {

double PointMoments::spread_along(const Vec3d& d) const {
  // E[(u.d)^2] - (E[u].d)^2, the variance of the projection on d.
  const Vec3d m = mean();
  const double second =
      (d.x * d.x * xx + d.y * d.y * yy + d.z * d.z * zz + 2 * (d.x * d.y * xy + d.x * d.z * xz + d.y * d.z * yz)) / n;
  const double first = dot(m, d);
  return std::max(0.0, second - first * first);
}

double PointMoments::spread() const {
  const Vec3d m = mean();
  return std::max(0.0, (xx + yy + zz) / n - squared_length(m));
}

double edge_thickness(const PointMoments& a, const Vec3d& origin_a, const PointMoments& b, const Vec3d& origin_b) {
  if (!(a.n > 0) || !(b.n > 0)) return 0;
  const Vec3d pa = a.mean() + origin_a, pb = b.mean() + origin_b;
  const Vec3d along = pb - pa;
  const double len = length(along);
  // The mean squared distance from L = the whole spread less the spread along L.
  auto perpendicular = [&](const PointMoments& m) {
    if (!(len > 0)) return std::sqrt(m.spread());
    return std::sqrt(std::max(0.0, m.spread() - m.spread_along(along / len)));
  };
  return perpendicular(a) + perpendicular(b);
}

double point_width(double count, const Vec3d& sum, double squares) {
  if (!(count > 0)) return 0;
  const Vec3d m = sum / count;
  return 2 * std::sqrt(std::max(0.0, squares / count - squared_length(m)));
}

ThickPrimitives select_thick_primitives(const std::vector<std::uint32_t>& triangles,
                                        const std::vector<EdgeCandidate>& edges,
                                        const std::vector<std::pair<std::uint32_t, float>>& point_clusters,
                                        std::size_t cluster_count) {
  FlatHashSet<std::uint64_t> sides(2 * triangles.size() + 16);
  std::vector<bool> used(cluster_count, false);
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      sides.insert(cluster_pair_key(triangles[t + k], triangles[t + (k + 1) % 3]));
      used[triangles[t + k]] = true;
    }
  ThickPrimitives out;
  for (const EdgeCandidate& e : edges) {
    if (sides.find(cluster_pair_key(e.a, e.b)) >= 0) continue;
    out.edges.insert(out.edges.end(), {e.a, e.b});
    out.edge_thickness.push_back(e.thickness);
  }
  for (std::uint32_t c : out.edges) used[c] = true;
  for (const auto& [c, width] : point_clusters) {
    if (used[c]) continue;
    used[c] = true;  // once per cluster
    out.points.push_back(c);
    out.point_thickness.push_back(width);
  }
  return out;
}

}  // namespace oocsimp
