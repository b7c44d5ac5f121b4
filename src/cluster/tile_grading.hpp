// Pass 2 of floating cells, first half: each tile's owned vertices graded (Low & Tan
// §3.1), sorted in visiting order (§3.2) and laid out in the tile's vertex block with
// the decisions of the first greedy. See docs/design.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cluster/vertex_grading.hpp"
#include "common/flat_hash_map.hpp"
#include "grid/tile_binning.hpp"
#include "grid/work_share.hpp"
#include "io/mesh_input.hpp"
#include "runtime/memory_budget.hpp"
#include "spill/block_store.hpp"
#include "spill/stream_spill.hpp"

namespace oocsimp {

/// A tile's triangles over local vertex ids (in order of first use), with each
/// vertex's input index and position (read once) and the owned ones.
struct TileLocalMesh {
  std::vector<std::uint32_t> corners;  // 3 per triangle
  std::vector<std::uint64_t> index;
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> owned;  // local ids, in order of first use

  FlatHashSet<std::uint64_t> ids;  // input indices, numbered by local id

  TileLocalMesh(const TriangleRecords& tris, const PositionArray& pos)
      : corners(3 * tris.size()), ids(2 * tris.size() + 16) {
    for (std::size_t t = 0; t < tris.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        std::uint64_t v = tris[t].v[k];
        const auto [id, first_use] = ids.try_insert(v);
        if (first_use) {
          index.push_back(v);
          positions.push_back(pos.get(v));
          // A vertex is owned by one tile, so every corner of it here says the same.
          if (tris[t].owned(k)) owned.push_back(id);
        }
        corners[3 * t + std::size_t(k)] = id;
      }
  }
  LocalMesh mesh() const { return {corners.data(), corners.size() / 3, index.data(), positions.data(), index.size()}; }
};

/// The tile's owned vertices (those whose records say so) graded from the tile's
/// triangles `tris` (input order), in `precedes` order. With `boundary`, also the
/// input indices of those on the mesh's boundary, ascending (grade_local_vertices).
std::vector<GradedVertex> grade_tile(const TriangleRecords& tris, const PositionArray& positions,
                                     std::vector<std::uint64_t>* boundary = nullptr);

/// The first greedy of a tile over its graded vertices (in `precedes` order): the
/// centres, given what the tiles run before it published.
using FirstChoice =
    std::function<std::vector<GradedVertex>(std::uint32_t tile, const std::vector<GradedVertex>& sorted)>;

/// Where the vertex blocks of one cell go.
struct BlockSettings {
  double cell_size = 1;                ///< the cells of the blocks (TileVertexBlock::build)
  std::string temp_dir;                ///< the BlockStore's folder
  std::uint64_t memory_allowance = 0;  ///< bytes of blocks that stay in memory
  /// The locked vertices (sorted input indices), or null: each is a centre of its own
  /// (lock_graded).
  const std::vector<std::uint64_t>* locked = nullptr;
  /// Every vertex on the mesh's boundary is locked too (SimplifyOptions::lock_boundary):
  /// a tile holds every face of the vertices it owns, so it finds them itself.
  bool lock_boundary = false;
};

/// What grade_tiles follows besides its blocks' settings.
struct GradingSettings {
  BlockSettings blocks;
  /// With --keep-tmp, each tile's sorted vertices are also appended to its stream here.
  StreamSpill* keep = nullptr;
  const ProgressCallback* progress = nullptr;  ///< the caller's, or none
  /// The tiles in work take at most this many bytes together (TileMemoryGate; a tile
  /// larger than that runs alone).
  std::uint64_t work_share = ~std::uint64_t(0);
  /// The run's budget (may be null), which the memory held and the tiles in work
  /// must fit (TileMemoryGate).
  const MemoryBudget* budget = nullptr;
  /// Gives the allocator's free pages back (SimplifyOptions::release_memory), or null.
  void (*release_memory)() = nullptr;
  /// Only these tiles are graded (a part's own), or every tile when null.
  const TileShare* only = nullptr;
};

/// Every tile's vertex block (TileVertexBlock) in one mapped BlockStore, as
/// settings.blocks say: graded with grade_tile (kept so, before lock_graded), the
/// tiles by colour class
/// (TileGrid::for_each_by_colour) so that `choose` sees the borders of the classes
/// before.
std::unique_ptr<BlockStore> grade_tiles(const BinnedTiles& tiles, const PositionArray& positions,
                                        const FirstChoice& choose, const GradingSettings& settings);

/// The same from the graded vertices in `earlier`, the blocks of another cell (levels
/// of detail: the sweeps change which vertices are centres, never their order).
std::unique_ptr<BlockStore> blocks_from_blocks(const TileGrid& grid, const BlockStore& earlier,
                                               const FirstChoice& choose, const BlockSettings& settings);

/// The same from vertices graded by an earlier run (stream `tile` of `kept`), with
/// this run's locked vertices (not settings.lock_boundary: the kept vertices do not
/// say which are on the boundary).
std::unique_ptr<BlockStore> blocks_from_kept(const TileGrid& grid, const StreamSpill& kept, const FirstChoice& choose,
                                             const BlockSettings& settings);

}  // namespace oocsimp
