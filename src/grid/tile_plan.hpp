// The side of the floating-cell tiles: from the memory budget, or as the user gave it.
// See docs/design.md, "Tiles and rounds" (tile size).
#pragma once

#include <cstdint>

#include <string>

#include "io/mesh_input.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"

namespace oocsimp {

/// A tile's working set per triangle while it is graded or clustered (its records,
/// local mesh, graded vertices and block), for sizing tiles from the budget.
constexpr double kTileBytesPerTriangle = 400;
/// Tiles beyond this outgrow the processor caches and run slower; much smaller ones
/// run slower too, as they need more border rounds.
constexpr double kMaxTileTriangles = 1 << 16;

/// What the tiling and its spills take from a run's options.
struct TileSettings {
  std::uint64_t memory_budget = 0;  ///< bytes (resolved: never 0)
  double tile_side = 0;             ///< the user's tile side in model units; 0 = from the budget
  bool keep_temp = false;           ///< tiles are kept for a later run (FloatingOptions::keep_temp)
  SpillCompression spill_compression = SpillCompression::automatic;
  std::string temp_dir;  ///< empty = default_temp_dir()
};

/// The tile side for cells of side `cell`: settings.tile_side when given (refused with
/// UsageError when its tiles' buffers would not fit settings.memory_budget, see
/// check_tile_count_fits), else from the budget, the face count and the occupancy of
/// a sample of the vertices. Never below `cell`, so a cell reaches only adjacent tiles.
double plan_tile_side(const MeshInput& input, const TileSettings& settings, double cell);

/// The triangle records of the fullest tile of side `side`, estimated from a sample
/// of the vertices (about two triangles per vertex).
std::uint64_t estimate_fullest_tile_records(const MeshInput& input, double side);

/// A --tile so small that its tiles' fixed costs exceed the budget is refused before
/// binning (UsageError, exit 2): the user chose the side, so it is not silently changed.
void check_tile_count_fits(const MeshInput& input, double tile_side, double user_side, std::uint64_t budget);

}  // namespace oocsimp
