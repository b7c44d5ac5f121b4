#include "grid/tile_plan.hpp"

#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_set>
#include <vector>

#include "common/flat_hash_map.hpp"
#include "grid/grid_coord.hpp"
#include "grid/occupancy.hpp"
#include "grid/tile_binning.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// The vertex count of the fullest tile of side `side`, estimated from at most
// about 4M evenly spaced vertices.
double fullest_tile_vertices(const PositionArray& pos, double side) {
  std::uint64_t stride = std::max<std::uint64_t>(1, pos.count / (std::uint64_t(1) << 22));
  FlatHashMap<GridCoord, std::uint64_t, GridCoordHash> count;
  std::uint64_t most = 0;
  for (std::uint64_t i = 0; i < pos.count; i += stride) {
    const Vec3d p = pos.get(i);
    if (!is_finite(p)) continue;
    most = std::max(most, ++count.value(count.insert(GridCoord::of(p, side))));
  }
  return double(most) * double(stride);
}

}  // namespace

std::uint64_t estimate_fullest_tile_records(const MeshInput& input, double side) {
  return std::uint64_t(2 * fullest_tile_vertices(input.positions, side));
}

// Tile side from the memory budget: a tile's working set is about
// kTileBytesPerTriangle per triangle and `threads` tiles are in memory at once; use
// half the budget.
double plan_tile_side(const MeshInput& input, const TileSettings& settings, double cell) {
  std::uint64_t budget = settings.memory_budget;
  unsigned threads = unsigned(std::max(1, tbb::this_task_arena::max_concurrency()));
  double side = settings.tile_side;
  if (side <= 0) {
    double per_tile = std::clamp(double(budget) / 2 / threads / kTileBytesPerTriangle, 1.0, kMaxTileTriangles);
    double tiles_needed = std::max(1.0, double(input.info.face_count) / per_tile);
    // Enough tiles to keep every thread busy, once tiles are worth their overhead.
    constexpr double kMinTileTriangles = 1 << 15;
    tiles_needed = std::max(tiles_needed, std::min(4.0 * threads, double(input.info.face_count) / kMinTileTriangles));
    const Box3d& b = input.info.bounds;
    double longest = b.empty() ? 1 : std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z});
    if (tiles_needed <= 1 || longest <= 0) {
      side = std::max(longest, cell);
    } else {
      // Occupied tiles grow as divisions^2 on a surface: scale from the finest
      // counted level that does not exceed the need (or the coarsest one).
      // An estimate is enough (the tiling never changes the output): about 2^20
      // vertices, a few per cell of the finest level on a surface.
      std::uint64_t stride = std::max<std::uint64_t>(1, input.positions.count >> 20);
      std::vector<std::uint64_t> occ = count_occupancy(input.positions, b, stride);
      int l = 0;
      while (l + 1 < kLevelCount && double(occ[std::size_t(l + 1)]) <= tiles_needed) ++l;
      double divisions =
          double(kLevels[l]) * std::sqrt(tiles_needed / double(std::max<std::uint64_t>(occ[std::size_t(l)], 1)));
      side = longest / divisions;
      // That is the average tile; the fullest one can hold several times as much
      // (the generated sphere's poles are dense), and the fullest sets the memory.
      // Shrink the side until the fullest, estimated from a sample of the vertices,
      // fits, but to no less than half: a denser part would otherwise cut the whole
      // mesh into many times as many tiny tiles, each costing buffers and rounds.
      const double average_side = side;
      for (int pass = 0; pass < 4 && side > 0.5 * average_side; ++pass) {
        double fullest = 2 * fullest_tile_vertices(input.positions, std::max(side, cell));  // ~2 triangles per vertex
        if (fullest <= per_tile) break;
        side = std::max(0.5 * average_side, side * 0.95 * std::sqrt(per_tile / fullest));
      }
    }
  }
  // A tile is at least one floating cell wide, so a cell reaches only into the
  // adjacent tiles.
  side = std::max(side, cell);
  if (settings.tile_side > 0) check_tile_count_fits(input, side, settings.tile_side, budget);
  return side;
}

// The occupied tiles of the vertices are counted until there are too many.
void check_tile_count_fits(const MeshInput& input, double tile_side, double user_side, std::uint64_t budget) {
  const std::uint64_t most = std::max<std::uint64_t>(1, budget / 4 / kTileFixedBytes);
  const Box3d& b = input.info.bounds;
  if (b.empty()) return;
  double box_tiles = 1;
  for (double e : {b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z}) box_tiles *= std::floor(e / tile_side) + 2;
  if (box_tiles <= double(most)) return;  // even a full box fits
  std::unordered_set<GridCoord, GridCoordHash> occupied;
  GridCoord last{INT64_MIN, 0, 0};
  const PositionArray& pos = input.positions;
  for (std::uint64_t i = 0; i < pos.count && occupied.size() <= most; ++i) {
    Vec3d p = pos.get(i);
    if (!is_finite(p)) continue;
    GridCoord c = GridCoord::of(p, tile_side);
    if (c == last) continue;  // neighbouring vertices mostly share a tile
    last = c;
    occupied.insert(c);
  }
  if (occupied.size() <= most) return;
  char side[64];
  std::snprintf(side, sizeof side, "%g", user_side);
  throw UsageError("options.floating.tile_side",
                   "options.floating.tile_side " + std::string(side) + " makes more than " + std::to_string(most) +
                       " tiles here, whose buffers (" + std::to_string(kTileFixedBytes >> 10) +
                       " KiB each) need more than a quarter of options.memory_budget " + std::to_string(budget >> 20) +
                       " MiB: give a larger options.floating.tile_side or options.memory_budget, or leave "
                       "options.floating.tile_side unset to size tiles from options.memory_budget");
}

}  // namespace oocsimp
