// Floating-cell clustering out of core; see floating_clusterer.cpp and
// docs/design.md.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "cluster/cluster_accumulation.hpp"
#include "cluster/quadric.hpp"
#include "methods/cluster_methods.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "methods/run_plan.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Clusters `input` (triangle stream at its start) with floating cells of side
/// `grid.cell` as `plan` says (shape, assignment, representative, memory budget,
/// tile side, temp folder); fills the clustering fields of `stats`. The result equals
/// the sequential algorithm of Low & Tan on the whole mesh, for any tiling and thread
/// count. Only vertices used by a triangle take part.
OutputMesh cluster_floating(MeshInput& input, const RunPlan& plan, const GridSpec& grid, SimplifyStats* stats,
                            std::vector<Quadric>* quadrics = nullptr);

/// cluster_floating at each of `grids` (levels of detail, Low & Tan 1997 §3.2.2 and
/// §4: "sort once"): the input is binned and graded once, with tiles that fit the
/// coarsest cell (binning and grading do not depend on the cell, see kept_tiles.hpp),
/// and every level runs its first greedy from the graded vertices, then its sweeps,
/// accumulation, stitch and assembly. Each level equals cluster_floating with its
/// grid, since the result does not depend on the tiling. Each level's stats start as
/// a copy of `base`; the first level's phases include the binning and grading.
void cluster_floating_levels(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids,
                             const LevelSink& sink, const SimplifyStats& base,
                             std::vector<Quadric>* quadrics = nullptr);

/// What a part of a floating run tells its merge besides its shares: the tiling
/// every part must agree on, and the input's counts the merge buckets by.
struct FloatingPartPlan {
  double tile_side = 0;
  std::uint64_t tiles = 0;
  std::uint64_t triangles = 0;  ///< the input's, as binned
  std::uint64_t vertices = 0;   ///< the input's
  SkippedFaces skipped;
};
/// Takes a part's cluster shares, a run of records of one kind at a time.
using ClusterShareSink = std::function<void(ShareKind, const void* records, std::size_t count)>;
/// Hands every part's cluster shares to the sink it is given.
using ClusterShareSource = std::function<void(const ClusterShareSink&)>;

/// Part `part` of `parts` of cluster_floating (docs/cluster.md): bins the whole input
/// as one process does, and accumulates the cluster shares of the tiles dealt to it
/// (by triangle records), handed to `sink`. The centres need every tile's grading and
/// the border sweeps: with `channel` (parts running at once) each part grades and
/// sweeps its own tiles, exchanging borders; without, each part grades and sweeps
/// every tile itself. `tiling` gets the tiling and counts; `stats` the part's phases.
void cluster_floating_part(MeshInput& input, const RunPlan& plan, const GridSpec& grid, std::uint32_t part,
                           std::uint32_t parts, const PartChannel& channel, const ClusterShareSink& sink,
                           FloatingPartPlan* tiling, SimplifyStats* stats);

/// The merge of a floating run's parts: their shares (`shares`, of the run `tiling`
/// says) stitched and assembled as cluster_floating does; the same mesh for any
/// number of parts, and with `quadrics` as for cluster_floating. Throws InputError for
/// a share that does not fit the input.
OutputMesh merge_floating_shares(MeshInput& input, const RunPlan& plan, const GridSpec& grid,
                                 const FloatingPartPlan& tiling, const ClusterShareSource& shares, SimplifyStats* stats,
                                 std::vector<Quadric>* quadrics = nullptr);

}  // namespace oocsimp
