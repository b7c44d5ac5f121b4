// The per-cell machinery of uniform-grid clustering (OoCS: Lindstrom, "Out-of-Core
// Simplification of Large Polygonal Models", SIGGRAPH 2000): the table of occupied
// cells, the two streaming passes that sum into it, the output vertices numbered by
// first use and each cell's representative. methods/uniform_clusterer.cpp runs them
// in order and checks the budget between them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <utility>
#include <memory>
#include <string>
#include <vector>

#include "cluster/quadric.hpp"
#include "cluster/triangle_set.hpp"
#include "runtime/memory_budget.hpp"
#include "grid/cell_map.hpp"
#include "grid/occupancy.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "io/output_mesh.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

struct VertexSum {
  Vec3d sum;
  double squares = 0;  // sum of |p|^2, for the width of a thick point (point_width)
  std::uint64_t n = 0;
};

/// What the two passes sum in an occupied cell.
struct CellRecord {
  Quadric q;
  VertexSum vertices;
};

/// Cells along the longest axis of `g`.
inline std::uint32_t grid_resolution(const GridSpec& g) { return std::max({g.dims[0], g.dims[1], g.dims[2]}); }

/// Bytes an occupied cell takes at least in its table (key, record and the two slots
/// of a half-full index).
constexpr std::uint64_t kCellEntryBytes = sizeof(std::uint64_t) + sizeof(CellRecord) + 2 * sizeof(std::uint32_t);

/// The uniform method's tables within --mem: the occupied cells and kept triangles in
/// their hash tables, the pipeline's per-chunk tables and, at the end, the output
/// arrays, on top of what the process held when the run began (its buffers, the
/// libraries). A run that would need more stops with a UsageError (exit 2) naming
/// --mem and what would fit, rather than exceed it.
class TableBudget {
 public:
  TableBudget(const MemoryBudget& budget, const GridSpec& grid, const OccupancyGrowth& occupancy,
              std::uint64_t vertices)
      : budget_(budget),
        held_(budget.held()),
        resolution_(grid_resolution(grid)),
        occupancy_(occupancy),
        vertices_(vertices) {}

  /// Throws UsageError unless tables of `bytes` fit next to what was held at the
  /// start; `what` names what they hold ("about 3000000 occupied cells").
  void check(std::uint64_t bytes, const std::string& what) const;
  /// Whether tables of `bytes` fit next to what was held at the start.
  bool fits(std::uint64_t bytes) const { return held_ + bytes <= budget_.bytes(); }

 private:
  std::uint32_t coarser_resolution(double cells) const;

  MemoryBudget budget_;
  std::uint64_t held_;  // when the run began: the tables come on top
  std::uint32_t resolution_;
  OccupancyGrowth occupancy_;
  std::uint64_t vertices_;
};

class VertexClusters;

/// The places that stay where they are (SimplifyOptions::locked_vertices): each is a
/// cluster of its own, whose key is kLockedKey | its rank (grid keys use 63 bits,
/// cluster keys 32) and whose cell is the point itself. A place is a position, not a
/// vertex: every vertex there is in it, so the other side of a texture seam or a
/// duplicated vertex at a locked one goes with it, and the surface does not open.
constexpr std::uint64_t kLockedKey = std::uint64_t(1) << 63;
class LockedVertices {
 public:
  LockedVertices() = default;
  /// The finite positions of `vertices` (each below positions.count).
  LockedVertices(const std::vector<std::uint64_t>& vertices, const PositionArray& positions, const GridSpec& grid);
  bool empty() const { return places_.empty(); }
  std::size_t size() const { return places_.size(); }
  /// The rank of the place at `relative` (a position relative to the grid's origin),
  /// or -1.
  std::int64_t rank_of(const Vec3d& relative) const;
  /// The place of rank `rank`, relative to the grid's origin.
  const Vec3d& place(std::uint64_t rank) const { return places_[std::size_t(rank)]; }
  /// The place of rank `rank` as the input has it: relative + origin can differ from
  /// it in the last bit of a double.
  const Vec3d& input_position(std::uint64_t rank) const { return input_[std::size_t(rank)]; }

 private:
  std::vector<Vec3d> places_;  // ascending by x, then y, then z
  std::vector<Vec3d> input_;   // the same places as the input has them
};

/// Where a vertex's cell is: the grid cell its position falls in (OoCS), or the
/// cluster VertexClusters gave it (the curvature method, cluster/curvature_cells.hpp),
/// whose cell is an octree leaf. The cell's box bounds the quadric solve and is the
/// frame of the thick edges' moments.
class CellKeys {
 public:
  CellKeys(const GridSpec& grid, const VertexClusters* clusters, const LockedVertices* locked)
      : grid_(grid), clusters_(clusters), locked_(locked && !locked->empty() ? locked : nullptr) {}
  std::uint64_t key(std::uint64_t vertex, const Vec3d& relative) const {
    if (locked_) {
      const std::int64_t rank = locked_->rank_of(relative);
      if (rank >= 0) return kLockedKey | std::uint64_t(rank);
    }
    return clusters_ ? cluster_of(vertex) : grid_.key_relative(relative);
  }
  /// The lower corner of cell `key`, relative to the grid's origin, and its side.
  Vec3d cell_min(std::uint64_t key) const;
  /// The input's position of the locked place of `key` (key & kLockedKey).
  const Vec3d& locked_position(std::uint64_t key) const { return locked_->input_position(key & ~kLockedKey); }
  double cell_side(std::uint64_t key) const;

 private:
  std::uint64_t cluster_of(std::uint64_t vertex) const;
  GridSpec grid_;
  const VertexClusters* clusters_;
  const LockedVertices* locked_;
};

class UniformAttributeSums;
struct ThickSums;

/// What a chunk of pass 1 sums: its cells in the order it met them, and their vertex
/// sums. Chunk j holds vertices [j 2^16, (j + 1) 2^16).
struct VertexChunkSums {
  std::vector<std::uint64_t> keys;
  std::vector<VertexSum> sums;
};

/// What a chunk of pass 2 sums: its cells in the order it met them, their quadrics,
/// its surviving triangles over those cells (3 local indices each) and, with
/// attributes, UniformAttributeSums::width() sums per cell. Chunk j is the j-th read
/// of the triangle stream.
struct FaceChunkSums {
  std::uint64_t triangles = 0;
  std::vector<std::uint64_t> keys;
  std::vector<Quadric> quadrics;
  std::vector<std::uint32_t> kept;
  std::vector<double> attribute_sums;
};

/// A part's share of the passes: the chunks it sums, each handed on with its number.
struct ChunkPart {
  std::uint32_t part = 0, parts = 1;  ///< chunk j belongs to part j mod parts
  std::function<void(std::uint64_t chunk, const VertexChunkSums&)> vertices;
  std::function<void(std::uint64_t chunk, const FaceChunkSums&)> faces;
};

/// The occupied cells of a grid and what OoCS sums in them, in the order the driver
/// calls the methods: add_vertices, start_face_sums, add_triangles, release_indexes,
/// number_output_vertices, solve_representatives. Each pass cuts its input into
/// fixed-size chunks that all threads process into private cell tables, merged in
/// input order, so every sum is taken in the same order for any thread count.
class UniformCells {
 public:
  /// No cells yet, on `grid`, carrying the vertex attributes of `attributes`; with
  /// `clusters`, a vertex's cell is its cluster there rather than its grid cell; a
  /// vertex of `locked` is a cell of its own, its representative where it is.
  UniformCells(const GridSpec& grid, const AttributeArray& attributes, const VertexClusters* clusters = nullptr,
               const LockedVertices* locked = nullptr);
  ~UniformCells();
  UniformCells(const UniformCells&) = delete;
  UniformCells& operator=(const UniformCells&) = delete;

  /// Pass 1 over the vertices: per cell, the sum and count of the vertex positions in
  /// it (the anchor of the quadric solve). Checks `budget` after each chunk's merge.
  void add_vertices(const PositionArray& positions, const TableBudget& budget, const ProgressCallback& progress);

  /// A distributed run's passes (docs/cluster.md). sum_part sums the chunks of both
  /// passes that `part` owns and hands them on, merging nothing; it returns the
  /// number of vertex and face chunks of the whole input. A merge then calls
  /// merge_vertex_chunk for every vertex chunk in order, start_face_sums, and
  /// merge_face_chunk for every face chunk in order: the same sums, in the same order,
  /// as add_vertices and add_triangles. No thick edges.
  std::pair<std::uint64_t, std::uint64_t> sum_part(MeshInput& input, const ChunkPart& part,
                                                   const ProgressCallback& progress) const;
  void merge_vertex_chunk(const VertexChunkSums& chunk);
  void merge_face_chunk(const FaceChunkSums& chunk);
  /// Between the passes, over the cells pass 1 found: the zeroed attribute sums and,
  /// with `thick_edges`, the sums of what collapses below a triangle.
  void start_face_sums(bool thick_edges);
  /// Pass 2 over the triangle stream of `input` (at its start): per cell, the sum of
  /// the area-weighted plane quadrics of every triangle with a corner in it (and the
  /// weighted sums of the corners' attribute values); triangles whose corners fall in
  /// three different cells survive, each unordered cell triple once; with thick edges
  /// (Low & Tan 1997 §3.3) the others add to their edge or point. Returns the
  /// triangles read.
  std::uint64_t add_triangles(MeshInput& input, const TableBudget& budget, const ProgressCallback& progress);
  /// The curvature method's representatives (RepresentativeRule::vertex), after
  /// add_triangles: one more pass over the vertices finds, per cell, the vertex that
  /// `matches` it with the least error under the cell's quadric (Hua et al. §3.3 step
  /// 3: of two vertices the one with the smaller error stays), ties to the lower index;
  /// a cell without a matching vertex takes its least-error vertex.
  /// solve_representatives then puts the output vertices there.
  using VertexMatch = bool (*)(const void* context, std::uint64_t vertex, std::uint64_t cell_key);
  void choose_vertices(const PositionArray& positions, VertexMatch matches, const void* context,
                       const ProgressCallback& progress);
  /// How many of the output vertices of `order` (number_output_vertices) are locked
  /// vertices: a locked vertex all of whose neighbours fall in one other cell has no
  /// triangle left, and is not among them.
  std::size_t locked_output_count(const std::vector<std::uint32_t>& order) const;
  /// Bytes choose_vertices holds until the solve.
  std::uint64_t chosen_bytes() const;
  /// Frees the hash indexes of the cells and the kept triangles: no lookups follow.
  void release_indexes();
  /// The surviving triangles into mesh->triangles, placed by `place` (and with thick
  /// edges the surviving edges and points into mesh->primitives) over output
  /// vertices: the cells they use, numbered by first use. Returns the cell of each
  /// output vertex; the kept triangles and thick sums are freed.
  std::vector<std::uint32_t> number_output_vertices(OutputMesh* mesh, const ArrayPlace& place);
  /// Each output vertex of `order` (positions and attribute values placed by `place`)
  /// at the point that minimises its cell's quadric
  /// (minimize_quadric, from the cell's vertex mean, kept in the cell), or at its cell's
  /// chosen vertex after choose_vertices, with its
  /// attribute values; with `quadrics`, also its cell's quadric (relative to the
  /// grid's origin).
  void solve_representatives(const std::vector<std::uint32_t>& order, OutputMesh* mesh, std::vector<Quadric>* quadrics,
                             const ArrayPlace& place);

  struct FaceChunk;  ///< pass 2's unit of work, private to uniform_cells.cpp

  /// Sizes, for the budget checks.
  std::size_t cell_count() const { return cells_.size(); }
  std::uint64_t cell_bytes() const { return cells_.bytes(); }
  std::size_t kept_count() const { return kept_.size(); }
  std::uint64_t kept_bytes() const { return kept_.bytes(); }
  std::size_t attribute_count() const;  ///< values per vertex
  std::size_t attribute_width() const;  ///< sums per cell
  std::uint64_t attribute_sum_bytes() const { return attribute_sums_.capacity() * sizeof(double); }

 private:
  void sum_face_chunk(const PositionArray& positions, FaceChunk& c) const;
  // A chunk's sums (FaceChunk or FaceChunkSums) added to the run's, in input order.
  template <class Chunk>
  void merge_faces(const Chunk& c, std::vector<std::uint32_t>* to_global);
  void sum_vertex_chunk(const PositionArray& positions, std::uint64_t begin, std::uint64_t end,
                        CellMap<VertexSum>* cells) const;
  std::vector<std::uint32_t> to_global_;  // merge_face_chunk's scratch

  struct ChosenVertex;

  GridSpec grid_;
  CellKeys keys_;
  std::unique_ptr<const UniformAttributeSums> attributes_;
  CellMap<CellRecord> cells_{1 << 16};
  TriangleSet kept_;
  std::vector<double> attribute_sums_;  // attribute_width() per cell, in the cells' table order
  std::unique_ptr<ThickSums> thick_;    // with thick edges
  std::vector<ChosenVertex> chosen_;    // per cell, after choose_vertices
};

}  // namespace oocsimp
