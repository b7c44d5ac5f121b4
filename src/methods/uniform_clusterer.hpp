// Uniform-grid clustering (OoCS); see uniform_clusterer.cpp.
#pragma once

#include <vector>

#include "cluster/quadric.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) on `grid`, reporting to
/// options.progress (no other option applies); fills the clustering fields of `stats`
/// (counts and the vertices / faces / solve seconds).
SimplifiedMesh cluster_uniform(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                               SimplifyStats* stats, std::vector<Quadric>* quadrics = nullptr);

}  // namespace oocsimp
