#include "cluster/tile_grading.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <utility>

#include "cluster/floating_cells.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

namespace {

// What a thread grades its tiles with, kept from tile to tile (capacities reused).
struct GradingBuffers {
  std::vector<TriangleRecord> tris;
  TileLocalMesh local;
  GradingWorkspace work;
  std::vector<GradedVertex> graded;
};

// grade_tile into buffers->graded.
void grade_tile(const std::vector<TriangleRecord>& tris, const PositionArray& positions, GradingBuffers* buffers) {
  // The tile's vertices as local ids in order of first use, each position read
  // once; the owned ones (whose fans are complete here) are graded.
  buffers->local.build(tris, positions);
  std::vector<GradedVertex>& graded = buffers->graded;
  grade_local_vertices(buffers->local.mesh(), buffers->local.owned, &buffers->work, &graded);
  std::sort(graded.begin(), graded.end(), [](const GradedVertex& a, const GradedVertex& b) { return precedes(a, b); });
}

}  // namespace

std::vector<GradedVertex> grade_tile(const std::vector<TriangleRecord>& tris, const PositionArray& positions) {
  GradingBuffers buffers;
  grade_tile(tris, positions, &buffers);
  return std::move(buffers.graded);
}

std::unique_ptr<BlockStore> grade_tiles(const BinnedTiles& tiles, const PositionArray& positions, double cell_size,
                                        const FirstChoice& choose, StreamSpill* keep, const std::string& temp_dir,
                                        std::uint64_t memory_allowance, ProgressReporter* progress) {
  std::uint32_t n = tiles.count();
  if (progress) progress->begin("grade tiles", n, "tile");
  std::atomic<std::uint32_t> done{0};
  // Round 1: grade, sort and spill every tile's vertices; the greedy with the
  // borders of the neighbours graded before.
  auto blocks = std::make_unique<BlockStore>(temp_dir, "vertex-blocks", n, memory_allowance);
  tbb::enumerable_thread_specific<GradingBuffers> buffers;
  tiles.grid.for_each_by_colour([&](std::uint32_t tile) {
    // Isolated: a thread waiting inside the body must not take up another tile
    // with the same buffers.
    tbb::this_task_arena::isolate([&] {
      GradingBuffers& b = buffers.local();
      tiles.load(tile, &b.tris);
      grade_tile(b.tris, positions, &b);
      const std::vector<GradedVertex>& graded = b.graded;
      if (keep) keep->append(tile, graded.data(), graded.size());
      std::vector<unsigned char> block = TileVertexBlock::build(graded, choose(tile, graded), cell_size);
      blocks->put(tile, block.data(), block.size());
    });
    if (progress) progress->set(++done);
  });
  if (keep) keep->flush();
  blocks->map();
  if (progress) progress->end();
  return blocks;
}

std::unique_ptr<BlockStore> blocks_from_kept(const TileGrid& grid, const StreamSpill& kept, double cell_size,
                                             const FirstChoice& choose, const std::string& temp_dir,
                                             std::uint64_t memory_allowance) {
  auto blocks = std::make_unique<BlockStore>(temp_dir, "vertex-blocks", grid.count(), memory_allowance);
  grid.for_each_by_colour([&](std::uint32_t tile) {
    std::vector<GradedVertex> sorted;
    kept.read(tile, &sorted);
    std::vector<unsigned char> block = TileVertexBlock::build(sorted, choose(tile, sorted), cell_size);
    blocks->put(tile, block.data(), block.size());
  });
  blocks->map();
  return blocks;
}

}  // namespace oocsimp
