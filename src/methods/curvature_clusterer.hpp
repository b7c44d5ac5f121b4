// Curvature-adaptive vertex clustering (Hua et al.); see curvature_clusterer.cpp.
#pragma once

#include <vector>

#include "cluster/quadric.hpp"
#include "methods/cluster_methods.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) on `grid`'s cells split where the
/// principal curvatures disagree, as options.curvature says; fills the clustering
/// fields of `stats` like cluster_uniform, with the method's phases first.
OutputMesh cluster_curvature(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                             SimplifyStats* stats, std::vector<Quadric>* quadrics = nullptr);

/// cluster_curvature at each of `grids` (levels of detail): the curvatures are
/// estimated once, then each level builds its octree, parts and clusters. Each level
/// equals cluster_curvature with its grid; the first level's phases include the
/// estimate.
void cluster_curvature_levels(MeshInput& input, const SimplifyOptions& options, const std::vector<GridSpec>& grids,
                              const LevelSink& sink, const SimplifyStats& base,
                              std::vector<Quadric>* quadrics = nullptr);

}  // namespace oocsimp
