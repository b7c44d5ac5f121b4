// Floating-cell clustering, Low & Tan §3.2 and §4 (shared/papers/000), on one tile.
// See floating_cells_design.md for how tiles combine into the exact global result.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "cluster/vertex_grading.hpp"
#include "oocsimp/simplify.hpp"

namespace oocsimp {

/// The §3.2 visiting order: heavier first; equal weights by smaller input index, so
/// the order is total and the same in every partition of the input.
inline bool precedes(const GradedVertex& a, const GradedVertex& b) {
  return a.weight > b.weight || (a.weight == b.weight && a.index < b.index);
}

/// A floating cell: a cube of side `size` or a sphere of diameter `size` centred on
/// its centre vertex.
struct FloatingCellShape {
  double size = 1;
  CellShape shape = CellShape::cube;
  /// Whether p lies in the cell centred at c (boundary included).
  bool contains(const Vec3d& c, const Vec3d& p) const {
    double h = 0.5 * size;
    double dx = p.x - c.x, dy = p.y - c.y, dz = p.z - c.z;
    if (shape == CellShape::cube) return std::abs(dx) <= h && std::abs(dy) <= h && std::abs(dz) <= h;
    return dx * dx + dy * dy + dz * dz <= h * h;
  }
};

/// The centres among `sorted` (vertices in `precedes` order) chosen by the §3.2
/// greedy: a vertex becomes a centre unless a centre heavier than it holds it in its
/// cell. `external` are centres owned by other tiles; each covers only vertices it
/// precedes. Uses §4's lookup: centres are filed by the grid cell (side `size`,
/// anchored at the origin) holding them, and a vertex checks the 2x2x2 grid cells
/// its own cell overlaps, so the pass is linear after the sort.
std::vector<GradedVertex> choose_centres(const std::vector<GradedVertex>& sorted,
                                         const std::vector<GradedVertex>& external, const FloatingCellShape& cell);

/// The greedy again after the external centres changed from `old_external` to
/// `new_external` (both in `precedes` order), given `old_centres`, its result for the
/// old input. Only vertices near a change are re-decided: a vertex whose cell holds
/// no changed item (an external centre added or removed, or a vertex of the tile
/// whose decision changed earlier in the pass) keeps its decision, because the
/// heavier centres around it are the same. Returns the same as choose_centres with
/// `new_external`, in time proportional to the tile plus the changes.
std::vector<GradedVertex> rechoose_centres(const std::vector<GradedVertex>& sorted,
                                           const std::vector<GradedVertex>& old_centres,
                                           const std::vector<GradedVertex>& old_external,
                                           const std::vector<GradedVertex>& new_external, const FloatingCellShape& cell);

/// For each vertex of `vertices` (in any order), the position in `centres` of the
/// centre of its cluster: among the centres that precede it and hold it in their
/// cell, the nearest (ties: the one that precedes) or the heaviest, by `rule`. A
/// centre is its own cluster. Throws std::logic_error for a vertex no centre covers
/// (the centres were not the greedy result for these vertices).
std::vector<std::uint32_t> assign_to_centres(const std::vector<GradedVertex>& vertices,
                                             const std::vector<GradedVertex>& centres, const FloatingCellShape& cell,
                                             AssignRule rule);

}  // namespace oocsimp
