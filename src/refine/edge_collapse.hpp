// Quadric edge collapse in core (Garland & Heckbert 1997; Theoharis et al. 2008,
// "Graphics & Visualization: Principles and Algorithms", ch. 6 ("Model Representation
// and Simplification"), section "Simplification using Iterative Edge Collapses"
// (2)-(6)): the second phase of multiphase simplification (Garland & Shaffer 2002),
// and the whole of --method qem.
//
// The state of the mesh being collapsed (CollapseState, refine/collapse_state.hpp) is
// separate from the order the collapses are taken in, so that a test can drive the
// same state with a naive queue and compare. collapse_edges() takes them in parallel
// tiles (large meshes; tiled_collapse.cpp), then in passes (each vertex in one
// collapse a pass, the cheapest first; collapse_passes.cpp), then from a priority
// queue with lazy updates in strict order of cost (lazy_queue.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "refine/collapse_state.hpp"
#include "refine/collapse_types.hpp"

namespace oocsimp {

class ProgressPhase;

/// The collapses of `state` in order of cost, from a priority queue with lazy updates,
/// down to settings.target_triangles (exactly, with settings.exact_count). The driver
/// of collapse_state() after its passes.
void collapse_in_order(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                       ProgressPhase* progress);

/// The collapses of `state` down to settings.target_triangles: in passes
/// (settings.pass_faces, pass_share), then in strict order (collapse_in_order). The
/// driver of collapse_edges() after its tiles, and of each tile.
void collapse_state(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                    ProgressPhase* progress);

/// The parallel first step of collapse_edges() (refine/tiled_collapse.cpp): the faces
/// of `state` (no collapse taken yet) are cut into tiles of about settings.tile_faces,
/// consecutive in Morton order of their centroids; each tile collapses on its own
/// (collapse_state), its border vertices locked, to settings.tile_share times its share
/// of the target. Returns the mesh with the tiles' collapses taken, vertices in their
/// places, and adds to `stats`. Spends `state`.
QuadricMesh collapse_tiles(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats);

/// QEM edge collapse until settings.target_triangles are left: large meshes in tiles
/// first (collapse_tiles), then collapse_state(): passes, then the cheapest valid
/// collapse first (ties by vertex index) from a priority queue whose entries are
/// checked when taken (lazy updates). The result is the same for any thread count.
/// Reports the collapses taken to `progress` when given (which may cancel).
QuadricMesh collapse_edges(QuadricMesh mesh, const CollapseSettings& settings, CollapseStats* stats,
                           ProgressPhase* progress = nullptr);

/// Where collapse_edges_to_levels() hands each level: its number (0 the finest), the
/// mesh as collapse_edges() returns it, and the stats so far.
using CollapseLevelSink = std::function<void(std::size_t level, QuadricMesh mesh, const CollapseStats& stats)>;

/// collapse_edges() down to settings.target_triangles, then on from there down to each
/// of `coarser` (descending) in turn, each level handed to `each` as it is reached.
/// A coarser level continues the finer one's collapse, in passes and in order of cost
/// as for one target, so that a chain of levels costs about one collapse; each starts
/// with the needle guard of `settings`. Edges a finer level split to meet its count
/// stay, and may collapse in the next. The stats count from the start (the collapses
/// taken to reach a level, the largest cost and error among them); stuck,
/// stopped_by_error and parity are each level's own.
void collapse_edges_to_levels(QuadricMesh mesh, const CollapseSettings& settings,
                              const std::vector<std::uint64_t>& coarser, CollapseStats* stats,
                              const CollapseLevelSink& each, ProgressPhase* progress = nullptr);

}  // namespace oocsimp
