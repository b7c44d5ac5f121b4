// Uniform-grid clustering (OoCS); see uniform_clusterer.cpp.
#pragma once

#include "oocsimp/simplify.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) on `grid`; fills the clustering
/// fields of `stats` (counts and the vertices / faces / solve seconds).
SimplifiedMesh cluster_uniform(MeshInput& input, const GridSpec& grid, ProgressReporter* progress,
                               SimplifyStats* stats);

}  // namespace oocsimp
