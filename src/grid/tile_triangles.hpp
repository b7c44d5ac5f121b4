// Triangles binned into tiles (pass 1 of floating cells) and a tile's triangles
// over local vertex ids (pass 2). See cluster/floating_cells_design.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "cluster/vertex_grading.hpp"
#include "common/flat_hash_map.hpp"
#include "grid/cell_map.hpp"
#include "grid/grid_coord.hpp"
#include "oocsimp/mesh_input.hpp"

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

/// A tile's triangles over local vertex ids (in order of first use), with each
/// vertex's input index and position (read once) and the owned ones.
struct TileLocalMesh {
  std::vector<std::uint32_t> corners;  // 3 per triangle
  std::vector<std::uint64_t> index;
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> owned;  // local ids, in order of first use

  CellMap<char> ids;  // input index -> local id

  TileLocalMesh(const std::vector<TriangleRecord>& tris, const PositionArray& pos)
      : corners(3 * tris.size()), ids(2 * tris.size() + 16) {
    for (std::size_t t = 0; t < tris.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        std::uint64_t v = tris[t].v[k];
        std::size_t before = ids.size();
        std::uint32_t id = ids.insert(v);
        if (ids.size() != before) {
          index.push_back(v);
          positions.push_back(pos.get(v));
          // A vertex is owned by one tile, so every corner of it here says the same.
          if (tris[t].owned(k)) owned.push_back(id);
        }
        corners[3 * t + std::size_t(k)] = id;
      }
  }
  LocalMesh mesh() const {
    return {corners.data(), corners.size() / 3, index.data(), positions.data(), index.size()};
  }
};

/// Binning's unit of work: triangles read in input order, their records grouped by tile.
constexpr std::size_t kBinChunk = 1 << 15;

struct BinChunk {
  std::vector<std::uint64_t> tris = std::vector<std::uint64_t>(3 * kBinChunk);
  std::size_t count = 0;
  std::uint64_t first = 0;  // input index of the first triangle
  // The chunk's records grouped by tile, each group in input order, so each tile
  // gets one append: group g is records[group_start[g], group_start[g + 1]) of
  // tile tiles.key(g).
  std::vector<TriangleRecord> records;
  FlatHashSet<GridCoord, GridCoordHash> tiles;  // the chunk's tiles, numbered in order of first use
  std::vector<std::uint32_t> group_start;
  // Scratch: the chunk-local tile of each record in input order, and the next
  // free place of each group while grouping.
  std::vector<std::pair<std::uint32_t, TriangleRecord>> filed;
  std::vector<std::uint32_t> at;

  // Groups `filed` by chunk-local tile with a counting sort (stable: input order
  // within a tile), instead of sorting 56-byte (coordinate, record) pairs.
  void group() {
    const std::size_t count = tiles.size();
    group_start.assign(count + 1, 0);
    for (const auto& f : filed) ++group_start[f.first + 1];
    for (std::size_t g = 0; g < count; ++g) group_start[g + 1] += group_start[g];
    records.resize(filed.size());
    at.assign(group_start.begin(), group_start.end() - 1);
    for (const auto& f : filed) records[at[f.first]++] = f.second;
  }
  /// The chunk-local number of tile c.
  std::uint32_t local_tile(const GridCoord& c) { return tiles.insert(c); }
};

}  // namespace oocsimp
