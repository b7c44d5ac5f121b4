// Choosing the clustering grid from the options' cell sizing.
#pragma once

#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"

namespace oocsimp {

/// The grid `sizing` asks for over `input` (for `ratio`, estimated from a pass over
/// the vertices that counts occupied cells of a coarse grid and scales it as a
/// surface, i.e. with the square of the resolution). Throws UsageError.
GridSpec choose_grid(const MeshInput& input, const CellSizing& sizing, unsigned threads);

}  // namespace oocsimp
