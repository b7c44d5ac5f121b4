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
  std::uint64_t flipped_faces = 0;   ///< repair: faces whose winding was turned to agree with their neighbours'
  std::uint64_t cut_edges = 0;       ///< repair: edges of three or more faces, or of two that could not agree
  std::uint64_t detached_faces = 0;  ///< repair: faces given vertices of their own where cutting was not enough
  /// For each copy appended, the vertex it copies (the input's vertices keep their
  /// numbers).
  std::vector<std::uint32_t> copied_from;
};

/// Drops faces that name a vertex twice or use a non-finite vertex, then splits each
/// vertex whose faces form several fans (two cones meeting at a point) into one vertex
/// per fan: the fan of the vertex's first face keeps it, the others get copies
/// appended in the order of their first face. An edge that two faces wind the same
/// way, or that three or more faces share, throws InputError naming `name` and the
/// edge's vertices, unless `repair`:
///  1. orient: faces joined by an edge of exactly two faces are made to wind it
///     oppositely, walking each component from its first face; a component keeps the
///     winding most of its faces had (the fewer faces are flipped). An edge closing a
///     loop that cannot agree (a Moebius strip) is cut;
///  2. cut: an edge of three or more faces, or cut in step 1, joins none of its faces:
///     the vertex split above, which joins faces only across edges of exactly two
///     faces wound oppositely, gives each side its own copies of the edge's ends;
///  3. where faces that share such a cut edge are still joined around both its ends
///     (rare), each of them is given three vertices of its own.
/// A mesh that was already manifold and wound consistently is left exactly as without
/// `repair`.
ManifoldMesh make_manifold(std::vector<Vec3d> positions, std::vector<std::uint32_t> triangles, const std::string& name,
                           bool repair = false);

}  // namespace oocsimp
