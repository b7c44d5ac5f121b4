// oocsimp — out-of-core simplification.
//
// simplify() streams a MeshInput once for its vertices and once for its triangles and
// returns the simplified mesh; the heap it uses grows with the number of occupied
// cells and output triangles, never with the input.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/grid_spec.hpp"
#include "oocsimp/mesh_input.hpp"

namespace oocsimp {

class ProgressReporter;

enum class ClusterMethod {
  uniform,   ///< Lindstrom's OoCS: uniform grid cells, quadric representatives
  floating,  ///< Low & Tan's floating cells on a tiled out-of-core grid
};

/// Floating cells: a cube of side `cell`, or a sphere of diameter `cell`.
enum class CellShape { cube, sphere };

/// Floating cells: which cell takes a vertex that lies in several.
enum class AssignRule {
  nearest,   ///< Low & Tan §3.2.3: the nearest centre (ties: the heavier)
  heaviest,  ///< Low & Tan §3.2: the heaviest centre (the first cell that took it)
};

/// Floating cells: where a cluster's output vertex goes.
enum class RepresentativeRule {
  quadric,  ///< minimiser of the cluster's summed vertex quadrics, kept in the cell
  centre,   ///< the centre vertex (Low & Tan)
  mean,     ///< the mean of the cluster's vertices
};

/// Floating: whether the triangle, stitch and kept-triangle spills under temp_dir are
/// compressed with zstd.
enum class SpillCompression {
  automatic,  ///< zstd when the raw spill would not fit in half the available memory
  zstd,       ///< always (slow disks: the spill shrinks to about half)
  none,       ///< never (the spill stays in the page cache, or the disk is fast)
};

/// The precision of the output positions.
enum class Precision {
  automatic,  ///< double when the input holds more than float precision (MeshInfo::double_precision), else float
  float32,    ///< float, whatever the input
  float64,    ///< double, whatever the input
};

/// How the cell size is chosen; exactly one of the three is set (> 0).
struct CellSizing {
  double cell = 0;            ///< absolute cell side in model units
  std::uint32_t grid = 0;     ///< cells along the bounding box's longest axis
  double ratio = 0;           ///< approximate fraction of input triangles to keep
};

struct SimplifyOptions {
  CellSizing sizing;
  ClusterMethod method = ClusterMethod::floating;
  CellShape cell_shape = CellShape::cube;                     ///< floating only
  AssignRule assign = AssignRule::nearest;                    ///< floating only
  RepresentativeRule representative = RepresentativeRule::quadric;  ///< floating only
  std::uint64_t memory_budget = 0;  ///< bytes for the working set; 0 = a quarter of physical memory
  double tile_side = 0;             ///< floating: tile side in model units; 0 = from the budget
  /// Floating: keep the binned and graded tiles in temp_dir after the run, and reuse
  /// tiles kept by an earlier run on the same input (same path, size and time) when
  /// the cell still fits in a tile, skipping binning and grading.
  bool keep_temp = false;
  SpillCompression spill_compression = SpillCompression::automatic;  ///< floating only
  unsigned threads = 0;             ///< 0 = all cores
  std::string temp_dir;             ///< empty = default_temp_dir()
  Precision precision = Precision::automatic;  ///< of the output positions
  ProgressReporter* progress = nullptr;
};

struct SimplifyStats {
  std::uint64_t input_vertices = 0;
  std::uint64_t input_triangles = 0;
  SkippedFaces skipped;                  ///< faces the input lost, by reason (see TriangleStream)
  std::uint64_t non_finite_vertices = 0;  ///< vertices with a NaN or infinite coordinate, ignored
  std::uint64_t first_non_finite_vertex = 0;     ///< the first of them by index
  std::string first_non_finite_position;         ///< where it is in the file ("byte N", "line N")
  std::uint64_t occupied_cells = 0;
  std::uint64_t output_vertices = 0;
  std::uint64_t output_triangles = 0;
  double cell_size = 0;
  std::uint32_t grid_dims[3] = {0, 0, 0};
  double seconds_open = 0;      ///< header, positions conversion/mapping, bounding box
  double seconds_vertices = 0;  ///< per-cell vertex means
  double seconds_faces = 0;     ///< per-cell quadrics and surviving triangles
  double seconds_solve = 0;     ///< representative vertices
  double seconds_write = 0;
  double seconds_total = 0;
  std::uint64_t tiles = 0;            ///< floating: occupied tiles
  std::uint64_t rounds = 0;           ///< floating: the first greedy and the sweeps of border decisions that changed something
  std::uint64_t spill_bytes = 0;      ///< floating: tile spill written to disk
  std::uint64_t spill_raw_bytes = 0;  ///< floating: the same before compression
  bool resumed = false;               ///< floating: reused tiles kept by an earlier run
  std::uint64_t peak_rss_bytes = 0;
  std::uint64_t peak_anon_bytes = 0;
};

struct SimplifiedMesh {
  std::vector<double> positions;         ///< 3 per vertex
  std::vector<std::uint32_t> triangles;  ///< 3 per face
  /// The precision chosen for the output: with f32 every position is a float value
  /// (rounded from the double the clustering computed), and writers store it as float.
  ScalarType precision = ScalarType::f32;
};

/// A quarter of physical memory: the default working-set budget.
std::uint64_t default_memory_budget();

/// Parses a byte size with an optional binary suffix: "256M", "2G", "512k", "1048576".
/// Throws UsageError.
std::uint64_t parse_byte_size(const std::string& text);

/// The grid `sizing` asks for over `input` (for `ratio`, estimated from a pass over
/// the vertices that counts occupied cells of a coarse grid and scales it as a
/// surface, i.e. with the square of the resolution). Throws UsageError.
GridSpec choose_grid(const MeshInput& input, const CellSizing& sizing, unsigned threads);

/// Clusters `input` by `options.method`: floating cells (the default; Low & Tan,
/// see src/cluster/floating_cells_design.md: cells centred on the heaviest vertices,
/// quadric representatives kept in their cell, tiles of the grid spilled to
/// `options.temp_dir` and sized from `options.memory_budget`) or a uniform grid
/// (OoCS: per cell the area-weighted plane quadrics of every triangle with a corner
/// in it and the mean of its vertices; the representative minimises the quadric
/// around that mean and stays in its cell). Either way a triangle survives when its
/// corners fall in three different clusters, each unordered triple once with the
/// orientation of its first occurrence in file order, and the result is
/// byte-identical for any thread count (and, for floating cells, any tiling).
SimplifiedMesh simplify(MeshInput& input, const SimplifyOptions& options, SimplifyStats* stats);

/// The precision `options` ask for on `input` (resolves Precision::automatic).
ScalarType output_precision(const MeshInput& input, Precision precision);

/// Opens `input_path`, simplifies it and writes `output_path` (format and compression
/// from its name, see format_for_path, which is checked before any work; ascii PLY or
/// STL when `ascii`) at the precision of the result. Fills `stats` when given.
void simplify_file(const std::string& input_path, const std::string& output_path, bool ascii,
                   const SimplifyOptions& options, SimplifyStats* stats);

/// `stats` as a JSON object (counts, seconds per phase, peak memory, input Mtri/s).
std::string stats_to_json(const SimplifyStats& stats);

/// One line (no newline) naming `input_path` and every count of skipped faces and
/// ignored vertices in `stats`, with the first non-finite vertex; empty when the input
/// lost nothing.
std::string skipped_input_summary(const std::string& input_path, const SimplifyStats& stats);

}  // namespace oocsimp
