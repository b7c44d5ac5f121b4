// oocsimp — out-of-core simplification.
//
// simplify() streams a MeshInput once for its vertices and once for its triangles and
// returns the simplified mesh; the heap it uses grows with the number of occupied
// cells and output triangles, never with the input.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "oocsimp/enum_names.hpp"
#include "oocsimp/grid_spec.hpp"
#include "oocsimp/mesh_input.hpp"
#include "oocsimp/mesh_writer.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

enum class ClusterMethod {
  uniform,   ///< Lindstrom's OoCS: uniform grid cells, quadric representatives
  floating,  ///< Low & Tan's floating cells on a tiled out-of-core grid
  qem,       ///< no clustering: quadric edge collapse of the whole input in memory (the quality reference)
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

/// How the cell size is chosen: at most one of the three is set (non-zero); when none
/// is, the ratio is kDefaultRatio.
struct CellSizing {
  double cell = 0;         ///< absolute cell side in model units
  std::uint32_t grid = 0;  ///< cells along the bounding box's longest axis
  double ratio = 0;        ///< approximate fraction of input triangles to keep, in (0, 1]
};

/// The most cells a grid has along an axis (CellSizing::grid): cell coordinates are
/// packed into 21 bits per axis.
constexpr std::uint32_t kMaxGridDivisions = (1u << 21) - 1;

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
  RefineMethod refine = RefineMethod::qem;
  /// Phase 1 aims at this many times the target's triangles (see README, "Exact targets").
  double intermediate_factor = 4;
  bool given() const { return triangles != 0 || ratio != 0 || max_error != 0; }
};

struct SimplifyOptions {
  CellSizing sizing;
  TargetOptions target;
  ClusterMethod method = ClusterMethod::floating;
  FloatingOptions floating;         ///< read by the floating method only
  std::uint64_t memory_budget = 0;  ///< bytes for the working set; 0 = a quarter of physical memory
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
  /// Progress reports, and cancellation when it returns false (see ProgressCallback).
  ProgressCallback progress;
  /// Floating: called between the phases of a run, whose tiles' buffers were just
  /// freed on several threads, so the process's allocator can give them back to the
  /// system (the CLI passes release_free_heap(), see oocsimp/memory_tuning.hpp).
  /// Process-wide allocator settings are the program's business, not the library's.
  void (*release_memory)() = nullptr;
};

/// One timed phase of a run.
struct PhaseTime {
  std::string name;
  double seconds = 0;
};

struct SimplifyStats {
  std::uint64_t input_vertices = 0;     ///< after welding, when welded
  std::uint64_t unwelded_vertices = 0;  ///< vertices as stored, when welded (STL, --weld); 0: not welded
  std::uint64_t input_triangles = 0;
  SkippedFaces skipped;                       ///< faces the input lost, by reason (see TriangleStream)
  std::uint64_t non_finite_vertices = 0;      ///< vertices with a NaN or infinite coordinate, ignored
  std::uint64_t first_non_finite_vertex = 0;  ///< the first of them by index
  std::string first_non_finite_position;      ///< where it is in the file ("byte N", "line N")
  std::uint64_t occupied_cells = 0;
  std::uint64_t output_vertices = 0;
  std::uint64_t output_triangles = 0;
  std::uint64_t output_edges = 0, output_points = 0;  ///< thick edges and points (SimplifyOptions::thick_edges)
  /// simplify_lods: the level's cell for choosing a level (lod-select): the clustering
  /// cell, or with a target sqrt(2 A / T) for an output of area A and T triangles, the
  /// cell of a grid that leaves about T triangles on such a surface (two per cell).
  double lod_cell = 0;
  double cell_size = 0;
  std::uint32_t grid_dims[3] = {0, 0, 0};
  /// Wall seconds of each phase in order: "open" (header, positions, bounding box), the
  /// method's own phases (uniform: vertices, faces, solve; floating: bin, grade, rounds,
  /// cluster, stitch, assemble), then "write".
  std::vector<PhaseTime> phases;
  double seconds_total = 0;
  std::uint64_t tiles = 0;   ///< floating: occupied tiles
  std::uint64_t rounds = 0;  ///< floating: the first greedy and the sweeps of border decisions that changed something
  std::uint64_t spill_bytes = 0;            ///< floating: tile spill written to disk
  std::uint64_t spill_raw_bytes = 0;        ///< floating: the same before compression
  std::uint64_t spill_bytes_in_memory = 0;  ///< floating: spill records held in memory instead (within the budget)
  bool resumed = false;                     ///< floating: reused tiles kept by an earlier run
  std::uint64_t largest_tile_records = 0;   ///< floating: triangle records of the fullest tile (its working set)
  /// Floating, per sweep of border decisions after the first greedy (the last one
  /// only confirms): the tiles looked at (a neighbour's border changed since they
  /// last ran) and, of those, the tiles re-run (their external centres had changed).
  struct SweepCount {
    std::uint64_t looked_at = 0, rerun = 0;
  };
  std::vector<SweepCount> sweeps;
  /// Things the run did differently from what was asked, one line each ("FILE: what
  /// happened; what was done instead"), e.g. kept tiles that did not match the input
  /// and were recomputed. The CLI prints them on stderr.
  std::vector<std::string> warnings;
  /// The vertex attributes carried to the output, in its order.
  std::vector<VertexAttribute> attributes;
  std::uint64_t peak_rss_bytes = 0;
  std::uint64_t peak_anon_bytes = 0;
  /// With a target (TargetOptions) or --method qem: the triangles phase 1 handed on
  /// (the input's for qem), the collapses taken, the largest collapse cost (area x
  /// distance^2) and error (model units), and whether the target was missed (no valid
  /// collapse left, max_error reached, or a closed surface asked for an odd count).
  std::uint64_t intermediate_triangles = 0;
  /// Peak anonymous memory of phase 1 (the clustering, which --mem bounds) and of
  /// phase 2 (the collapse, which holds the intermediate whole), in bytes; 0 for a
  /// phase that did not run.
  std::uint64_t phase1_peak_anon_bytes = 0;
  std::uint64_t phase2_peak_anon_bytes = 0;
  std::uint64_t collapses = 0;
  double largest_collapse_cost = 0;
  double largest_collapse_error = 0;
  bool target_missed = false;
};

struct SimplifiedMesh {
  std::vector<double> positions;         ///< 3 per vertex
  std::vector<std::uint32_t> triangles;  ///< 3 per face
  /// The carried vertex attributes (MeshInput::attributes): per output vertex the
  /// area-weighted mean of its cluster's values (src/cluster/attribute_sums.hpp).
  AttributeValues attributes;
  /// Thick edges and points (SimplifyOptions::thick_edges); their vertices follow
  /// the triangles' in the numbering.
  ThickPrimitives primitives;
  /// The precision chosen for the output: with f32 every position is a float value
  /// (rounded from the double the clustering computed), and writers store it as float.
  ScalarType precision = ScalarType::f32;
};

/// Sets float attributes nx, ny, nz on every vertex: the unit sum of the normals of its
/// triangles, each weighted by its area (the cross product's length), so that a thin
/// sliver does not turn a vertex; (0, 0, 0) for a vertex of no area. Carried nx, ny, nz
/// are replaced (they were clusters' means); other attributes stay, nx, ny, nz last.
/// For thick edges (Low & Tan 1997 §3.3.2) a renderer computes a dynamic normal
/// instead: (V1 - C) x (V2 - C) x (V2 - V1), C the camera.
void add_vertex_normals(SimplifiedMesh* mesh);

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

/// Levels of detail from one run (Low & Tan 1997 §3.2.2 and §4).
struct LodOptions {
  std::uint32_t levels = 1;  ///< K, 1 to 16
  double factor = 2;         ///< F > 1: level k clusters at cell C F^k, C the first level's cell
};

/// Hears each level when it is done: its number, its mesh (which the sink may move
/// from) and its stats.
using LodSink = std::function<void(std::uint32_t level, SimplifiedMesh& mesh, const SimplifyStats& stats)>;

/// simplify() at K levels, finest first. Level 0 is what simplify() gives for
/// `options`; level k clusters at cell C F^k (C the cell of level 0), and equals
/// simplify() with options.sizing.cell = C F^k. Floating cells bin and grade the
/// input once for all levels (binning and grading do not depend on the cell; the
/// tiles fit the coarsest); the uniform grid, which neither bins nor grades, reads
/// the input twice per level. With a target (triangles or ratio, not max_error),
/// level k aims at the target halved k times, each a run of its own (its
/// SimplifyStats::lod_cell an equivalent cell). Throws
/// UsageError for a bad `lods`, `qem` or options.target.max_error.
void simplify_lods(MeshInput& input, const SimplifyOptions& options, const LodOptions& lods, const LodSink& sink);

/// Where level k of `mesh_path` goes: ".lod<k>" before the extension ("out.ply" ->
/// "out.lod0.ply", "a/b.obj.zst" -> "a/b.lod0.obj.zst").
std::string lod_level_path(const std::string& mesh_path, std::uint32_t level);
/// Where the description of the levels goes: "out.ply" -> "out.lods.json".
std::string lod_description_path(const std::string& mesh_path);

/// The precision `options` ask for on `input` (resolves Precision::automatic).
ScalarType output_precision(const MeshInput& input, Precision precision);

/// Where simplify_file writes.
struct OutputOptions {
  std::string mesh;            ///< format and compression from the name; "-" is binary PLY on stdout
  std::string stats;           ///< the stats JSON; empty = none, "-" = stdout
  bool ascii = false;          ///< ascii PLY
  bool replace_input = false;  ///< the mesh may be the input (--force): replaced only after success
  bool normals = false;        ///< write per-vertex normals (add_vertex_normals)
};

/// Opens `input_path`, simplifies it and writes `outputs` (see OutputFile: regular files
/// through a temporary name and a rename, devices, FIFOs and stdout streamed). Before any
/// work it refuses (UsageError) an unwritable extension and destinations that are the
/// input (unless replace_input) or each other, and opens every destination; the stats
/// are committed before the mesh, so a failure leaves the mesh as it was. Fills `stats`
/// when given.
void simplify_file(const std::string& input_path, const OutputOptions& outputs, const SimplifyOptions& options,
                   SimplifyStats* stats);
/// The same with only a mesh output.
void simplify_file(const std::string& input_path, const std::string& output_path, bool ascii,
                   const SimplifyOptions& options, SimplifyStats* stats);

/// simplify_lods on the file at `input_path`, level k written to
/// lod_level_path(outputs.mesh, k) (outputs.normals and outputs.ascii apply; not
/// stdout, and outputs.stats is refused: the levels' figures are the caller's to
/// describe). Every level file is opened before the work and renamed into place only
/// when all levels are written. Fills `stats` with one entry per level.
void simplify_lods_file(const std::string& input_path, const OutputOptions& outputs, const SimplifyOptions& options,
                        const LodOptions& lods, std::vector<SimplifyStats>* stats);

/// The format `outputs.mesh` is written in: format_for_path, except that stdout ("-"),
/// a device, a FIFO or a socket whose name has no extension we write gets binary (or
/// ascii) PLY. Throws UsageError for a regular or new file whose name we cannot write.
MeshFormat output_format(const OutputOptions& outputs);

/// A run as a JSON object: the version, the paths, the method and every option, counts,
/// seconds per phase, peak memory and input Mtri/s.
std::string stats_to_json(const SimplifyStats& stats, const std::string& input_path, const OutputOptions& outputs,
                          const SimplifyOptions& options);

/// The oocsimp version (the CMake project version).
const char* version();

/// Every clustering method, the default first.
std::vector<ClusterMethod> cluster_methods();

/// Option values as the command line spells them ("floating", "cube", "nearest", ...).
const char* method_name(ClusterMethod m);
const char* cell_shape_name(CellShape s);
const char* assign_name(AssignRule a);
const char* representative_name(RepresentativeRule r);
const char* spill_compression_name(SpillCompression c);
const char* refine_name(RefineMethod r);
const char* precision_name(Precision p);

/// The tables those names come from, one per enum, each in the order the command line
/// lists the values (the default first).
const EnumNames<ClusterMethod>& cluster_method_names();
const EnumNames<CellShape>& cell_shape_names();
const EnumNames<AssignRule>& assign_rule_names();
const EnumNames<RepresentativeRule>& representative_rule_names();
const EnumNames<SpillCompression>& spill_compression_names();
const EnumNames<RefineMethod>& refine_method_names();
const EnumNames<Precision>& precision_names();

/// One line (no newline) naming `input_path` and every count of skipped faces and
/// ignored vertices in `stats`, with the first non-finite vertex; empty when the input
/// lost nothing.
std::string skipped_input_summary(const std::string& input_path, const SimplifyStats& stats);

}  // namespace oocsimp
