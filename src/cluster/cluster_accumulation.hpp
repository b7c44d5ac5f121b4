// Pass 3 of floating cells: per tile, vertices assigned to the decided centres,
// vertex quadrics summed into partition-independent cluster shares, and the
// triangles over three clusters kept. See docs/design.md, "Sums that do not
// depend on the partition".
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "cluster/attribute_sums.hpp"
#include "cluster/centre_sweeps.hpp"
#include "cluster/floating_cells.hpp"
#include "grid/tile_binning.hpp"
#include "grid/grid_spec.hpp"
#include "grid/work_share.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"
#include "runtime/memory_budget.hpp"
#include "spill/block_store.hpp"
#include "spill/stream_spill.hpp"

namespace oocsimp {

/// What the tiles hand to the stitch and the assembly, all in spills.
struct ClusterShares {
  /// PartialCluster: every tile's share of each cluster it touched, in stream
  /// `centre / cluster_span` (the centre's input index).
  std::unique_ptr<StreamSpill> partials;
  std::uint64_t cluster_span = 1;
  /// KeptTriangle: the triangles decided inside their tile (deduplicated per tile),
  /// and CornerRecord: the corners of triangles that cross tiles, both in stream
  /// `triangle index / bucket_span`.
  std::unique_ptr<StreamSpill> inside, corners;
  std::uint64_t bucket_span = 1;
  /// With attributes: every tile's share of each cluster's attribute sums (records of
  /// attribute_record_bytes(): the centre's input index, then the layout's width()
  /// fixed-point sums), in the streams of `partials`; null without attributes.
  std::unique_ptr<StreamSpill> attribute_shares;
  AttributeLayout attributes;
  /// With thick edges: EdgeShare records of the triangles decided in tiles that
  /// collapse to an edge, one per tile and cluster pair, in the streams of `partials`
  /// by the pair's first cluster; the stitch adds the cross-tile ones. Null without.
  std::unique_ptr<StreamSpill> edge_shares;
};

/// Bytes of one attribute share for `layout`.
inline std::size_t attribute_record_bytes(const AttributeLayout& layout) {
  return sizeof(std::uint64_t) * (1 + layout.width());
}

/// Settings of the accumulation: the options it follows and where its spills go.
struct AccumulationSettings {
  FloatingCellShape cell;
  AssignRule assign = AssignRule::nearest;
  std::uint64_t memory_budget = 0;  ///< a cluster bucket's shares fit in an eighth of it
  SpillSettings spill;
  const ProgressCallback* progress = nullptr;  ///< the caller's, or none
  const AttributeArray* attributes = nullptr;  ///< the carried vertex attributes, or none
  /// Bytes the tiles in work may take together (TileMemoryGate).
  std::uint64_t work_share = ~std::uint64_t(0);
  /// Keep what collapses below a triangle (ClusterShares::edge_shares, and
  /// ClusterRecord::collapsed): Low & Tan 1997 §3.3.
  bool thick_edges = false;
  /// The run's budget (may be null), which the memory held and the tiles in work
  /// must fit (TileMemoryGate).
  const MemoryBudget* budget = nullptr;
  /// Gives the allocator's free pages back (SimplifyOptions::release_memory), or null.
  void (*release_memory)() = nullptr;
  /// Only these tiles are accumulated (a part's own), or every tile when null.
  const TileShare* only = nullptr;
};

/// The records of ClusterShares, by the spill they go to: what a part of a
/// distributed run hands to its merge.
enum class ShareKind : std::uint8_t { partial = 1, inside = 2, corner = 3, attribute = 4 };
/// Bytes of one record of `kind` (attribute shares: with `layout`).
std::size_t share_record_bytes(ShareKind kind, const AttributeLayout& layout);

/// Empty shares for a mesh of `triangle_count` triangles and `vertex_count` vertices,
/// bucketed as accumulate_clusters buckets them under `settings` (without thick
/// edges), for the shares of parts to be added to.
ClusterShares open_cluster_shares(std::uint64_t triangle_count, std::uint64_t vertex_count,
                                  const AccumulationSettings& settings);
/// Adds `count` records of `kind` to the bucket of each; throws InputError (naming
/// `where`) for a record whose key is beyond the shares' buckets.
void add_share_records(ClusterShares* shares, ShareKind kind, const void* records, std::size_t count,
                       const std::string& where);
/// Writes every partly filled buffer of the shares' spills (after records were added).
void flush_shares(ClusterShares* shares);
/// f(kind, records, count) for every record of `shares`, a run at a time (after
/// accumulate_clusters).
void for_each_share_run(const ClusterShares& shares, const std::function<void(ShareKind, const void*, std::size_t)>& f);

/// Per tile (in parallel): assigns the owned vertices of its block in `blocks` to the
/// tile's centres and the neighbours' `borders`, sums vertex quadrics (Garland &
/// Heckbert) relative to the cluster centres into fixed-point cluster shares, and
/// keeps the triangles spanning three clusters. `vertex_count`: the input's vertices
/// (the largest centre index + 1).
ClusterShares accumulate_clusters(const BinnedTiles& tiles, const PositionArray& positions, const BlockStore& blocks,
                                  const TileBorders& borders, std::uint64_t vertex_count,
                                  const AccumulationSettings& settings);

}  // namespace oocsimp
