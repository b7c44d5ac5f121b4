// The clustering methods as rows of one table: a new method is an enum value, its
// file and a row in cluster_methods.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "cluster/quadric.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "io/output_mesh.hpp"
#include "methods/run_plan.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// A clustering method: simplify() opens the input, chooses the grid and calls its
/// run function with the triangle stream at its start; run fills the clustering
/// fields of `stats` (counts, the method's phases). With `quadrics`, it also gives
/// each output vertex its cluster's summed quadric, in model units relative to
/// grid.origin (multiphase simplification's phase 1, Garland & Shaffer 2002).
using ClusterRun = OutputMesh (*)(MeshInput& input, const RunPlan& plan, const GridSpec& grid, SimplifyStats* stats,
                                  std::vector<Quadric>* quadrics);
/// Hears each level of a ClusterLevels run when it is done: its number, its mesh
/// (which the sink may move from) and its stats.
using LevelSink = std::function<void(std::size_t level, OutputMesh& mesh, SimplifyStats& stats)>;
/// A method's levels of detail at each of `grids` from one run: what does not depend
/// on the grid (floating: binning and grading; curvature: the estimate) is done once.
/// Each level equals `run` at its grid; its stats start as a copy of `base`, and the
/// first level's phases include the shared work. With `quadrics`, as for ClusterRun.
using ClusterLevels = void (*)(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids,
                               const LevelSink& sink, const SimplifyStats& base, std::vector<Quadric>* quadrics);
/// A ClusterRun from a method's ClusterLevels: `levels` at the one grid `grid`.
OutputMesh single_level(ClusterLevels levels, MeshInput& input, const RunPlan& plan, const GridSpec& grid,
                        SimplifyStats* stats, std::vector<Quadric>* quadrics);
/// The positions of the input vertices `locked`, sorted, each once: the places that
/// stay where they are.
std::vector<std::array<double, 3>> locked_positions(const PositionArray& positions,
                                                    const std::vector<std::uint64_t>& locked);

/// The warning for `dropped` of the `places` locked positions that no output triangle
/// uses: every neighbour of theirs fell in one other cluster.
void warn_dropped_locks(std::size_t dropped, std::size_t places, SimplifyStats* stats);

struct ClusterMethodEntry {
  ClusterMethod method;  ///< spelled by cluster_method_names() (oocsimp/simplify.hpp)
  ClusterRun run;        ///< null for qem, which clusters nothing (simplify_to_target)
  ClusterLevels levels;  ///< null where each level is a run of its own
};
/// Every method, the default first.
const std::vector<ClusterMethodEntry>& cluster_method_table();
/// The entry of `m`; throws UsageError for a value without one.
const ClusterMethodEntry& cluster_method(ClusterMethod m);

}  // namespace oocsimp
