// The tiling of floating cells: cubes of side `side` anchored at the origin, of which
// the occupied ones are numbered 0, 1, 2, ... in order of first use. See
// docs/design.md, "Tiles and rounds".
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "grid/grid_coord.hpp"
#include "io/mesh_input.hpp"

namespace oocsimp {

/// Occupied tiles: their side, coordinates and ids, and what the rounds ask of them
/// (boxes, neighbours, colour classes).
class TileGrid {
 public:
  double side = 1;

  GridCoord of(const Vec3d& p) const { return GridCoord::of(p, side); }
  Box3d box(const GridCoord& c) const {
    Box3d b;
    b.min = {double(c.x) * side, double(c.y) * side, double(c.z) * side};
    b.max = {double(c.x + 1) * side, double(c.y + 1) * side, double(c.z + 1) * side};
    return b;
  }
  Box3d box(std::uint32_t tile) const { return box(coords_[tile]); }

  std::uint32_t count() const { return std::uint32_t(coords_.size()); }
  const GridCoord& coord(std::uint32_t tile) const { return coords_[tile]; }
  /// The id of the tile at `c`; -1 when it is not occupied.
  std::int64_t find(const GridCoord& c) const {
    auto it = ids_.find(c);
    return it == ids_.end() ? -1 : std::int64_t(it->second);
  }
  /// Adds the tile at `c` (not yet present) as the next id.
  std::uint32_t add(const GridCoord& c) {
    std::uint32_t id = count();
    ids_.emplace(c, id);
    coords_.push_back(c);
    return id;
  }

  /// Neighbouring tile ids (up to 26), ascending.
  std::vector<std::uint32_t> neighbours(std::uint32_t tile) const {
    std::vector<std::uint32_t> out;
    const GridCoord& c = coords_[tile];
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (!dx && !dy && !dz) continue;
          auto it = ids_.find(GridCoord{c.x + dx, c.y + dy, c.z + dz});
          if (it != ids_.end()) out.push_back(it->second);
        }
    std::sort(out.begin(), out.end());
    return out;
  }

  /// The colour class of a tile: the parity of its coordinates. Tiles of a class
  /// are never adjacent (a cell reaches only adjacent tiles), so they can run at
  /// once while the borders they read, their neighbours', hold still.
  int colour(std::uint32_t tile) const { return colour_of(coords_[tile]); }
  static int colour_of(const GridCoord& c) { return int(c.x & 1) | int(c.y & 1) << 1 | int(c.z & 1) << 2; }
  static constexpr int kColours = 8;

  /// The tiles of colour class k, ascending; with `only`, those t with (*only)[t].
  std::vector<std::uint32_t> tiles_of_colour(int k, const std::vector<char>* only = nullptr) const {
    std::vector<std::uint32_t> out;
    for (std::uint32_t t = 0; t < count(); ++t)
      if ((!only || (*only)[t]) && colour(t) == k) out.push_back(t);
    return out;
  }

  /// f(tile) for every tile: the 8 colour classes one after the other, each in parallel.
  template <class F>
  void for_each_by_colour(F&& f) const {
    for (int k = 0; k < kColours; ++k) {
      std::vector<std::uint32_t> of_colour = tiles_of_colour(k);
      tbb::parallel_for(std::size_t(0), of_colour.size(), [&](std::size_t i) { f(of_colour[i]); });
    }
  }

 private:
  std::unordered_map<GridCoord, std::uint32_t, GridCoordHash> ids_;
  std::vector<GridCoord> coords_;
};

}  // namespace oocsimp
