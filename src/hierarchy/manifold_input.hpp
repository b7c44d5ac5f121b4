// What a 4-k hierarchy is built on: a manifold mesh, every edge of one or two faces
// wound oppositely and every vertex's faces one fan. Velho 1999 assumes it; an input
// is made so here by a documented rule, or refused.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/geometry.hpp"

namespace oocsimp {

struct ManifoldMesh {
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;
  std::uint64_t split_vertices = 0;  ///< copies added where several fans met at a vertex
  std::uint64_t dropped_faces = 0;   ///< faces naming a vertex twice, or a non-finite one
  /// For each copy appended, the vertex it copies (the input's vertices keep their
  /// numbers).
  std::vector<std::uint32_t> copied_from;
};

/// Drops faces that name a vertex twice or use a non-finite vertex, then splits each
/// vertex whose faces form several fans (two cones meeting at a point) into one vertex
/// per fan: the fan of the vertex's first face keeps it, the others get copies
/// appended in the order of their first face. An edge that two faces wind the same
/// way, or that three or more faces share, throws InputError naming `name` and the
/// edge's vertices.
ManifoldMesh make_manifold(std::vector<Vec3d> positions, std::vector<std::uint32_t> triangles, const std::string& name);

}  // namespace oocsimp
