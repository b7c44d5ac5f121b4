// Quadric edge collapse out of core: the mesh in tiles, each collapsed in core with
// its border held, in passes whose tiles shift, down to a remainder a few times the
// target that the last, in-core collapse takes to the exact count (Cignoni et al.
// 2003, OEMM; refine/pass_tile.hpp). See docs/design.md, "Exact targets".
#pragma once

#include <cstdint>
#include <functional>

#include "io/mesh_input.hpp"
#include "methods/run_plan.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"
#include "refine/edge_collapse.hpp"
#include "refine/pass_tile.hpp"

namespace oocsimp {

/// The sizes the passes work at. Tests make them small, to cut small meshes into many
/// tiles; a run takes the defaults, so that its tiles follow from the input alone.
struct PassSizes {
  /// Faces per occupied tile of the first pass, on average: a tile's working set
  /// stays within the processor caches' reach, and its border, held still, is a small
  /// share of it.
  double tile_faces = 65536;
  /// Inputs of fewer faces collapse whole, in core: a tile would hold most of them.
  std::uint64_t from_faces = std::uint64_t(1) << 20;
  /// A first-pass tile of more face records than this is worked on in parts (cubes
  /// of it; 0: six times tile_faces).
  std::uint64_t part_above = 0;
};

/// Whether an input of `faces` faces goes through the passes on its way to `target`:
/// meshes of fewer faces, or too near the target, collapse whole at once. The choice
/// depends on the counts alone, never on the budget or the threads.
bool collapses_in_passes(std::uint64_t faces, std::uint64_t target, const PassSizes& sizes = {});

/// The passes over `input` (triangle stream at its start) towards `target`: each pass
/// collapses every tile up to one error threshold for the whole mesh, taken from a
/// sample of its tiles, until at most a few times the target is left. Returns that
/// remainder whole: positions relative to `origin`, quadrics with the boundary planes
/// in them, each face's input normal, faces in input order. Fills the stats' input
/// counts and refine.passes. Throws UsageError (exit 2) up front when the budget
/// cannot hold a tile or the last collapse.
QuadricMesh reduce_in_passes(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t target,
                             SimplifyStats* stats, const PassSizes& sizes = {});

// The first pass spread over the parts of a distributed run (parts/, docs/cluster.md).
// Every part bins the input and takes the pass's threshold from the same sample, as
// one process would, then collapses only its own share of the tiles; the merge bins
// every part's tiles for the second pass and goes on as one process does. The tiles,
// the sample and the threshold follow from the input and the target, and a pass's
// next tiles read their records sorted, so the output does not depend on the parts.

/// What the first pass decided, the same in every part, and what a part's own tiles
/// collapsed.
struct FirstPassPlan {
  std::uint64_t input_triangles = 0;  ///< the faces binned
  SkippedFaces skipped;
  std::uint64_t tiles = 0;  ///< the pass's tiles
  double side = 0;          ///< their side
  double threshold = 0;     ///< the pass's collapse cost threshold
  std::uint64_t collapses = 0;
  double largest_cost = 0, largest_error = 0;
};

/// Where a part's tiles go: called from the threads that collapse them, one call at a
/// time.
using TileOutputSink = std::function<void(const TileOutput&)>;
/// Every tile of every part, each handed to the sink, in any order.
using TileOutputSource = std::function<void(const TileOutputSink&)>;

/// The first pass as the parts did it: their plans combined (the collapses added up)
/// and their tiles.
struct FirstPassParts {
  FirstPassPlan plan;
  TileOutputSource tiles;
};

/// Part `part` of `parts` of reduce_in_passes's first pass: the tiles whose work falls
/// to the part (the work balanced over the parts by face records, largest first),
/// each collapsed and handed to `out`.
FirstPassPlan first_pass_part(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t target,
                              std::uint32_t part, std::uint32_t parts, const TileOutputSink& out,
                              const PassSizes& sizes = {});

/// reduce_in_passes, its first pass done by the parts: `first_pass` their plan (the
/// collapses added up) and `tiles` their tiles. The same remainder and stats as
/// reduce_in_passes.
QuadricMesh reduce_after_first_pass(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t target,
                                    const FirstPassPlan& first_pass, const TileOutputSource& tiles,
                                    SimplifyStats* stats, const PassSizes& sizes = {});

}  // namespace oocsimp
