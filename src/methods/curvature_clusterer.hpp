// Curvature-adaptive vertex clustering (Hua et al.); see curvature_clusterer.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "cluster/quadric.hpp"
#include "curvature/mesh_curvatures.hpp"
#include "methods/cluster_methods.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "methods/run_plan.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) on `grid`'s cells split where the
/// principal curvatures disagree, as plan.curvature says; fills the clustering
/// fields of `stats` like cluster_uniform, with the method's phases first.
OutputMesh cluster_curvature(MeshInput& input, const RunPlan& plan, const GridSpec& grid, SimplifyStats* stats,
                             std::vector<Quadric>* quadrics = nullptr);

/// cluster_curvature at each of `grids` (levels of detail): the curvatures are
/// estimated once, then each level builds its octree, parts and clusters. Each level
/// equals cluster_curvature with its grid; the first level's phases include the
/// estimate.
void cluster_curvature_levels(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids,
                              const LevelSink& sink, const SimplifyStats& base,
                              std::vector<Quadric>* quadrics = nullptr);

/// What a part of a distributed curvature run leaves beside its vertices' values: the
/// figures every part must agree on, and its own counts.
struct CurvaturePartPlan {
  std::uint64_t vertices = 0, triangles = 0;
  double radius = 0;
  std::uint64_t invariant = 0, fitted = 0;  ///< the part's own vertices
  /// 0 when the run reads no vertex curvatures (quadric representatives): the
  /// parts estimate nothing and the merge runs it whole, at the uniform grid's pace.
  std::uint32_t estimated = 0;
  std::uint32_t reserved = 0;
};

/// Part `part` of `parts` of cluster_curvature's run: the estimate of the vertices the
/// part is dealt (VertexDeal), handed to `sink`, which is nearly all of the method's
/// time; the octree, the parts rule and the clusters follow in the merge. Adds the
/// phase "curvatures" to `stats`.
CurvaturePartPlan estimate_curvature_part(MeshInput& input, const RunPlan& plan, std::uint32_t part,
                                          std::uint32_t parts, const CurvatureSink& sink, SimplifyStats* stats);

/// Fills k1 and k2 of every vertex into k[2 v], k[2 v + 1] (the array holds zeros) and
/// returns the counts over all vertices.
using CurvatureFill = std::function<CurvatureStats(float* k)>;

/// cluster_curvature with the curvatures from `fill` (the parts of a distributed run)
/// instead of estimated here: the same bytes and stats (and `quadrics`).
OutputMesh merge_curvature_parts(MeshInput& input, const RunPlan& plan, const GridSpec& grid, const CurvatureFill& fill,
                                 SimplifyStats* stats, std::vector<Quadric>* quadrics = nullptr);

}  // namespace oocsimp
