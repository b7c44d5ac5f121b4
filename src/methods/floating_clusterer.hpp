// Floating-cell clustering out of core; see floating_clusterer.cpp and
// floating_cells_design.md.
#pragma once

#include <vector>

#include "cluster/quadric.hpp"
#include "oocsimp/simplify.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) with floating cells of side
/// `grid.cell` as `options` say (shape, assignment, representative, memory budget,
/// tile side, temp folder); fills the clustering fields of `stats`. The result equals
/// the sequential algorithm of Low & Tan on the whole mesh, for any tiling and thread
/// count. Only vertices used by a triangle take part.
SimplifiedMesh cluster_floating(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                                SimplifyStats* stats, std::vector<Quadric>* quadrics = nullptr);

}  // namespace oocsimp
