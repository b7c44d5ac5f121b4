#include "cluster/tile_grading.hpp"

#include <algorithm>
#include <atomic>

#include "cluster/floating_cells.hpp"
#include "grid/tile_memory_gate.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

std::vector<GradedVertex> grade_tile(const TriangleRecords& tris, const PositionArray& positions,
                                     std::vector<std::uint64_t>* boundary) {
  // The tile's vertices as local ids in order of first use, each position read
  // once; the owned ones (whose fans are complete here) are graded.
  TileLocalMesh local(tris, positions);
  std::vector<GradedVertex> graded = grade_local_vertices(local.mesh(), local.owned, boundary);
  std::sort(graded.begin(), graded.end(), [](const GradedVertex& a, const GradedVertex& b) { return precedes(a, b); });
  return graded;
}

std::unique_ptr<BlockStore> grade_tiles(const BinnedTiles& tiles, const PositionArray& positions,
                                        const FirstChoice& choose, const GradingSettings& settings) {
  const double cell_size = settings.blocks.cell_size;
  StreamSpill* const keep = settings.keep;
  std::uint32_t n = tiles.count();
  const ProgressCallback none;
  ProgressPhase phase(settings.progress ? *settings.progress : none, "grade tiles", n, "tile");
  // Round 1: grade, sort and spill every tile's vertices; the greedy with the
  // borders of the neighbours graded before.
  auto blocks =
      std::make_unique<BlockStore>(settings.blocks.temp_dir, "vertex-blocks", n, settings.blocks.memory_allowance);
  TileMemoryGate gate(settings.work_share, settings.budget, settings.release_memory);
  tiles.grid.for_each_by_colour([&](std::uint32_t tile) {
    if (settings.only && !settings.only->owns(tile)) {
      phase.advance(1);
      return;
    }
    gate.run(tiles.triangles->record_count(tile) * kTileBytesPerRecord, [&] {
      std::vector<std::uint64_t> boundary;
      std::vector<GradedVertex> graded =
          grade_tile(tiles.load(tile), positions, settings.blocks.lock_boundary ? &boundary : nullptr);
      if (keep) keep->append(tile, graded.data(), graded.size());
      lock_graded(&graded, boundary);
      if (settings.blocks.locked) lock_graded(&graded, *settings.blocks.locked);
      std::vector<unsigned char> block = TileVertexBlock::build(graded, choose(tile, graded), cell_size);
      blocks->put(tile, block.data(), block.size());
    });
    phase.advance(1);
  });
  if (keep) keep->flush();
  blocks->map();
  return blocks;
}

std::unique_ptr<BlockStore> blocks_from_blocks(const TileGrid& grid, const BlockStore& earlier,
                                               const FirstChoice& choose, const BlockSettings& settings) {
  const double cell_size = settings.cell_size;
  auto blocks =
      std::make_unique<BlockStore>(settings.temp_dir, "vertex-blocks", grid.count(), settings.memory_allowance);
  grid.for_each_by_colour([&](std::uint32_t tile) {
    const TileVertexBlock before(earlier.block(tile));
    const std::vector<GradedVertex> sorted(before.vertices(), before.vertices() + before.size());
    std::vector<unsigned char> block = TileVertexBlock::build(sorted, choose(tile, sorted), cell_size);
    blocks->put(tile, block.data(), block.size());
  });
  blocks->map();
  return blocks;
}

std::unique_ptr<BlockStore> blocks_from_kept(const TileGrid& grid, const StreamSpill& kept, const FirstChoice& choose,
                                             const BlockSettings& settings) {
  const double cell_size = settings.cell_size;
  auto blocks =
      std::make_unique<BlockStore>(settings.temp_dir, "vertex-blocks", grid.count(), settings.memory_allowance);
  grid.for_each_by_colour([&](std::uint32_t tile) {
    std::vector<GradedVertex> sorted;
    kept.read(tile, &sorted);
    if (settings.locked) lock_graded(&sorted, *settings.locked);
    std::vector<unsigned char> block = TileVertexBlock::build(sorted, choose(tile, sorted), cell_size);
    blocks->put(tile, block.data(), block.size());
  });
  blocks->map();
  return blocks;
}

}  // namespace oocsimp
