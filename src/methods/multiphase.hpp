// Exact triangle targets (TargetOptions) and --method qem: multiphase simplification
// (Garland & Shaffer 2002) with clustering as phase 1 and quadric edge collapse
// (refine/edge_collapse) as phase 2, or the collapse alone on a mesh held whole.
#pragma once

#include <functional>
#include <vector>

#include "cluster/quadric.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "io/output_mesh.hpp"
#include "methods/qem_passes.hpp"
#include "methods/run_plan.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// The least target: the fewest triangles of a closed surface (a tetrahedron).
constexpr std::uint64_t kLeastTarget = 4;

/// The triangle count target `t` asks of an input of `input_triangles`: the count, or
/// the ratio's share (at least 4), or 4 for max_error alone.
std::uint64_t resolve_target(const TargetOptions& t, std::uint64_t input_triangles);

/// A level of detail below the run's target that simplify_to_target() reaches by going
/// on with the target's edge collapse (levels of detail to halved targets).
struct CoarserLevel {
  /// The level's target (a count or a ratio of the input's triangles), at or below
  /// the run's and the finer level's.
  TargetOptions target;
  /// Reached by going on: `mesh` and `stats` hold the level. A run that ends in no
  /// collapse (the input given back, --refine none), or a level that missed its count
  /// where a finer phase 1 could meet it, leaves it false for this level and the
  /// coarser ones, for the caller to run them on their own.
  bool done = false;
  SimplifiedMesh mesh;
  /// The run's stats with this level's collapse fields, output counts, warnings and
  /// "refine" seconds (the time since the finer level).
  SimplifyStats stats;
};

/// Simplifies `input` (triangle stream at its start) to plan.target:
///  - ClusterMethod::qem: per-vertex face quadrics and the collapse, on the whole mesh
///    in memory, or out of core in passes of tiles down to a remainder that fits
///    plan.budget_bytes, then whole;
///  - uniform or floating: phase 1 clusters to about target.intermediate_factor x the
///    target at a cell chosen from the vertex sample (choose_grid), handing on each
///    cluster's summed quadric; phase 2 collapses that mesh, in memory, to the target.
/// A target at or above the input's triangles gives the input back with a warning.
/// Fills `stats` (the clustering's fields, intermediate_triangles, collapses, the
/// largest collapse cost and error, target_missed, phase seconds "refine").
/// `quadrics`, when given, receives the output vertices' quadrics (boundary planes
/// included, in model units) where the run ends in the collapse; otherwise it is
/// left empty. `coarser`, when given, lists levels the collapse goes on to (targets
/// descending, below the run's): see CoarserLevel.
SimplifiedMesh simplify_to_target(MeshInput& input, const RunPlan& plan, SimplifyStats* stats,
                                  std::vector<Quadric>* quadrics = nullptr,
                                  std::vector<CoarserLevel>* coarser = nullptr);

/// Part `part` of `parts` of simplify_to_target's run with plan.method qem (the
/// default with a target): the share of the first out-of-core pass that falls to the
/// part, its tiles into `out` and the pass's plan into `first_pass`. False, with nothing
/// done, when the run has no such pass (an input that collapses whole, a target at or
/// above the input's count): the merge then runs it whole.
bool simplify_to_target_part(MeshInput& input, const RunPlan& plan, std::uint32_t part, std::uint32_t parts,
                             const TileOutputSink& out, FirstPassPlan* first_pass);

/// simplify_to_target's result, the same bytes and stats, from the parts' first pass.
SimplifiedMesh simplify_to_target_after_parts(MeshInput& input, const RunPlan& plan, const FirstPassParts& parts,
                                              SimplifyStats* stats);

/// Phase 1 of simplify_to_target with a clustering method (uniform, floating,
/// curvature) as the parts of a distributed run share it: the grid of its first
/// attempt into `grid`. False when the run clusters nothing there (a target at or
/// above the input's count, or the whole input collapsed instead): the merge then runs
/// it whole.
bool target_clustering_grid(MeshInput& input, const RunPlan& plan, GridSpec* grid);

/// The clustering of phase 1's first attempt as the parts left it, at `grid` (the one
/// target_clustering_grid chose), filling the clustering fields of `stats` and, when
/// given, each output vertex's summed quadric.
using MergedPhaseOne =
    std::function<OutputMesh(const GridSpec& grid, SimplifyStats* stats, std::vector<Quadric>* quadrics)>;

/// simplify_to_target's result, the same bytes and stats, with phase 1's first attempt
/// from `merged` when its grid is `parts_grid` (else, as for retries, clustered here);
/// with `any_grid` (the parts' work does not depend on the grid: the curvature
/// estimate), every attempt of phase 1 at any grid from `merged`.
SimplifiedMesh simplify_to_target_after_clustering(MeshInput& input, const RunPlan& plan, const GridSpec& parts_grid,
                                                   const MergedPhaseOne& merged, bool any_grid, SimplifyStats* stats);
}  // namespace oocsimp
