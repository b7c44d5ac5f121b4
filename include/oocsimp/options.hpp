// oocsimp — the options of a run, as plain data: the clustering method and its
// settings, an exact target, levels of detail and where a file run writes.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

/// The largest grid: cell coordinates are packed into 21 bits per axis, so a grid
/// has at most 2^21 - 1 cells along each axis (CellSizing::grid).
constexpr std::uint32_t kMaxGridDivisions = (1u << 21) - 1;

enum class ClusterMethod {
  automatic,  ///< qem with a target (TargetOptions), floating without one: see resolved_method()
  uniform,    ///< Lindstrom's OoCS: uniform grid cells, quadric representatives
  floating,   ///< Low & Tan's floating cells on a tiled out-of-core grid
  /// Hua et al.: uniform cells split as an octree where the vertices' principal
  /// curvatures disagree, clusters the connected parts of each cell
  curvature,
  /// No clustering: quadric edge collapse, in tiles out of core on a large input, then
  /// whole (the quality reference)
  qem,
};

/// What refines the clustering's result down to an exact target (TargetOptions).
enum class RefineMethod {
  qem,   ///< quadric edge collapse from the clusters' summed quadrics (Garland & Shaffer's multiphase)
  none,  ///< the clustering alone, at a cell chosen for about the target
};

/// Floating cells: a cube of side `cell`, or a sphere of diameter `cell`.
enum class CellShape { cube, sphere };

/// Floating cells: which cell takes a vertex that lies in several.
enum class AssignRule {
  nearest,   ///< Low & Tan §3.2.3: the nearest centre (ties: the heavier)
  heaviest,  ///< Low & Tan §3.2: the heaviest centre (the first cell that took it)
};

/// Where a cluster's output vertex goes. Floating takes quadric, centre and mean;
/// curvature takes vertex and quadric.
enum class RepresentativeRule {
  quadric,  ///< minimiser of the cluster's summed vertex quadrics, kept in the cell
  centre,   ///< the centre vertex (Low & Tan)
  mean,     ///< the mean of the cluster's vertices
  /// the cluster's vertex whose curvatures match its cell's, with the least quadric
  /// error (Hua et al. §3.3 step 3 and §3.4)
  vertex,
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

/// How the cell size is chosen: at most one of the three is set (non-zero); when none
/// is, the ratio is kDefaultRatio.
struct CellSizing {
  double cell = 0;         ///< absolute cell side in model units
  std::uint32_t grid = 0;  ///< cells along the bounding box's longest axis
  double ratio = 0;        ///< approximate fraction of input triangles to keep, in (0, 1]
};

/// The ratio when no size is given: "simplify this" keeps about a tenth of the triangles.
constexpr double kDefaultRatio = 0.1;

/// The floating method's own options (SimplifyOptions::floating).
struct FloatingOptions {
  CellShape cell_shape = CellShape::cube;
  AssignRule assign = AssignRule::nearest;
  RepresentativeRule representative = RepresentativeRule::quadric;
  double tile_side = 0;  ///< tile side in model units; 0 = from the memory budget
  /// Keep the binned and graded tiles in temp_dir after the run, and reuse tiles kept
  /// by an earlier run on the same input (same path, inode, size and times, and the
  /// same content checksum) when the cell still fits in a tile, skipping binning and
  /// grading. Kept files that fail a check are recomputed, with a line in
  /// SimplifyStats::warnings.
  bool keep_temp = false;
  SpillCompression spill_compression = SpillCompression::automatic;
};

/// The curvature method's own options (SimplifyOptions::curvature): Hua et al. §3.4,
/// with the choices the paper leaves open in docs/curvature.md.
struct CurvatureClusterOptions {
  /// Of the integral invariants' ball or sphere, model units; 0 = 5 mean edge lengths
  /// (CurvatureOptions::radius).
  double radius = 0;
  bool sphere_neighbourhood = false;  ///< the sphere variant (eq. 15-18) instead of the ball (eq. 8-14)
  /// A cell of side s is split into eight, down to max_depth, when a child's principal
  /// curvatures (each from its faces' moments) differ from the cell's by more than
  /// tolerance / s (radians of turn across the cell); with the vertex representative a
  /// vertex matches its leaf when its own lie within tolerance / s of the leaf's means.
  double tolerance = 0.5;
  /// Splits of a grid cell, 0 to 6. 0 (the grid's cells cut into their connected
  /// parts) measured the least error at equal counts on the parts, the terrain and the
  /// scans (docs/curvature.md, "Quality with the cell-scale octree").
  std::uint32_t max_depth = 0;
  /// Where a cluster's output vertex goes: quadric, the minimiser of its quadric in its
  /// cell (the default: the lower RMS error of the two, docs/curvature.md), or vertex, the
  /// paper's matching input vertex.
  RepresentativeRule representative = RepresentativeRule::quadric;
  /// Side of the tiles the curvatures are estimated in (CurvatureOptions::tile_side);
  /// 0 = in memory when the mesh fits the budget. The output is the same either way.
  double tile_side = 0;
};

/// An exact size for the output: clustering (the method) down to about
/// intermediate_factor times the target, then quadric edge collapse down to it, from
/// the clusters' summed quadrics. Give at most one of triangles and ratio, and no
/// CellSizing with them.
struct TargetOptions {
  std::uint64_t triangles = 0;  ///< exactly this many output triangles (at least 4); 0 = not given
  double ratio = 0;             ///< exactly this fraction of the input's triangles, rounded, in (0, 1]; 0 = not given
  /// Stop before a collapse whose error (the placement's RMS distance to the planes it
  /// stands for) exceeds this, in model units; alone it lets the collapse go as far as
  /// it stays below. 0 = not given.
  double max_error = 0;
  /// max_error as a fraction of the input's bounding-box diagonal (0.001 for 0.1%), as
  /// meshoptimizer's target_error: the same figure means the same on a model in
  /// millimetres and one in metres. Give at most one of the two. 0 = not given.
  double max_error_of_diagonal = 0;
  RefineMethod refine = RefineMethod::qem;
  /// Phase 1 aims at this many times the target's triangles (see README, "Exact targets").
  double intermediate_factor = 4;
  bool given() const { return triangles != 0 || ratio != 0 || max_error != 0 || max_error_of_diagonal != 0; }
};

/// What the parts of a distributed run that run at once (MPI ranks) exchange while
/// they run: every part calls it with its bytes, at the same point of the run, and
/// gets every part's bytes, by part number. Throws when another part failed.
using PartExchange = std::function<std::vector<std::vector<unsigned char>>(const std::vector<unsigned char>&)>;
/// What the parts of a distributed run that run at once send one another: every part
/// calls it at the same point of the run with a message for each part (by part
/// number, its own included) and gets each part's message for it, by part number.
/// Throws when another part failed.
using PartDelivery =
    std::function<std::vector<std::vector<unsigned char>>(const std::vector<std::vector<unsigned char>>&)>;

/// How the parts of a distributed run that run at once reach one another (both
/// empty for parts that run apart): see PartOptions.
struct PartChannel {
  PartExchange exchange;
  PartDelivery deliver;  ///< optional with `exchange`
};

struct SimplifyOptions {
  CellSizing sizing;
  TargetOptions target;
  ClusterMethod method = ClusterMethod::automatic;
  FloatingOptions floating;           ///< read by the floating method only
  CurvatureClusterOptions curvature;  ///< read by the curvature method only
  std::uint64_t memory_budget = 0;    ///< bytes for the working set; 0 = a quarter of physical memory
  /// Whether memory_budget bounds the whole process's anonymous memory, what it held
  /// before the run included (the CLI: the process is the run), or only what the run
  /// adds to it (a program that holds memory of its own).
  bool budget_counts_process = false;
  /// PLY and OBJ: weld vertices at exactly the same position before clustering (STL
  /// input always is; see OpenOptions::weld).
  bool weld = false;
  unsigned threads = 0;                        ///< 0 = all cores
  std::string temp_dir;                        ///< empty = default_temp_dir()
  Precision precision = Precision::automatic;  ///< of the output positions
  /// Which vertex attributes are carried to the output (all by default).
  AttributeSelection attributes;
  /// Keep what clustering reduces below a triangle as thick edges and points
  /// (Low & Tan 1997 §3.3; SimplifiedMesh::primitives) instead of dropping it.
  bool thick_edges = false;
  /// Every vertex on the mesh's boundary (an edge of one face) stays where it is: open
  /// borders, holes and the seams of separately textured parts keep their exact
  /// outline. The edge collapse (ClusterMethod::qem, the default with a target) and
  /// floating cells hold it (each boundary vertex a cluster of its own); the uniform
  /// grid and curvature cells refuse it, and so does floating with a target refined
  /// by the collapse (which would hold phase 1's tears as boundary too).
  bool lock_boundary = false;
  /// Input vertices (by index, any order) that stay where they are: the edge collapse
  /// moves and removes none of them (like a boundary under lock_boundary), and the
  /// clustering methods make each a cluster of its own, its output vertex where it is
  /// (in a phase 1 before a target too). Marked features, seams, joints with other
  /// parts. A distributed run (PartOptions) refuses them.
  std::vector<std::uint64_t> locked_vertices;
  /// Progress reports, and cancellation when it returns false (see ProgressCallback).
  ProgressCallback progress;
  /// Floating: called between the phases of a run, whose tiles' buffers were just
  /// freed on several threads, so the process's allocator can give them back to the
  /// system (the CLI passes release_free_heap(), declared in oocsimp/oocsimp.hpp).
  /// Process-wide allocator settings are the program's business, not the library's.
  void (*release_memory)() = nullptr;
};

/// The method a run takes: options.method, or for ClusterMethod::automatic, qem when a
/// target is given (the exact count at the collapse's quality) and floating otherwise.
inline ClusterMethod resolved_method(const SimplifyOptions& options) {
  if (options.method != ClusterMethod::automatic) return options.method;
  return options.target.given() ? ClusterMethod::qem : ClusterMethod::floating;
}

/// Levels of detail from one run (Low & Tan 1997 §3.2.2 and §4).
struct LodOptions {
  std::uint32_t levels = 1;  ///< K, 1 to 16
  double factor = 2;         ///< F > 1: level k clusters at cell C F^k, C the first level's cell
};

/// Where simplify_file writes.
struct OutputOptions {
  std::string mesh;            ///< format and compression from the name; "-" is binary PLY on stdout
  std::string stats;           ///< the stats JSON; empty = none, "-" = stdout
  bool ascii = false;          ///< ascii PLY
  bool replace_input = false;  ///< the mesh may be the input (--force): replaced only after success
  bool normals = false;        ///< write per-vertex normals (add_vertex_normals)
};

}  // namespace oocsimp
