// oocsimp — out-of-core simplification of huge triangle meshes. The library's one
// include: it gathers the headers below (each can be included alone); link
// oocsimp::oocsimp (find_package(oocsimp)).
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

#include "oocsimp/attributes.hpp"  // VertexAttribute, AttributeArray, AttributeValues, AttributeSelection
#include "oocsimp/curvature.hpp"   // estimate_curvatures, curvature_file
#include "oocsimp/enum_names.hpp"  // EnumNames: each option value's spelling
#include "oocsimp/error.hpp"       // UsageError, InputError, IoError, Cancelled
#include "oocsimp/formats.hpp"     // describe_mesh, write_mesh, format_for_path, add_vertex_normals
#include "oocsimp/geometry.hpp"    // Vec3d, Box3d
#include "oocsimp/hierarchy.hpp"   // build_hierarchy, extract_mesh: Velho's 4-k hierarchy
#include "oocsimp/mesh.hpp"        // MeshView, SimplifiedMesh, MeshInfo, MeshSummary, MeshFormat
#include "oocsimp/names.hpp"       // default_memory_budget, method_name, stats_to_json, version
#include "oocsimp/options.hpp"     // SimplifyOptions, TargetOptions, LodOptions, OutputOptions
#include "oocsimp/parts.hpp"       // simplify_part, merge_parts: distributed runs
#include "oocsimp/process.hpp"     // install_signal_cleanup, the allocator's settings
#include "oocsimp/progress.hpp"    // Progress, ProgressCallback
#include "oocsimp/simplify.hpp"    // simplify_file, simplify_mesh, the levels of detail
#include "oocsimp/stats.hpp"       // SimplifyStats
