// oocsimp — out-of-core simplification of huge triangle meshes. The library's one
// header: include this, link oocsimp::oocsimp (find_package(oocsimp)).
//
// Files (simplify_file):
//   oocsimp::SimplifyOptions o;            // floating cells, --ratio 0.1, all attributes
//   o.sizing.grid = 512;
//   oocsimp::simplify_file("scan.ply", "small.ply", o);
// A mesh in memory (simplify_mesh):
//   oocsimp::MeshView v;
//   v.positions = xyz; v.vertex_count = n; v.indices = idx; v.triangle_count = t;
//   oocsimp::SimplifiedMesh m = oocsimp::simplify_mesh(v, o);
//
// Progress and cancelling: one callback (oocsimp/progress.hpp),
//   o.progress = [](const oocsimp::Progress& p) { return !user_pressed_stop(); };
//
// Every function throws oocsimp::UsageError for options it cannot honour (exit 2 in
// the CLI), InputError for bad input (3) and IoError for I/O and resource failures
// (4), each with a one-line message naming the option field at fault (see
// oocsimp/error.hpp), or Cancelled when the progress callback returned false.
//
// Beside the core, in targets of their own: oocsimp::generate (oocsimp/generate.hpp,
// synthetic test meshes), oocsimp::metrics (oocsimp/measure.hpp, surface distances),
// oocsimp::progress_ui (oocsimp/progress_reporter.hpp, a terminal progress bar),
// oocsimp::render (oocsimp/render.hpp, pictures) and oocsimp::lod (oocsimp/lod.hpp,
// choosing a level of detail).
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"  // VertexAttribute, AttributeArray, AttributeValues, AttributeSelection
#include "oocsimp/curvature.hpp"   // estimate_curvatures, curvature_file
#include "oocsimp/enum_names.hpp"  // EnumNames: each option value's spelling
#include "oocsimp/error.hpp"       // UsageError, InputError, IoError, Cancelled
#include "oocsimp/geometry.hpp"    // Vec3d, Box3d
#include "oocsimp/hierarchy.hpp"   // build_hierarchy, extract_mesh: Velho's 4-k hierarchy
#include "oocsimp/mesh.hpp"        // MeshView, SimplifiedMesh, MeshInfo, MeshSummary, MeshFormat
#include "oocsimp/options.hpp"     // SimplifyOptions, TargetOptions, LodOptions, OutputOptions
#include "oocsimp/progress.hpp"    // Progress, ProgressCallback
#include "oocsimp/stats.hpp"       // SimplifyStats

namespace oocsimp {

// --- Simplifying ---------------------------------------------------------------

/// Opens `input_path`, simplifies it and writes `outputs` (see OutputFile: regular files
/// through a temporary name and a rename, devices, FIFOs and stdout streamed). Before any
/// work it refuses (UsageError) an unwritable extension and destinations that are the
/// input (unless replace_input) or each other, and opens every destination; the stats
/// are committed before the mesh, so a failure leaves the mesh as it was. Fills `stats`
/// when given.
OOCSIMP_API void simplify_file(const std::string& input_path, const OutputOptions& outputs,
                               const SimplifyOptions& options, SimplifyStats* stats);
/// The same with only a mesh output; a PLY or STL is written binary (the overload
/// above names an ascii one in OutputOptions::ascii).
OOCSIMP_API void simplify_file(const std::string& input_path, const std::string& output_path,
                               const SimplifyOptions& options, SimplifyStats* stats = nullptr);

// --- Distributed runs (docs/cluster.md) -----------------------------------------

/// One part of a run spread over processes or machines.
struct PartOptions {
  std::uint32_t index = 0;  ///< this part, below count
  std::uint32_t count = 1;  ///< the parts of the run, each given the same input and options
  std::string work_dir;     ///< where the part's file goes; the folder merge_parts reads
  /// Parts that run at once (MPI ranks) may exchange what they decide while they run;
  /// floating cells then split their grading and border sweeps between the parts
  /// instead of each part running them whole. Empty for parts that run apart (job
  /// arrays).
  PartExchange exchange = nullptr;
  /// With `exchange`, a part's messages to each part (MPI's all-to-all), for what
  /// one part has and another needs (floating cells: the triangles each rank reads
  /// for the others' tiles). Optional: without it they go through `exchange`, each
  /// part then receiving every message.
  PartDelivery deliver = nullptr;
};

/// Throws UsageError naming the option when `options` ask for what a distributed run
/// cannot do yet: thick edges, locks.
OOCSIMP_API void check_distributed_options(const SimplifyOptions& options);

/// Part part.index of part.count of the run simplify_file(input_path, ..., options)
/// would make: the share of its work the part owns, left in
/// part.work_dir/part-I-of-K.oocpart (renamed into place when complete, so a failed
/// part leaves nothing) for merge_parts. Every part reads the whole input from a
/// shared path. Four runs spread for now (UsageError otherwise): options.method
/// uniform without a target, whose chunks the parts sum; a target with the edge
/// collapse (options.method qem, or automatic with a target), whose first out-of-core
/// pass the parts share; options.method floating, whose parts each accumulate their
/// own tiles (grading and sweeping only those with part.exchange); and
/// options.method curvature, whose parts each estimate the curvatures of their share
/// of the vertices (the merge builds the clusters). A target after one of those
/// clustering methods spreads its phase 1 (its first attempt) the same way; the
/// collapse runs in the merge. Fills the input counts of `stats` when given.
OOCSIMP_API void simplify_part(const std::string& input_path, const SimplifyOptions& options, const PartOptions& part,
                               SimplifyStats* stats = nullptr);

/// Finishes a distributed run from the part files in `work_dir`: writes `outputs` as
/// simplify_file would with the parts' input and options, the same bytes for any
/// part count and threads. From `options` only the memory budget, threads, temporary
/// folder and progress apply. Throws InputError (exit 3) naming a missing, damaged or
/// stale part (another input or other options), or an input changed since.
OOCSIMP_API void merge_parts(const std::string& work_dir, const OutputOptions& outputs, const SimplifyOptions& options,
                             SimplifyStats* stats = nullptr);

/// simplify_lods on the file at `input_path`, level k written to
/// lod_level_path(outputs.mesh, k) (outputs.normals and outputs.ascii apply; not
/// stdout, and outputs.stats is refused: the levels' figures are the caller's to
/// describe). Every level file is opened before the work and renamed into place only
/// when all levels are written. Fills `stats` with one entry per level.
OOCSIMP_API void simplify_lods_file(const std::string& input_path, const OutputOptions& outputs,
                                    const SimplifyOptions& options, const LodOptions& lods,
                                    std::vector<SimplifyStats>* stats);

/// Simplifies a mesh in memory: the mesh is read in place (with options.attributes), then simplified as a file would
/// be. With a budget the spills fit in (the default, a quarter of memory, for any mesh that fits in memory), no file is
/// written, and options.temp_dir is not touched. The result equals the one simplify_file gives for the same mesh stored
/// in a file.
OOCSIMP_API SimplifiedMesh simplify_mesh(const MeshView& mesh, const SimplifyOptions& options,
                                         SimplifyStats* stats = nullptr);

/// Simplifies the file at `input_path` into memory: what simplify_file writes, as a
/// SimplifiedMesh (input opened as simplify_file opens it; no normals added).
OOCSIMP_API SimplifiedMesh simplify_file_to_mesh(const std::string& input_path, const SimplifyOptions& options,
                                                 SimplifyStats* stats = nullptr);

/// Hears each level when it is done: its number, its mesh (which the sink may move
/// from) and its stats.
using LodSink = std::function<void(std::uint32_t level, SimplifiedMesh& mesh, const SimplifyStats& stats)>;

/// simplify_lods_file into memory: each level of the file at `input_path`, finest
/// first, handed to `sink` when it is done (the levels simplify_lods_file writes).
/// With a target, the levels that go on from level 0's collapse are all done before
/// level 0 is handed on.
OOCSIMP_API void simplify_file_to_lods(const std::string& input_path, const SimplifyOptions& options,
                                       const LodOptions& lods, const LodSink& sink);

// --- Reading -------------------------------------------------------------------

/// Opens the mesh file at `path` (temporary files in `temp_dir`; empty =
/// default_temp_dir()) and summarises it. The tallies of thick edges and points need a
/// pass over the faces, taken only when the file has some. Throws InputError for a
/// malformed file, IoError when it cannot be read.
/// `progress` hears its phases: "read positions", and "read edges and points" when the
/// faces are read through.
OOCSIMP_API MeshSummary describe_mesh(const std::string& path, const std::string& temp_dir = std::string(),
                                      const ProgressCallback& progress = {});

// --- Writing -------------------------------------------------------------------

/// The format implied by a path's extension, ignoring case and an optional ".zst"
/// (which compresses the stream): ".ply" (ascii PLY when `ascii`), ".obj", ".stl"
/// (ascii STL when `ascii`), ".off" or ".glb" (glTF 2.0 binary). Any other name throws
/// UsageError listing what can be written.
OOCSIMP_API MeshFormat format_for_path(const std::string& path, bool ascii);

/// Writes a triangle mesh given as flat arrays: `positions` holds 3 coordinates per
/// vertex, `triangles` 3 vertex indices per face. `precision` says how coordinates
/// are stored: PLY writes "property float x" or "property double x", the text formats
/// (OBJ, OFF, ascii STL) the shortest text that reads back as the same double (rounded
/// to float first for f32, so that a float output reads back as float input; ascii
/// PLY, which declares float, the shortest text of the float); binary STL holds
/// float32 whatever `precision` says, and so does glTF (.glb: POSITION, NORMAL and
/// COLOR_0 as float, unsigned int indices, one mesh of one primitive). PLY faces are
/// "uchar uint vertex_indices" lists; STL facet normals are the unit normals of the
/// triangles (0 for degenerate ones). A ".zst" suffix compresses the stream.
/// `attributes` (values per vertex, see AttributeValues) go where the format has room
/// for them (format_keeps_attributes).
/// A regular file is written under a temporary name
/// in its folder and renamed into place only when complete (on any failure it is
/// untouched and the temporary file removed); a device, FIFO or "-" is streamed into.
/// `primitives` (may be null) go to PLY as elements after the faces, "element edge"
/// (int vertex1, int vertex2, float thickness) and "element point" (int vertex, float
/// thickness), and to OBJ as "l a b" and "p a" lines, which have no room for the
/// thickness; STL, OFF and glTF drop them (format_keeps_primitives).
/// Throws IoError.
OOCSIMP_API void write_mesh(const std::string& path, const std::vector<double>& positions,
                            const std::vector<std::uint32_t>& triangles, MeshFormat format,
                            ScalarType precision = ScalarType::f32, const AttributeValues* attributes = nullptr,
                            const ThickPrimitives* primitives = nullptr);

/// Whether `format` can store vertex attributes: PLY every one (as "property TYPE
/// NAME" after x, y, z), OBJ the colours red, green and blue ("v x y z r g b", in
/// [0, 1]) and the normals nx, ny, nz ("vn", a line per vertex, which the faces name
/// as "f a//a b//b c//c"), glTF the colours (with alpha) and the normals; STL and OFF
/// none.
OOCSIMP_API bool format_keeps_attributes(MeshFormat format, const AttributeValues& attributes);

/// Whether `format` keeps materials (Materials): OBJ, as its mtllib line and usemtl
/// groups, and glTF, as one primitive per material naming it (the library in the
/// root's extras.mtllib). PLY keeps the material_K attributes as vertex properties but
/// no library reference; STL and OFF keep neither.
OOCSIMP_API bool format_keeps_materials(MeshFormat format);

/// Whether `format` stores thick edges and points with their thickness (PLY only; OBJ
/// keeps the edges and points without it, STL, OFF and glTF drop them).
OOCSIMP_API bool format_keeps_primitives(MeshFormat format);

/// The format `outputs.mesh` is written in: format_for_path, except that stdout ("-"),
/// a device, a FIFO or a socket whose name has no extension we write gets binary (or
/// ascii) PLY. Throws UsageError for a regular or new file whose name we cannot write.
OOCSIMP_API MeshFormat output_format(const OutputOptions& outputs);

/// Sets float attributes nx, ny, nz on every vertex: the unit sum of the normals of its
/// triangles, each weighted by its area (the cross product's length), so that a thin
/// sliver does not turn a vertex; (0, 0, 0) for a vertex of no area. Carried nx, ny, nz
/// are replaced (they were clusters' means); other attributes stay, nx, ny, nz last.
/// For thick edges (Low & Tan 1997 §3.3.2) a renderer computes a dynamic normal
/// instead: (V1 - C) x (V2 - C) x (V2 - V1), C the camera.
OOCSIMP_API void add_vertex_normals(SimplifiedMesh* mesh);

/// Where level k of `mesh_path` goes: ".lod<k>" before the extension ("out.ply" ->
/// "out.lod0.ply", "a/b.obj.zst" -> "a/b.lod0.obj.zst").
OOCSIMP_API std::string lod_level_path(const std::string& mesh_path, std::uint32_t level);
/// Where the description of the levels goes: "out.ply" -> "out.lods.json".
OOCSIMP_API std::string lod_description_path(const std::string& mesh_path);

// --- Options, names and reports --------------------------------------------------

/// A quarter of physical memory: the default working-set budget.
OOCSIMP_API std::uint64_t default_memory_budget();

/// The least memory budget a simplify run takes (32 MiB): below it a run cannot hold
/// its I/O buffers, one tile's spill buffers and the pipeline's chunks, whatever the
/// input.
OOCSIMP_API std::uint64_t minimum_memory_budget();

/// Parses a byte size with an optional binary suffix: "256M", "2G", "512k", "1048576".
/// Throws UsageError.
OOCSIMP_API std::uint64_t parse_byte_size(const std::string& text);

/// The default temporary directory: $TMPDIR if set and non-empty, else /tmp.
OOCSIMP_API std::string default_temp_dir();

/// A run as a JSON object: the version, the paths, the method and every option, counts,
/// seconds per phase, peak memory and input Mtri/s.
OOCSIMP_API std::string stats_to_json(const SimplifyStats& stats, const std::string& input_path,
                                      const OutputOptions& outputs, const SimplifyOptions& options);

/// The oocsimp version (the CMake project version).
OOCSIMP_API const char* version();

/// Every clustering method, the default first.
OOCSIMP_API std::vector<ClusterMethod> cluster_methods();

/// Option values as the command line spells them ("floating", "cube", "nearest", ...).
OOCSIMP_API const char* method_name(ClusterMethod m);
OOCSIMP_API const char* cell_shape_name(CellShape s);
OOCSIMP_API const char* assign_name(AssignRule a);
OOCSIMP_API const char* representative_name(RepresentativeRule r);
OOCSIMP_API const char* spill_compression_name(SpillCompression c);
OOCSIMP_API const char* refine_name(RefineMethod r);
OOCSIMP_API const char* precision_name(Precision p);

/// The tables those names come from, one per enum, each in the order the command line
/// lists the values (the default first).
OOCSIMP_API const EnumNames<ClusterMethod>& cluster_method_names();
OOCSIMP_API const EnumNames<CellShape>& cell_shape_names();
OOCSIMP_API const EnumNames<AssignRule>& assign_rule_names();
OOCSIMP_API const EnumNames<RepresentativeRule>& representative_rule_names();
OOCSIMP_API const EnumNames<SpillCompression>& spill_compression_names();
OOCSIMP_API const EnumNames<RefineMethod>& refine_method_names();
OOCSIMP_API const EnumNames<Precision>& precision_names();

/// One line (no newline) naming `input_path` and every count of skipped faces and
/// ignored vertices in `stats`, with the first non-finite vertex; empty when the input
/// lost nothing.
OOCSIMP_API std::string skipped_input_summary(const std::string& input_path, const SimplifyStats& stats);

// --- Process-wide settings for a program that runs oocsimp (the library sets none
// itself; the CLI calls these) -------------------------------------------------------

/// Fixes glibc's mmap threshold at 4 MiB: the floating method's tiles allocate and
/// free buffers of 0.1-10 MiB on every thread, and glibc's dynamic threshold would
/// soon serve even the largest from its per-thread arenas, which keep freed memory.
/// Call once at start-up, before other threads allocate.
OOCSIMP_API void tune_allocator_for_tiles();

/// Lets glibc keep up to a sixty-fourth of `budget_bytes` (at most 256 MiB) freed at
/// the top of each arena, where it gives back all above 128 KiB by default: the
/// collapse's tiles then reuse the buffers of the tile before them instead of
/// faulting fresh pages in. Budgets under 512 MiB keep glibc's default. Call once the
/// run's budget is known, before the run.
OOCSIMP_API void keep_freed_heap(std::uint64_t budget_bytes);

/// Gives the allocator's free memory back to the system (malloc_trim): freed memory
/// in the per-thread arenas otherwise counts against the budget. For
/// SimplifyOptions::release_memory.
OOCSIMP_API void release_free_heap();

/// Installs SIGINT, SIGTERM, SIGHUP and SIGQUIT handlers that delete all registered
/// temporary files and then terminate the process with the conventional status
/// (128 + signal), and ignores SIGXFSZ and SIGPIPE, so that a write beyond a file-size
/// limit (ulimit -f) fails with EFBIG, and one into a pipe or FIFO whose reader has gone
/// with EPIPE, and the run cleans up and exits 4 instead of being killed. A SIGBUS from reading a memory-mapped input
/// that shrank during the run (truncated by another process) deletes them too and exits 4 with "oocsimp: FILE: input
/// changed during the run"; any other SIGBUS is a crash after the clean-up.
OOCSIMP_API void install_signal_cleanup();

}  // namespace oocsimp
