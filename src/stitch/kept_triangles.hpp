// The output triangles of floating cells before assembly: the triangles over three
// distinct clusters that tiles decided, joined with the cross-tile ones found by
// joining their corners' clusters (docs/design.md, "Sums that do not
// depend on the partition", last paragraph).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "cluster/triangle_records.hpp"
#include "io/mesh_input.hpp"
#include "spill/stream_spill.hpp"

namespace oocsimp {

/// Where the stitch hands its triangles: `count` at `triangles`, a bucket at a time.
using KeptTriangleSink = std::function<void(const KeptTriangle* triangles, std::size_t count)>;

/// Joins the corners of cross-tile triangles, which the tiles owning them wrote into
/// `corners` (CornerRecord, one bucket of triangle indices per spill tile, each
/// bucket small enough to sort in memory): hands `keep` the triangles whose three
/// clusters differ, deduplicated per bucket. Throws std::logic_error when a triangle
/// lacks a corner (the tiles did not report every owned corner).
void stitch_cross_tile_corners(StreamSpill& corners, const KeptTriangleSink& keep,
                               const struct CrossTileEdges* edges = nullptr);

/// With thick edges, where the stitch puts the cross-tile triangles over two clusters
/// or one: EdgeShare records appended to `shares` (stream: first cluster /
/// `cluster_span`, as the tiles' shares), the corners' offsets from their centres
/// taken from `positions` (a centre is an input vertex) in units of `cell`.
struct CrossTileEdges {
  const PositionArray* positions = nullptr;
  double cell = 1;
  StreamSpill* shares = nullptr;
  std::uint64_t cluster_span = 1;
};

}  // namespace oocsimp
