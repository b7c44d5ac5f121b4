// A loaded mesh as the edge collapse takes it: positions, triangles and the
// area-weighted face quadrics (face_quadrics), for the collapse's tests.
#pragma once

#include <cstddef>
#include <cstdint>

#include "refine/edge_collapse.hpp"
#include "test_support.hpp"

namespace oocsimp_test {

inline oocsimp::QuadricMesh quadric_mesh_of(const LoadedMesh& m) {
  oocsimp::QuadricMesh q;
  for (std::size_t i = 0; i < m.vertex_count(); ++i)
    q.positions.push_back({m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]});
  for (std::uint64_t v : m.triangles) q.triangles.push_back(std::uint32_t(v));
  q.quadrics = oocsimp::face_quadrics(q.positions, q.triangles);
  return q;
}

}  // namespace oocsimp_test
