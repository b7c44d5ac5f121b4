// Uniform-grid clustering (OoCS), and the same run over other clusters; see
// uniform_clusterer.cpp.
#pragma once

#include <vector>

#include "cluster/quadric.hpp"
#include "cluster/uniform_cells.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) on `grid`, reporting to
/// options.progress (no other option applies); fills the clustering fields of `stats`
/// (counts and the vertices / faces / solve seconds).
OutputMesh cluster_uniform(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid, SimplifyStats* stats,
                           std::vector<Quadric>* quadrics = nullptr);

/// What another method changes in the uniform run: its clusters in place of the grid
/// cells (VertexClusters, the curvature method) and, for vertex representatives, the
/// test of a vertex against its cell (UniformCells::choose_vertices).
struct ClusterCellSource {
  const VertexClusters* clusters = nullptr;
  UniformCells::VertexMatch matches = nullptr;  ///< null: quadric representatives
  const void* context = nullptr;                ///< handed to matches
};

/// cluster_uniform over the cells of `source`.
OutputMesh cluster_cells(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                         const ClusterCellSource& source, SimplifyStats* stats, std::vector<Quadric>* quadrics);

}  // namespace oocsimp
