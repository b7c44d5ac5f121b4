// The end of floating cells: the cross-tile triangles stitched to the ones decided
// in tiles, the output vertices numbered by first use and the cluster
// representatives solved from their merged shares. See
// docs/design.md, "Sums that do not depend on the partition".
#pragma once

#include <cstdint>
#include <vector>

#include "cluster/attribute_sums.hpp"
#include "cluster/fixed_point_sums.hpp"
#include "cluster/floating_cells.hpp"
#include "runtime/memory_budget.hpp"
#include "spill/stream_spill.hpp"
#include "grid/grid_spec.hpp"
#include "io/large_array.hpp"
#include "io/mesh_input.hpp"
#include "io/output_mesh.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"
#include "stitch/kept_triangles.hpp"

namespace oocsimp {

/// The candidate output triangles: those decided inside tiles (read from `inside`)
/// and the cross-tile ones joined from `corners` (stitch_cross_tile_corners), in an
/// array placed by `place` (a mapped file when it is large: the list never needs the
/// heap). With a `budget`, throws UsageError when the largest stitch bucket (and the
/// list, where `place` keeps it in the heap) would not fit next to what the process
/// holds. With `edges`, the cross-tile triangles over two clusters or one go to its
/// shares (CrossTileEdges).
LargeArray<KeptTriangle> stitch_kept_triangles(StreamSpill& inside, StreamSpill& corners,
                                               const ArrayPlace& place = ArrayPlace(),
                                               const MemoryBudget& budget = MemoryBudget(),
                                               const CrossTileEdges* edges = nullptr);

/// The output position of a cluster from its merged sums: its centre, the mean of
/// its vertices or the quadric minimiser kept in the cell (`rule`), for cells `cell`.
Vec3d representative(const ClusterRecord& s, const FloatingCellShape& cell, RepresentativeRule rule);

/// What assembly counted.
struct AssemblyCounts {
  std::uint64_t clusters = 0;     ///< clusters with a share, used by a triangle or not
  std::uint64_t locked = 0;       ///< clusters of locked centres
  std::uint64_t locked_used = 0;  ///< of those, the ones the output uses (as a vertex or a point)
};

/// With thick edges (Low & Tan 1997 §3.3), where assemble_mesh finds the edges and
/// points that clustering reduced below a triangle.
struct ThickAssembly {
  StreamSpill* edge_shares = nullptr;        ///< EdgeShare records by first cluster / cluster span
  const PositionArray* positions = nullptr;  ///< the input's: a centre is an input vertex
};

/// How assemble_mesh places the output vertices, and what it carries with them.
struct AssemblySettings {
  FloatingCellShape cell;
  RepresentativeRule rule = RepresentativeRule::quadric;  ///< see representative()
  /// Checked before the output tables are allocated (unbounded by default).
  MemoryBudget budget;
  /// With attributes: every tile's share of each cluster's attribute sums, in the
  /// streams of `partials` (see ClusterShares), and their layout. Null without.
  StreamSpill* attribute_shares = nullptr;
  const AttributeLayout* attributes = nullptr;
  /// With thick edges: see ThickAssembly. Null without.
  const ThickAssembly* thick = nullptr;
  /// What the handed-on quadrics are relative to (assemble_mesh's `quadrics`).
  Vec3d origin;
  /// Clusters are named by their centre's input index, below this (the input's
  /// vertex count): the size of the table that numbers them.
  std::uint64_t cluster_span = 0;
  /// Where the output's arrays and the cluster numbering go.
  ArrayPlace place;
};

/// The output mesh: `kept` deduplicated and in input order of first occurrence
/// (consumed, sorted where it is), vertices numbered by first use, each placed at
/// representative() of its cluster's shares merged from `partials` a bucket at a
/// time. The output's arrays and the numbering go where settings.place puts them: an
/// output of any size is assembled next to a bucket of shares. Throws UsageError
/// before allocating what goes in the heap when that (and the largest cluster
/// bucket) would not fit settings.budget next to what the process holds.
/// With settings.attribute_shares, each output vertex also gets its cluster's
/// attribute values (AttributeLayout::finish).
/// With `quadrics`, each output vertex also gets its cluster's summed quadric, in
/// model units relative to settings.origin (multiphase_quadric).
/// With settings.thick, the output also gets SimplifiedMesh::primitives: the edges of
/// `thick->edge_shares` (summed per cluster pair) that no output triangle has as a
/// side, sorted by cluster pair, and as points the clusters that some triangle
/// collapsed into and no triangle or edge uses, by centre index; their vertices follow
/// the triangles'. See select_thick_primitives.
/// `counts`, when given, gets what assembly counted.
OutputMesh assemble_mesh(LargeArray<KeptTriangle> kept, StreamSpill& partials, const AssemblySettings& settings,
                         AssemblyCounts* counts = nullptr, std::vector<Quadric>* quadrics = nullptr);

/// A cluster's summed quadric, kept in cell units about its centre, in model units
/// about `origin`: with u = (y - t) / s (t the centre less origin, s the cell side)
/// E_model(y) = s^4 E(u), so A' = s^2 A, b' = s^2 A t + s^3 b, c' = s^2 t.A t + 2 s^3 b.t + s^4 c.
Quadric multiphase_quadric(const ClusterRecord& s, const FloatingCellShape& cell, const Vec3d& origin);

}  // namespace oocsimp
