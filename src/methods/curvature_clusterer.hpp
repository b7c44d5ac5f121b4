// Curvature-adaptive vertex clustering (Hua et al.); see curvature_clusterer.cpp.
#pragma once

#include <vector>

#include "cluster/quadric.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) on `grid`'s cells split where the
/// principal curvatures disagree, as options.curvature says; fills the clustering
/// fields of `stats` like cluster_uniform, with the method's phases first.
SimplifiedMesh cluster_curvature(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                                 SimplifyStats* stats, std::vector<Quadric>* quadrics = nullptr);

}  // namespace oocsimp
