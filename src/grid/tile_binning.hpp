// Pass 1 of floating cells: every triangle goes to the tile of each of its corners,
// so a tile sees the complete fan of every vertex it owns. See
// docs/design.md, "Tiles and rounds".
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/uninitialised_vector.hpp"
#include "grid/grid_spec.hpp"
#include "grid/tile_grid.hpp"
#include "grid/tile_plan.hpp"
#include "grid/work_share.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"
#include "spill/spill_allowances.hpp"
#include "spill/stream_spill.hpp"

namespace oocsimp {

/// A triangle as the tile spill holds it: one record per tile holding a corner.
struct TriangleRecord {
  std::uint64_t tm;    // input triangle index (file order) | owned-corner mask << 61
  std::uint64_t v[3];  // input vertex indices

  static constexpr int kMaskShift = 61;
  std::uint64_t index() const { return tm & ((std::uint64_t(1) << kMaskShift) - 1); }
  /// Whether corner k lies in the tile holding this record (the binning knew).
  bool owned(int k) const { return (tm >> (kMaskShift + k)) & 1; }
};

/// A tile's records as read from the spill: not cleared before they are read in,
/// since every byte is a record's.
using TriangleRecords = UninitialisedVector<TriangleRecord>;

/// Every occupied tile costs a binning buffer of at least kMinBufferRecords records
/// and its bookkeeping (spill chains, coordinates, borders, neighbour lists: under
/// 1 KiB). Binning gives the buffers a quarter of the budget.
constexpr std::size_t kMinBufferRecords = 256;
constexpr std::uint64_t kTileFixedBytes = kMinBufferRecords * sizeof(TriangleRecord) + 1024;

/// The share of `budget` the tiles in work take at once (TileMemoryGate): what two
/// tiles of kMaxTileTriangles per thread take, or the fullest tile of
/// `fullest_tile_records` when that is more, and at most half the budget. A tile
/// larger than the share (a dense part of the input) runs alone.
std::uint64_t tile_work_share(std::uint64_t budget, std::uint64_t fullest_tile_records);

/// What the tiles in work may hold at once, set aside before the spills' allowances:
/// the share, or the fullest tile of `fullest_tile_records` running alone.
std::uint64_t tile_memory_reserve(std::uint64_t work_share, std::uint64_t fullest_tile_records);

/// The binned mesh: the tiling, each tile's triangle records (stream `tile` of the
/// spill, in input order) and what the triangle stream reported.
struct BinnedTiles {
  TileGrid grid;
  std::unique_ptr<StreamSpill> triangles;
  std::uint64_t triangle_count = 0;
  SkippedFaces skipped;
  std::uint64_t faces_read = 0;  ///< the input's faces, or a part's range (bin_own_face_range)

  std::uint32_t count() const { return grid.count(); }
  /// The tile's triangles, sorted by input index (a vertex quadric sums its faces in
  /// this order; binning appends in input order, so this is normally sorted already).
  TriangleRecords load(std::uint32_t tile) const;
  /// The most triangle records any tile holds.
  std::uint64_t largest_tile_records() const;
};

/// Where the spills of a floating run go and whether they are compressed.
struct SpillSettings {
  std::string dir;
  bool compress = true;  ///< the triangle, stitch and kept-triangle spills
  /// A lower estimate of the tile spill's bytes, for the free-space check and the
  /// message of a write that fails.
  std::uint64_t expected_bytes = 0;
  /// What each spill store may hold in memory instead of its file.
  SpillAllowances allow;
  /// Bytes the tiles in work may take together (TileMemoryGate), set aside before
  /// the allowances.
  std::uint64_t work_share = 0;
};
/// From the tile settings: the temp folder, zstd where the spill would go to the disk,
/// and the estimate from the input's counts, `vertex_record_bytes` per vertex.
/// `fullest_tile_records`: the fullest tile's records as planned (0: unknown), whose
/// working set the tiles' share must hold. Throws UsageError (exit 2, before any
/// binning) when that tile alone would take more than three quarters of the budget.
/// `work_share` (if not 0): the tiles' share, from a caller that sizes its own pieces
/// of work (the collapse in passes).
SpillSettings spill_settings(const MeshInput& input, const TileSettings& settings, std::size_t vertex_record_bytes,
                             std::uint64_t fullest_tile_records = 0, std::uint64_t work_share = 0);

/// Which tiles get their triangles' records: every occupied tile is numbered as
/// usual, but a tile whose coordinates the filter refuses keeps no record (a part
/// that runs only its own tiles). Null: every tile.
using TileFilter = std::function<bool(const GridCoord& tile)>;

/// Bins the triangle stream of `input` (at its start) into tiles of side
/// `tile_side`, with buffers from a quarter of `memory_budget`, records only for the
/// tiles `keep` accepts (all when null). Throws IoError when the temp folder cannot
/// hold the spill.
BinnedTiles bin_triangles(MeshInput& input, double tile_side, std::uint64_t memory_budget, const SpillSettings& spill,
                          const ProgressCallback& progress, const TileFilter& keep = nullptr);

/// Parts that run at once and own the tiles `owners` deals, each reading only its
/// range of the faces (face_range.hpp): bins part share.part's range, sends every
/// other part the records of its tiles and keeps what they send of its own. The
/// result is what bin_triangles with the part's filter gives: the same records, the
/// tiles numbered alike. Every part calls it at the same point; nullopt, on every
/// part alike, when some range cannot be read alone (the input has no
/// FixedFaceTable, a face is not a triangle, a vertex is not finite).
std::optional<BinnedTiles> bin_own_face_range(MeshInput& input, double tile_side, std::uint64_t memory_budget,
                                              const SpillSettings& spill, const ProgressCallback& progress,
                                              const TileOwners& owners, const TileShare& share);

}  // namespace oocsimp
