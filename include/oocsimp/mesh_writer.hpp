// oocsimp — writing small (in-memory) meshes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/mesh_input.hpp"

namespace oocsimp {

enum class MeshFormat { ply_binary, ply_ascii, obj, stl_binary, stl_ascii, off };

/// Thick edges and points (Low & Tan 1997 §2 step 5, §3.3): what vertex clustering
/// leaves of parts thinner than a cell. A renderer draws an edge as a line
/// `edge_thickness` wide and a point as a disc `point_thickness` across, both in model
/// units (a line T wide is T / R pixels wide where a pixel is R, Low & Tan §4).
struct ThickPrimitives {
  std::vector<std::uint32_t> edges;    ///< 2 vertex indices per edge
  std::vector<float> edge_thickness;   ///< 1 per edge
  std::vector<std::uint32_t> points;   ///< 1 vertex index per point
  std::vector<float> point_thickness;  ///< 1 per point
  std::size_t edge_count() const { return edges.size() / 2; }
  std::size_t point_count() const { return points.size(); }
  bool empty() const { return edges.empty() && points.empty(); }
};

/// The format implied by a path's extension, ignoring case and an optional ".zst"
/// (which compresses the stream): ".ply" (ascii PLY when `ascii`), ".obj", ".stl"
/// (ascii STL when `ascii`) or ".off". Any other name throws UsageError listing what
/// can be written.
MeshFormat format_for_path(const std::string& path, bool ascii);

/// Writes a triangle mesh given as flat arrays: `positions` holds 3 coordinates per
/// vertex, `triangles` 3 vertex indices per face. `precision` says how coordinates
/// are stored: PLY writes "property float x" or "property double x", the text formats
/// (OBJ, OFF, ascii STL) the shortest text that reads back as the same double (rounded
/// to float first for f32, so that a float output reads back as float input; ascii
/// PLY, which declares float, the shortest text of the float); binary STL holds
/// float32 whatever `precision` says. PLY faces are
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
/// thickness; STL and OFF drop them (format_keeps_primitives).
/// Throws IoError.
void write_mesh(const std::string& path, const std::vector<double>& positions,
                const std::vector<std::uint32_t>& triangles, MeshFormat format, ScalarType precision = ScalarType::f32,
                const AttributeValues* attributes = nullptr, const ThickPrimitives* primitives = nullptr);

/// Whether `format` can store vertex attributes: PLY every one (as "property TYPE
/// NAME" after x, y, z), OBJ the colours red, green and blue ("v x y z r g b", in
/// [0, 1]); STL and OFF none.
bool format_keeps_attributes(MeshFormat format, const AttributeValues& attributes);

/// Whether `format` stores thick edges and points with their thickness (PLY only; OBJ
/// keeps the edges and points without it, STL and OFF drop them).
bool format_keeps_primitives(MeshFormat format);

}  // namespace oocsimp
