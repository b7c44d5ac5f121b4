// Uniform-grid clustering (OoCS), and the same run over other clusters; see
// uniform_clusterer.cpp.
#pragma once

#include <functional>
#include <vector>

#include "cluster/quadric.hpp"
#include "cluster/uniform_cells.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "methods/run_plan.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) on `grid` within plan.budget_bytes,
/// reporting to plan.progress; fills the clustering fields of `stats` (counts and the
/// vertices / faces / solve seconds).
OutputMesh cluster_uniform(MeshInput& input, const RunPlan& plan, const GridSpec& grid, SimplifyStats* stats,
                           std::vector<Quadric>* quadrics = nullptr);

/// What another method changes in the uniform run: its clusters in place of the grid
/// cells (VertexClusters, the curvature method) and, for vertex representatives, the
/// test of a vertex against its cell (UniformCells::choose_vertices).
struct ClusterCellSource {
  const VertexClusters* clusters = nullptr;
  UniformCells::VertexMatch matches = nullptr;  ///< null: quadric representatives
  const void* context = nullptr;                ///< handed to matches
};

/// Where merge_uniform_chunks takes the passes' chunk sums: chunk j of each pass
/// (filled into the given sums), the chunk counts, and the faces the input lost.
struct UniformChunkSource {
  std::uint64_t vertex_chunks = 0, face_chunks = 0;
  std::function<void(std::uint64_t chunk, VertexChunkSums* sums)> vertices;
  std::function<void(std::uint64_t chunk, FaceChunkSums* sums)> faces;
  SkippedFaces skipped;
};

/// cluster_uniform with the passes' chunk sums taken from `chunks` (the parts of a
/// distributed run, UniformCells::sum_part) instead of summed here: merged in chunk
/// order, as cluster_uniform merges its own, so the output is the same bytes.
/// `input` gives the attributes' layout; its triangles are not read. With `quadrics`,
/// as for cluster_uniform.
OutputMesh merge_uniform_chunks(MeshInput& input, const RunPlan& plan, const GridSpec& grid,
                                const UniformChunkSource& chunks, SimplifyStats* stats,
                                std::vector<Quadric>* quadrics = nullptr);

/// cluster_uniform over the cells of `source`.
OutputMesh cluster_cells(MeshInput& input, const RunPlan& plan, const GridSpec& grid, const ClusterCellSource& source,
                         SimplifyStats* stats, std::vector<Quadric>* quadrics);

}  // namespace oocsimp
