// Per-cell patch moments (cluster/patch_moments.hpp) summed in one streaming pass over
// the faces, and the curvature of a cell read from its own and its 26 neighbours' sums:
// the cell-scale estimate behind curvature clustering (Hua et al. §3.4) and behind
// `oocsimp curvature --at-scale`.
#pragma once

#include <cstdint>
#include <functional>

#include "cluster/patch_moments.hpp"
#include "grid/cell_map.hpp"
#include "grid/occupancy.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/progress.hpp"
#include "runtime/memory_budget.hpp"

namespace oocsimp {

/// Cubic cells of side `side` from `origin`, `dims` along each axis (at most 2^21 - 1),
/// keyed as GridSpec::key_relative packs them (x | y << 21 | z << 42).
struct MomentLattice {
  Vec3d origin;
  double side = 1;
  std::uint64_t dims[3] = {1, 1, 1};

  static constexpr std::uint64_t kAxisMask = (std::uint64_t(1) << 21) - 1;

  /// The cell holding a point relative to the origin; clamped to the lattice.
  std::uint64_t key_relative(const Vec3d& d) const {
    return axis(d.x, 0) | (axis(d.y, 1) << 21) | (axis(d.z, 2) << 42);
  }
  /// The lower corner of cell `key`, relative to the origin.
  Vec3d corner(std::uint64_t key) const {
    return {side * double(key & kAxisMask), side * double((key >> 21) & kAxisMask),
            side * double((key >> 42) & kAxisMask)};
  }

 private:
  std::uint64_t axis(double d, int a) const {
    const double q = d / side;
    if (!(q > 0)) return 0;
    if (q >= double(dims[a])) return dims[a] - 1;
    return std::uint64_t(q);
  }
};

/// Bytes an occupied cell takes in a moments table, at least (key, sums, two slots).
constexpr std::uint64_t kMomentCellBytes = sizeof(std::uint64_t) + sizeof(PatchMoments) + 2 * sizeof(std::uint32_t);

/// Which faces a pass sums: called with the key of the face's cell.
using MomentFilter = std::function<bool(std::uint64_t key)>;
/// Called after each chunk with the table's bytes and the triangles read so far; may
/// throw (a budget that the table outgrows).
using MomentCheck = std::function<void(std::uint64_t bytes, std::uint64_t triangles_read)>;

/// One pass over the triangle stream of `input` (at its start; restarted after): each
/// face whose corners are finite adds its area, centroid and normal moments to the cell
/// of `lattice` its centroid falls in (relative to the cell's corner), where `keep`
/// (if set) accepts the cell. Chunks of faces are summed on all threads into tables of
/// their own and merged in input order, so the sums do not depend on the thread count.
/// Returns the triangles read.
std::uint64_t sum_cell_moments(MeshInput& input, const MomentLattice& lattice, const MomentFilter& keep,
                               CellMap<PatchMoments>* cells, const MomentCheck& check, const ProgressCallback& progress,
                               const char* phase_name);

/// Occupied cells of `lattice` over the faces of a mesh with `faces` faces and the
/// bounding box `bounds`, estimated before any face is read from how the vertices'
/// occupancy grows with the resolution (grid/occupancy.hpp), a quarter more for that
/// estimate's error, and at most `faces` and the lattice's cells.
std::uint64_t estimated_moment_cells(const OccupancyGrowth& occupancy, const Box3d& bounds,
                                     const MomentLattice& lattice, std::uint64_t faces);
/// Heap bytes of a table of `cells` cells' moments, at its largest (while it grows).
std::uint64_t moment_table_bytes(std::uint64_t cells);
/// Heap bytes a pass of sum_cell_moments holds when it fills a table of `cells` cells:
/// the table, and each pipeline token's faces and table of its own. With `worst`,
/// each token's chunk of faces falls in as many cells as it can (a soup, or faces
/// stored in no spatial order): what the pass holds at most. Without, each chunk's
/// faces fall in one cell: what it holds at least.
std::uint64_t moment_pass_bytes(std::uint64_t cells, bool worst);

/// The curvature of cell `key` from the sums of it and its 26 neighbours (a cube three
/// cells across, centred on it), as patch_curvature reads them.
PatchCurvature neighbourhood_curvature(const CellMap<PatchMoments>& cells, const MomentLattice& lattice,
                                       std::uint64_t key);

/// How `estimate_at_scale` found its values.
struct ScaleCurvatureCounts {
  std::uint64_t cells = 0;                         ///< occupied cells
  std::uint64_t slope = 0, folded = 0, empty = 0;  ///< cells by PatchFit (single counts as empty)
  std::uint64_t interpolated = 0, none = 0;        ///< vertices: from cells around them; none (0 and 0)
  std::uint64_t triangles = 0;                     ///< read from the stream
};

/// Each vertex's k1, k2 (k[2 v], k[2 v + 1]) at the scale of cells of side `side` over
/// the input's bounds: the neighbourhood curvature of the cells whose centres surround
/// it, interpolated trilinearly over those that have one. A vertex with none around it
/// gets 0 and 0. UsageError (exit 2) for a side too small for the lattice, or, before
/// any face is read, when the tables estimated (estimated_moment_cells) cannot fit
/// `budget` even at their least, naming the budget that holds them at their most; the
/// pass checks the real tables as they grow.
ScaleCurvatureCounts estimate_at_scale(MeshInput& input, double side, const MemoryBudget& budget,
                                       const ProgressCallback& progress, float* k);

}  // namespace oocsimp
