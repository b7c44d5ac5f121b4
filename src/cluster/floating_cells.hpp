// Floating-cell clustering, Low & Tan 1997 §3.2 and §4, on one tile.
// See docs/design.md for how tiles combine into the exact global result.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "cluster/vertex_grading.hpp"
#include "common/vec3_math.hpp"
#include "grid/grid_coord.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

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
    const Vec3d d = p - c;
    if (shape == CellShape::cube) return std::abs(d.x) <= h && std::abs(d.y) <= h && std::abs(d.z) <= h;
    return squared_length(d) <= h * h;
  }
  /// Whether the cell of `centre` holds p: a locked centre's cell is the point where
  /// it is, so it is a cluster of its own (with the vertices at its very position).
  bool holds(const GradedVertex& centre, const Vec3d& p) const {
    if (is_locked(centre)) return p.x == centre.p.x && p.y == centre.p.y && p.z == centre.p.z;
    return contains(centre.p, p);
  }
};

/// The cubes (side `size`, anchored at the origin: §4's lookup grid) that the cell
/// around p, [p - size/2, p + size/2] on each axis, overlaps: at most 2 per axis,
/// from *lo to *hi. Widened by a relative epsilon so rounding in the division never
/// drops a candidate; FloatingCellShape::contains decides exactly.
inline void cubes_near(const Vec3d& p, double size, GridCoord* lo, GridCoord* hi) {
  double h = 0.5 * size * (1 + 1e-12);
  *lo = GridCoord::of(p - Vec3d{h, h, h}, size);
  *hi = GridCoord::of(p + Vec3d{h, h, h}, size);
}

/// The centres among `sorted` (vertices in `precedes` order) chosen by the §3.2
/// greedy: a vertex becomes a centre unless a centre heavier than it holds it in its
/// cell. `external` are centres owned by other tiles; each covers only vertices it
/// precedes. Uses §4's lookup: centres are filed by the grid cell (side `size`,
/// anchored at the origin) holding them, and a vertex checks the 2x2x2 grid cells
/// its own cell overlaps, so the pass is linear after the sort.
std::vector<GradedVertex> choose_centres(const std::vector<GradedVertex>& sorted,
                                         const std::vector<GradedVertex>& external, const FloatingCellShape& cell);

/// A tile's graded vertices laid out for the rounds in one block of bytes (in the
/// clusterer, a BlockStore block): in `precedes` order, filed by lookup cube
/// (§4's grid: cubes of the cell size, anchored at the origin), with their current
/// decisions. Built once per tile; re-runs read it and update the decisions in place,
/// so a round costs what its changes reach, not the whole tile.
class TileVertexBlock {
 public:
  /// The bytes of a block for `sorted` (in `precedes` order) whose centres are
  /// `centres` (a subsequence of `sorted`). Throws std::logic_error for vertices
  /// spanning more than 2^21 cells on an axis.
  static std::vector<unsigned char> build(const std::vector<GradedVertex>& sorted,
                                          const std::vector<GradedVertex>& centres, double cell_size);
  /// A view of the block at `block`, made by build() (8-byte aligned).
  explicit TileVertexBlock(unsigned char* block);

  std::size_t size() const { return count_; }
  const GradedVertex& vertex(std::size_t i) const { return vertices_[i]; }
  const GradedVertex* vertices() const { return vertices_; }
  /// The vertices grouped by lookup cube: the j-th is vertex(filed(j)). Visiting
  /// them so keeps lookups around neighbouring points together.
  std::uint32_t filed(std::size_t j) const { return by_cube_[j]; }
  bool is_centre(std::size_t i) const { return is_centre_[i] != 0; }
  /// Marks vertex i a centre or not, and files or unfiles it in its cube's centres.
  void set_centre(std::size_t i, bool c);
  /// The centres, in `precedes` order.
  std::vector<GradedVertex> centres() const;
  /// Calls f(i) for the vertices i whose cube the cell around p overlaps until f
  /// returns true; returns whether one did. With `before`, only vertices i < before
  /// (those that precede vertex `before`) are visited: a cube lists its vertices in
  /// priority order, so its scan stops at the first later one.
  template <class F>
  bool any_near(const Vec3d& p, F&& f, std::uint32_t before = ~std::uint32_t(0)) const {
    return scan_near(p, cube_starts_, by_cube_, nullptr, f, before);
  }
  /// any_near over the centres only: each cube keeps its current centres (in
  /// priority order), so a check for a covering centre does not walk the cube's
  /// other vertices, of which a dense part of a mesh has thousands per cell.
  template <class F>
  bool any_centre_near(const Vec3d& p, F&& f, std::uint32_t before = ~std::uint32_t(0)) const {
    return scan_near(p, cube_starts_, centre_by_cube_, centres_in_cube_, f, before);
  }

 private:
  // Walks, for the cubes near p, lists[starts[c] ..] (of length counts[c], or up
  // to starts[c + 1] without counts) while entries precede `before`.
  template <class F>
  bool scan_near(const Vec3d& p, const std::uint32_t* starts, const std::uint32_t* lists, const std::uint32_t* counts,
                 F&& f, std::uint32_t before) const {
    GridCoord lo, hi;
    cubes_near(p, cell_size_, &lo, &hi);
    auto from = [](std::int64_t c, std::int64_t o) { return std::max(c - o, std::int64_t(0)); };
    auto to = [](std::int64_t c, std::int64_t o) { return std::min(c - o, kKeyRange - 1); };
    for (std::int64_t x = from(lo.x, origin_[0]); x <= to(hi.x, origin_[0]); ++x)
      for (std::int64_t y = from(lo.y, origin_[1]); y <= to(hi.y, origin_[1]); ++y)
        for (std::int64_t z = from(lo.z, origin_[2]); z <= to(hi.z, origin_[2]); ++z) {
          std::size_t c = cube_at(x, y, z);
          if (c == kNoCube) continue;
          const std::uint32_t end = counts ? starts[c] + counts[c] : starts[c + 1];
          for (std::uint32_t j = starts[c]; j < end && lists[j] < before; ++j)
            if (f(lists[j])) return true;
        }
    return false;
  }

  struct Header;
  explicit TileVertexBlock(const Header& h);  // sizes only, for build()
  void lay_out(unsigned char* base, const Header& h);
  // Cube keys: coordinates relative to the block's origin cube, 21 bits per axis.
  static constexpr int kKeyBits = 21;
  static constexpr std::int64_t kKeyRange = std::int64_t(1) << kKeyBits;
  static std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
    return std::uint64_t(x) << (2 * kKeyBits) | std::uint64_t(y) << kKeyBits | std::uint64_t(z);
  }
  static constexpr std::size_t kNoCube = ~std::size_t(0);
  // The position of cube (x, y, z) (relative to the origin cube) among the occupied
  // ones, or kNoCube: from the dense table over the block's box of cubes when it
  // has one, else by binary search over the keys.
  std::size_t cube_at(std::int64_t x, std::int64_t y, std::int64_t z) const {
    if (dense_cubes_) {
      if (x >= dims_[0] || y >= dims_[1] || z >= dims_[2]) return kNoCube;
      std::uint32_t c = dense_cubes_[std::size_t((x * dims_[1] + y) * dims_[2] + z)];
      return c == ~std::uint32_t(0) ? kNoCube : std::size_t(c);
    }
    std::uint64_t key = pack(x, y, z);
    const std::uint64_t* k = std::lower_bound(cube_keys_, cube_keys_ + cubes_, key);
    return k == cube_keys_ + cubes_ || *k != key ? kNoCube : std::size_t(k - cube_keys_);
  }

  std::size_t count_ = 0, cubes_ = 0, bytes_ = 0;
  std::int64_t origin_[3] = {0, 0, 0};
  std::int64_t dims_[3] = {0, 0, 0};  // the box of cubes, when dense_cubes_ is laid out
  double cell_size_ = 1;
  GradedVertex* vertices_ = nullptr;
  std::uint64_t* cube_keys_ = nullptr;        // occupied cubes, sorted
  std::uint32_t* cube_starts_ = nullptr;      // per cube, its first entry in by_cube_
  std::uint32_t* dense_cubes_ = nullptr;      // per cube of the box, its position in cube_keys_ (or ~0)
  std::uint32_t* by_cube_ = nullptr;          // vertex positions grouped by cube
  std::uint32_t* centre_by_cube_ = nullptr;   // per cube, from cube_starts_[c]: its centres, ascending
  std::uint32_t* centres_in_cube_ = nullptr;  // per cube, how many
  char* is_centre_ = nullptr;
};

/// The greedy again, in place, after the external centres of `block`'s tile
/// changed from `old_external` to `new_external` (both in `precedes` order): only
/// vertices near a change are re-decided. A vertex whose cell holds no changed item
/// (an external centre added or removed, or a vertex whose decision changed earlier
/// in the pass) keeps its decision, because the heavier centres around it are the
/// same. Afterwards the block holds what choose_centres gives with `new_external`;
/// the time is proportional to what the changes reach. Returns whether any
/// decision changed.
bool rechoose_centres(TileVertexBlock& block, const std::vector<GradedVertex>& old_external,
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
