// oocsimp — out-of-core simplification of huge triangle meshes. The library's one
// header: include this, link oocsimp::oocsimp (find_package(oocsimp)).
//
// Files (simplify_file):
//   oocsimp::SimplifyOptions o;            // floating cells, --ratio 0.1, all attributes
//   o.sizing.grid = 512;
//   oocsimp::simplify_file("scan.ply", "small.ply", false, o, nullptr);
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
// synthetic test meshes), oocsimp::metrics (oocsimp/measure.hpp, surface distances)
// and oocsimp::progress_ui (oocsimp/progress_reporter.hpp, a terminal progress bar).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"   // VertexAttribute, AttributeArray, AttributeValues, AttributeSelection
#include "oocsimp/error.hpp"        // UsageError, InputError, IoError, Cancelled
#include "oocsimp/geometry.hpp"     // Vec3d, Box3d
#include "oocsimp/mesh_input.hpp"   // open_mesh_input: PLY, OBJ, STL (optionally .zst) as streams
#include "oocsimp/mesh_writer.hpp"  // write_mesh: PLY, OBJ, STL, OFF
#include "oocsimp/progress.hpp"     // Progress, ProgressCallback
#include "oocsimp/simplify.hpp"     // SimplifyOptions, FloatingOptions, simplify, simplify_file, SimplifiedMesh

// Process-wide settings, for a program's main (the library sets none itself).
#include "oocsimp/memory_tuning.hpp"  // tune_allocator_for_tiles, release_free_heap
#include "oocsimp/signals.hpp"        // install_signal_cleanup: temporary files go on SIGINT, SIGTERM, ...

namespace oocsimp {

/// A triangle mesh in the caller's memory, which must outlive the call it is given to.
struct MeshView {
  /// Vertex i's x, y, z: three values of `position_type` at positions + i*position_stride.
  const void* positions = nullptr;
  ScalarType position_type = ScalarType::f32;
  std::size_t position_stride = 0;  ///< bytes from one vertex to the next; 0 = three packed values
  std::uint64_t vertex_count = 0;
  /// Three vertex indices (below vertex_count) per triangle.
  const std::uint32_t* indices = nullptr;
  std::uint64_t triangle_count = 0;
  /// Optional per-vertex attributes (AttributeArray::add: name, type, first value,
  /// stride), carried as for a file; their count is vertex_count, their ranges are
  /// computed. Left empty: positions only.
  AttributeArray attributes;
};

/// Opens a mesh in memory as a MeshInput for simplify() (no file, no copy: the views
/// point into the caller's arrays), with the attributes `selection` names (as
/// --attributes does). Throws UsageError for null arrays with non-zero counts, or a
/// selection naming an attribute the view lacks; an index out of range is an
/// InputError when the triangles are read.
MeshInput open_mesh_view(const MeshView& mesh, const AttributeSelection& selection = {});

/// Simplifies a mesh in memory: open_mesh_view (with options.attributes), then simplify(). With a budget the
/// spills fit in (the default, a quarter of memory, for any mesh that fits in memory),
/// no file is written, and options.temp_dir is not touched. The result equals the one
/// simplify_file gives for the same mesh stored in a file.
SimplifiedMesh simplify_mesh(const MeshView& mesh, const SimplifyOptions& options, SimplifyStats* stats = nullptr);

/// The thick edges or the points of a mesh file (LinePrimitive): how many, and the
/// least, the largest and the sum of their thicknesses (0 where the file gives none).
struct PrimitiveTally {
  std::uint64_t count = 0;
  double least = HUGE_VAL, most = 0, sum = 0;
};

/// What `oocsimp info` prints about a mesh file.
struct MeshSummary {
  MeshInfo info;
  /// The vertex attributes a run carries by default (all), with their ranges.
  std::vector<VertexAttribute> attributes;
  PrimitiveTally edges, points;
};

/// Opens the mesh file at `path` (temporary files in `temp_dir`; empty =
/// default_temp_dir()) and summarises it. The tallies of thick edges and points need a
/// pass over the faces, taken only when the file has some. Throws InputError for a
/// malformed file, IoError when it cannot be read.
MeshSummary describe_mesh(const std::string& path, const std::string& temp_dir = std::string());

}  // namespace oocsimp
