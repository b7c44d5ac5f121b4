// Where an extracted mesh's vertices go (HierarchyQuery::placement): Velho's records
// keep a subset of the finest mesh's vertices where they are, as a half-edge collapse
// does; the quadric a vertex holds in the extracted state (its own and the shares
// removed vertices passed it, eq. 9) says where the surface it stands for lies.
#pragma once

#include <cstdint>
#include <vector>

#include "cluster/quadric.hpp"
#include "oocsimp/hierarchy.hpp"

namespace oocsimp {

/// The quadric each vertex of `hierarchy` holds once the records `applied` (one flag
/// per record) are: the finest mesh's (finest_vertex_quadrics), then each applied
/// removal's passed on in record order (pass_on_quadric), as the builder did. Sets
/// `heir[v]` for each vertex that took a share.
std::vector<Quadric> held_quadrics(const MeshHierarchy& hierarchy, const std::vector<std::uint8_t>& applied,
                                   std::vector<std::uint8_t>* heir);

/// Moves each vertex of `mesh` that took a share to the minimum of the quadric it
/// holds (minimize_quadric, within the box of its neighbours grown by its size), where no face around it
/// then turns by more than kMaxTurnDegrees from the face as extracted, loses its area,
/// or falls below the builder's needle guard; else it stays. `source[i]` is the
/// hierarchy vertex of mesh vertex i; a vertex with `pinned[i]` set (when `pinned` is
/// not empty) stays. The vertices are taken in order, each against the moves before
/// it, so the result is the same for any thread count.
void place_at_quadric_minima(const MeshHierarchy& hierarchy, const std::vector<std::uint8_t>& applied,
                             const std::vector<std::uint32_t>& source, const std::vector<std::uint8_t>& pinned,
                             SimplifiedMesh* mesh);

/// A face may turn by at most this as its vertices move to their quadrics' minima.
constexpr double kMaxTurnDegrees = 60;

}  // namespace oocsimp
