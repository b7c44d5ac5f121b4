#include "hierarchy/hierarchy_quadrics.hpp"

#include <algorithm>

#include "cluster/plane_quadric.hpp"
#include "common/vec3_math.hpp"
#include "common/vertex_faces.hpp"

namespace oocsimp {

std::vector<Quadric> finest_vertex_quadrics(const std::vector<Vec3d>& positions,
                                            const std::vector<std::uint32_t>& corners, double boundary_weight) {
  const std::size_t n = positions.size(), faces = corners.size() / 3;
  std::vector<Quadric> quadrics(n);
  for (std::size_t f = 0; f < faces; ++f) {
    const std::uint32_t* t = &corners[3 * f];
    Quadric q;
    q.add_triangle(positions[t[0]], positions[t[1]], positions[t[2]]);
    for (int k = 0; k < 3; ++k) quadrics[t[k]].add(q);
  }
  if (!(boundary_weight > 0)) return quadrics;
  // Whether a face has the directed edge from->to: one of from's faces has `to` next.
  const VertexFaces around(n, corners);
  auto has_edge = [&](std::uint32_t from, std::uint32_t to) {
    for (std::uint32_t i = around.start[from]; i < around.start[std::size_t(from) + 1]; ++i) {
      const std::uint32_t* t = &corners[3 * std::size_t(around.faces[i])];
      for (int k = 0; k < 3; ++k)
        if (t[k] == from && t[(k + 1) % 3] == to) return true;
    }
    return false;
  };
  for (std::size_t f = 0; f < faces; ++f) {
    const std::uint32_t* t = &corners[3 * f];
    const Vec3d normal = cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]);
    const double normal_length = length(normal);
    if (!(normal_length > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = t[k], w = t[(k + 1) % 3];
      if (has_edge(w, u)) continue;
      const Quadric line = boundary_edge_quadric(positions[u], positions[w], normal / normal_length, boundary_weight);
      quadrics[u].add(line);
      quadrics[w].add(line);
    }
  }
  return quadrics;
}

double half_edge_collapse_cost(const Quadric& qv, const Quadric& qu, const Vec3d& pu) {
  Quadric q = qv;
  q.add(qu);
  return std::max(0.0, q.error(pu));
}

RemovalHeirs removal_heirs(int ring_count, bool closed) {
  RemovalHeirs heirs;
  if (closed && ring_count == 3) {
    heirs.index[1] = 1;
    heirs.index[2] = 2;
    heirs.count = 3;
  } else {
    heirs.index[1] = ring_count == 2 ? 1 : 2;
    heirs.count = 2;
  }
  return heirs;
}

void pass_on_quadric(std::vector<Quadric>* quadrics, std::uint32_t v, const std::uint32_t* ring,
                     const double* ring_cost, const RemovalHeirs& heirs) {
  std::vector<Quadric>& q = *quadrics;
  double total = 0;
  for (int i = 0; i < heirs.count; ++i) total += ring_cost[heirs.index[i]];
  for (int i = 0; i < heirs.count; ++i) {
    const double cost = ring_cost[heirs.index[i]];
    const double share = total > 0 ? (total - cost) / ((heirs.count - 1) * total) : 1.0 / heirs.count;
    q[ring[heirs.index[i]]].add_scaled(q[v], share);
  }
}

}  // namespace oocsimp
