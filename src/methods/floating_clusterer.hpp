// Floating-cell clustering out of core; see floating_clusterer.cpp and
// docs/design.md.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "cluster/quadric.hpp"
#include "methods/cluster_methods.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) with floating cells of side
/// `grid.cell` as `options` say (shape, assignment, representative, memory budget,
/// tile side, temp folder); fills the clustering fields of `stats`. The result equals
/// the sequential algorithm of Low & Tan on the whole mesh, for any tiling and thread
/// count. Only vertices used by a triangle take part.
OutputMesh cluster_floating(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                            SimplifyStats* stats, std::vector<Quadric>* quadrics = nullptr);

/// cluster_floating at each of `grids` (levels of detail, Low & Tan 1997 §3.2.2 and
/// §4: "sort once"): the input is binned and graded once, with tiles that fit the
/// coarsest cell (binning and grading do not depend on the cell, see kept_tiles.hpp),
/// and every level runs its first greedy from the graded vertices, then its sweeps,
/// accumulation, stitch and assembly. Each level equals cluster_floating with its
/// grid, since the result does not depend on the tiling. Each level's stats start as
/// a copy of `base`; the first level's phases include the binning and grading.
void cluster_floating_levels(MeshInput& input, const SimplifyOptions& options, const std::vector<GridSpec>& grids,
                             const LevelSink& sink, const SimplifyStats& base,
                             std::vector<Quadric>* quadrics = nullptr);

}  // namespace oocsimp
