// How many cells of coarse grids a mesh occupies: the basis of size estimates.
#pragma once

#include <cstdint>
#include <vector>

#include "oocsimp/mesh_input.hpp"

namespace oocsimp {

/// The resolutions (cells along the bounding box's longest axis) count_occupancy uses.
constexpr std::uint32_t kLevels[] = {16, 32, 64, 128, 256};
constexpr int kLevelCount = 5;

/// Occupied cells of the grids with kLevels[i] cells along the longest axis of
/// `bounds`, counted over every `stride`-th vertex (per-thread bitmaps, at most
/// 2 MiB each). A stride above 1 undercounts cells holding fewer vertices than it.
std::vector<std::uint64_t> count_occupancy(const PositionArray& positions, const Box3d& bounds,
                                           std::uint64_t stride = 1);

}  // namespace oocsimp
