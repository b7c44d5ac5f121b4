// Quadric edge collapse out of core: the mesh in tiles, each collapsed in core with
// its border held, in passes whose tiles shift, down to a remainder a few times the
// target that the last, in-core collapse takes to the exact count (Cignoni et al.
// 2003, OEMM; refine/pass_tile.hpp). See docs/design.md, "Exact targets".
#pragma once

#include <cstdint>

#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"
#include "refine/edge_collapse.hpp"

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
QuadricMesh reduce_in_passes(MeshInput& input, const SimplifyOptions& options, const Vec3d& origin,
                             std::uint64_t target, SimplifyStats* stats, const PassSizes& sizes = {});

}  // namespace oocsimp
