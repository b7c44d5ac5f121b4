// oocsimp — the plain mesh data of the public API: a mesh in the caller's memory
// (MeshView), a simplified mesh (SimplifiedMesh), what a file holds (MeshInfo) and the
// formats the library writes.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"
#include "oocsimp/geometry.hpp"

namespace oocsimp {

enum class ScalarType : std::uint8_t { f32, f64 };

enum class MeshFormat { ply_binary, ply_ascii, obj, stl_binary, stl_ascii, off, glb };

/// What `oocsimp info` prints: the format and the header-level facts of a mesh.
struct MeshInfo {
  std::string path;
  std::string format;              ///< e.g. "ply binary_little_endian", "obj", "stl binary"
  bool compressed = false;         ///< read through zstd or gzip
  std::string compression;         ///< "zstd", "gzip", or empty when not compressed
  std::uint64_t vertex_count = 0;  ///< after welding, when welded
  std::uint64_t face_count = 0;    ///< faces as stored (polygons); STL: triangles
  /// Thick edges and points: PLY "edge" and "point" records, OBJ "l" and "p" lines.
  std::uint64_t edge_count = 0, point_count = 0;
  /// Vertices as stored (STL: 3 per triangle) when they were welded (STL always,
  /// PLY and OBJ with SimplifyOptions::weld); 0 when not welded.
  std::uint64_t unwelded_vertex_count = 0;
  std::vector<std::string> elements;  ///< "vertex 100 (x float, y float, ...)" per element
  std::vector<std::string> comments;  ///< PLY comment / obj_info lines
  /// OBJ's mtllib and usemtl (see Materials); the names are carried only with the
  /// material_K attributes.
  Materials materials;
  bool positions_in_place = false;  ///< true when positions are read from the input through mmap
  /// Positions carry more than float precision: the file stores them as double (PLY
  /// double), or a text coordinate has more digits than a float keeps ("451234.567",
  /// where "0.1" or a float written with %.9g does not count). They are then read as
  /// double, and Precision::automatic writes double output.
  bool double_precision = false;
  Box3d bounds;  ///< of the finite vertices
  /// Vertices with a NaN or infinite coordinate (see is_finite), the first of them by
  /// index and where it is in the file ("byte N" or "line N"); only the first is
  /// described, so a file full of them costs no memory.
  std::uint64_t non_finite_vertices = 0;
  std::uint64_t first_non_finite_vertex = 0;
  std::string first_non_finite_position;
  /// What the input has that the output will not carry, one line each naming the file:
  /// texture coordinates, per-face properties, vertex list properties, attributes left
  /// out by the selection (SimplifyOptions::attributes).
  std::vector<std::string> not_carried;
};

/// The thick edges or the points of a mesh file: how many, and the least, the largest
/// and the sum of their thicknesses (0 where the file gives none).
struct PrimitiveTally {
  std::uint64_t count = 0;
  double least = HUGE_VAL, most = 0, sum = 0;
};

/// What `oocsimp info` prints about a mesh file (describe_mesh).
struct MeshSummary {
  MeshInfo info;
  /// The vertex attributes a run carries by default (all), with their ranges.
  std::vector<VertexAttribute> attributes;
  PrimitiveTally edges, points;
};

/// Faces that the input lost instead of failing, by reason. Polygons are fanned
/// first, so the last two count triangles of the fan.
struct SkippedFaces {
  std::uint64_t short_faces = 0;     ///< faces with fewer than 3 corners
  std::uint64_t non_finite = 0;      ///< triangles with a corner that is not finite
  std::uint64_t repeated_index = 0;  ///< triangles that name one vertex twice (no area, no edge of their own)
  std::uint64_t total() const { return short_faces + non_finite + repeated_index; }
};

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

/// A simplified mesh, in memory.
struct SimplifiedMesh {
  std::vector<double> positions;         ///< 3 per vertex
  std::vector<std::uint32_t> triangles;  ///< 3 per face
  /// The carried vertex attributes: per output vertex the area-weighted mean of its
  /// cluster's values.
  AttributeValues attributes;
  /// Thick edges and points (SimplifyOptions::thick_edges); their vertices follow
  /// the triangles' in the numbering.
  ThickPrimitives primitives;
  /// The precision chosen for the output: with f32 every position is a float value
  /// (rounded from the double the clustering computed), and writers store it as float.
  ScalarType precision = ScalarType::f32;
};

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
  /// Optional, one per vertex: non-zero where the vertex must stay where it is (added
  /// to SimplifyOptions::locked_vertices). Null: none.
  const std::uint8_t* vertex_lock = nullptr;
};

}  // namespace oocsimp
