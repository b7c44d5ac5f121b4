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
/// per record) are: the finest mesh's (finest_vertex_quadrics, with the default
/// boundary weight), then each applied removal's passed on in record order
/// (pass_on_quadric). For a level (a prefix of the records) this is what the builder
/// held, when it ran with the default HierarchyOptions::boundary_weight and started
/// from the finest mesh's faces as the file stores them; an error bound or a region
/// applies records out of that order, and their heirs hold what those pass on. Sets
/// `heir[v]` for each vertex that took a share.
std::vector<Quadric> held_quadrics(const MeshHierarchy& hierarchy, const std::vector<std::uint8_t>& applied,
                                   std::vector<std::uint8_t>* heir);

/// Moves each vertex of `mesh` that took a share to the minimum of the quadric it
/// holds (minimize_quadric, within the box of its neighbours grown by its size), where
/// its fan keeps its shape: no face turns by more than kMaxTurnDegrees from the face
/// as extracted, loses its area or falls below the builder's compactness bounds, and
/// no crease at the vertex becomes sharper than it was and than the builder's
/// kCreaseCosine; else it stays. `source[i]` is the hierarchy vertex of mesh vertex i;
/// a vertex with `pinned[i]` set (when `pinned` is not empty) stays, and so does one
/// whose finest position another vertex shares (a split vertex's copies, a seam's
/// sides). The vertices are taken in order, each against the moves before it, so the
/// result is the same for any thread count.
void place_at_quadric_minima(const MeshHierarchy& hierarchy, const std::vector<std::uint8_t>& applied,
                             const std::vector<std::uint32_t>& source, const std::vector<std::uint8_t>& pinned,
                             SimplifiedMesh* mesh);

/// A face may turn by at most this as its vertices move to their quadrics' minima.
/// The edge collapse allows 90 degrees; a bound of 89 gave the same levels' error as
/// 60 (docs/hierarchy.md), so the stricter one keeps a margin against folds.
constexpr double kMaxTurnDegrees = 60;

}  // namespace oocsimp
