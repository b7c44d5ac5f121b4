// Formats and I/O: summarising a mesh file, writing a mesh, what each format keeps,
// vertex normals for an output and where levels of detail go.
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"
#include "oocsimp/mesh.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

/// Opens the mesh file at `path` (temporary files in `temp_dir`; empty =
/// default_temp_dir()) and summarises it. The tallies of thick edges and points need a
/// pass over the faces, taken only when the file has some. Throws InputError for a
/// malformed file, IoError when it cannot be read.
/// `progress` hears its phases: "read positions", and "read edges and points" when the
/// faces are read through.
OOCSIMP_API MeshSummary describe_mesh(const std::string& path, const std::string& temp_dir = std::string(),
                                      const ProgressCallback& progress = {});

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

}  // namespace oocsimp
