// How many cells of coarse grids a mesh occupies: the basis of size estimates.
#pragma once

#include <cstdint>
#include <vector>

#include "io/mesh_input.hpp"

namespace oocsimp {

/// The resolutions (cells along the bounding box's longest axis) count_occupancy uses.
constexpr std::uint32_t kLevels[] = {16, 32, 64, 128, 256};
constexpr int kLevelCount = 5;

/// Occupied cells of the grids with kLevels[i] cells along the longest axis of
/// `bounds`, counted over every `stride`-th vertex (per-thread bitmaps, at most
/// 2 MiB each). A stride above 1 undercounts cells holding fewer vertices than it.
std::vector<std::uint64_t> count_occupancy(const PositionArray& positions, const Box3d& bounds,
                                           std::uint64_t stride = 1);

/// How occupancy grows with resolution: `cells` occupied at `resolution` (cells
/// along the longest axis), and about cells * (r / resolution)^k at r (k ~ 2 for a
/// surface, clamped to [1, 3]). Measured between the two coarse levels of `occ`
/// (count_occupancy over `samples` vertices) fine enough to resolve the shape yet
/// coarse enough that the samples hit every occupied cell (at most one cell per 8).
struct OccupancyGrowth {
  double resolution = 1;
  double cells = 1;
  double k = 2;
  /// Occupied cells at resolution r.
  double cells_at(double r) const;
  /// The resolution with about `target` occupied cells.
  double resolution_for(double target) const;
  /// Cells that `vertices` occupy at resolution r: cells_at(r) C, less those no vertex
  /// falls in once cells outnumber vertices, C (1 - e^(-vertices / C)) as if the
  /// vertices fell at random (a mesh's vertices are spread more evenly and occupy more).
  double occupied_by(double r, std::uint64_t vertices) const;
};
OccupancyGrowth occupancy_growth(const std::vector<std::uint64_t>& occ, std::uint64_t samples);

/// occupancy_growth over a sample of about 2^20 of the vertices.
OccupancyGrowth sampled_occupancy_growth(const PositionArray& positions, const Box3d& bounds);

}  // namespace oocsimp
