// The sequential floating-cell clustering of Low & Tan §3.2, written as plainly as
// the paper states it, for comparison with the library's tiled implementation:
// sort, then visit; every visited vertex scans all existing cells (no grid).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "cluster/floating_cells.hpp"

namespace oocsimp_test {

struct ReferenceClustering {
  std::vector<std::uint64_t> centres;  ///< input indices of the centres, in visiting order
  std::vector<std::uint64_t> cluster;  ///< per vertex (in input order of `vertices`): its centre's index
};

/// With `locked` (one flag per vertex), a locked vertex is visited before all others
/// (by index) and is a cluster of its own: its cell is its point.
inline ReferenceClustering reference_floating_cells(const std::vector<oocsimp::GradedVertex>& vertices, double size,
                                                    oocsimp::CellShape shape, oocsimp::AssignRule rule,
                                                    const std::vector<char>& locked = {}) {
  const auto is_locked = [&](std::size_t i) { return !locked.empty() && locked[i]; };
  std::vector<std::size_t> order(vertices.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto &va = vertices[a], &vb = vertices[b];
    if (is_locked(a) != is_locked(b)) return is_locked(a);
    if (is_locked(a)) return va.index < vb.index;
    return va.weight > vb.weight || (va.weight == vb.weight && va.index < vb.index);
  });
  auto inside_cell = [&](const oocsimp::Vec3d& c, const oocsimp::Vec3d& p) {
    double h = 0.5 * size, dx = p.x - c.x, dy = p.y - c.y, dz = p.z - c.z;
    if (shape == oocsimp::CellShape::cube) return std::abs(dx) <= h && std::abs(dy) <= h && std::abs(dz) <= h;
    return dx * dx + dy * dy + dz * dz <= h * h;
  };
  auto inside_of = [&](std::size_t c, const oocsimp::Vec3d& p) {
    const oocsimp::Vec3d& q = vertices[c].p;
    return is_locked(c) ? (p.x == q.x && p.y == q.y && p.z == q.z) : inside_cell(q, p);
  };
  ReferenceClustering r;
  r.cluster.assign(vertices.size(), 0);
  std::vector<std::size_t> centre_pos;  // positions in `vertices`, in creation (= weight) order
  for (std::size_t i : order) {
    const auto& v = vertices[i];
    std::size_t best = SIZE_MAX;
    double best_d2 = 0;
    for (std::size_t c : centre_pos) {  // heaviest first
      if (!inside_of(c, v.p)) continue;
      double dx = v.p.x - vertices[c].p.x, dy = v.p.y - vertices[c].p.y, dz = v.p.z - vertices[c].p.z;
      double d2 = dx * dx + dy * dy + dz * dz;
      if (best == SIZE_MAX || (rule == oocsimp::AssignRule::nearest && d2 < best_d2)) {
        best = c;
        best_d2 = d2;
      }
    }
    if (best == SIZE_MAX) {
      centre_pos.push_back(i);
      r.centres.push_back(v.index);
      r.cluster[i] = v.index;
    } else {
      r.cluster[i] = vertices[best].index;
    }
  }
  return r;
}

}  // namespace oocsimp_test
