// The side of the floating-cell tiles: from the memory budget, or as the user gave it.
// See cluster/floating_cells_design.md, "Tiles and rounds" (tile size).
#pragma once

#include <cstdint>

#include "oocsimp/mesh_input.hpp"
#include "oocsimp/simplify.hpp"

namespace oocsimp {

/// A tile's working set per triangle while it is graded or clustered (its records,
/// local mesh, graded vertices and block), for sizing tiles from the budget.
constexpr double kTileBytesPerTriangle = 400;
/// Tiles beyond this outgrow the processor caches and run slower; much smaller ones
/// run slower too, as they need more border rounds.
constexpr double kMaxTileTriangles = 1 << 16;

/// The tile side for cells of side `cell`: options.floating.tile_side when given (refused with
/// UsageError when its tiles' buffers would not fit options.memory_budget, see
/// check_tile_count_fits), else from the budget, the face count and the occupancy of
/// a sample of the vertices. Never below `cell`, so a cell reaches only adjacent tiles.
double plan_tile_side(const MeshInput& input, const SimplifyOptions& options, double cell);

/// The triangle records of the fullest tile of side `side`, estimated from a sample
/// of the vertices (about two triangles per vertex).
std::uint64_t estimate_fullest_tile_records(const MeshInput& input, double side);

/// A --tile so small that its tiles' fixed costs exceed the budget is refused before
/// binning (UsageError, exit 2): the user chose the side, so it is not silently changed.
void check_tile_count_fits(const MeshInput& input, double tile_side, double user_side, std::uint64_t budget);

}  // namespace oocsimp
