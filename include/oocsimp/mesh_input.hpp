// oocsimp — streaming mesh input.
//
// A mesh file is opened as two things: a random-access array of vertex positions
// that lives in a memory-mapped file (the input itself for binary PLY with
// fixed-size vertex records, otherwise a temporary array under the temp directory,
// float or double as the input's precision needs), and a sequential stream of triangles (polygons are fanned). Neither
// ever holds the whole input in heap memory.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"
#include "oocsimp/geometry.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

enum class ScalarType : std::uint8_t { f32, f64 };

/// Read-only view of vertex positions in mapped memory: vertex i's x, y and z are
/// at base + i*stride + offset[k], stored as `type`, byte-swapped when `swap`.
struct PositionArray {
  const unsigned char* base = nullptr;
  std::uint64_t count = 0;
  std::size_t stride = 12;
  std::size_t offset[3] = {0, 4, 8};
  ScalarType type = ScalarType::f32;
  bool swap = false;

  /// Position of vertex i (i < count, unchecked) in double precision.
  inline Vec3d get(std::uint64_t i) const;
};

/// What `oocsimp info` prints: the format and the header-level facts of a mesh.
struct MeshInfo {
  std::string path;
  std::string format;              ///< e.g. "ply binary_little_endian", "obj", "stl binary"
  bool compressed = false;         ///< read through zstd
  std::uint64_t vertex_count = 0;  ///< after welding, when welded
  std::uint64_t face_count = 0;    ///< faces as stored (polygons); STL: triangles
  /// Thick edges and points (see LinePrimitive): PLY "edge" and "point" records, OBJ
  /// "l" and "p" lines.
  std::uint64_t edge_count = 0, point_count = 0;
  /// Vertices as stored (STL: 3 per triangle) when they were welded (STL always,
  /// PLY and OBJ with OpenOptions::weld); 0 when not welded.
  std::uint64_t unwelded_vertex_count = 0;
  std::vector<std::string> elements;  ///< "vertex 100 (x float, y float, ...)" per element
  std::vector<std::string> comments;  ///< PLY comment / obj_info lines
  bool positions_in_place = false;    ///< true when positions are read from the input through mmap
  /// Positions carry more than float precision: the file stores them as double (PLY
  /// double), or a text coordinate has more digits than a float keeps ("451234.567",
  /// where "0.1" or a float written with %.9g does not count). They are then read as
  /// double (PositionArray type f64), and Precision::automatic writes double output.
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
  /// out by the selection (OpenOptions::attributes).
  std::vector<std::string> not_carried;
};

/// Faces that the triangle stream left out instead of failing, by reason. Polygons are
/// fanned first, so the last two count triangles of the fan.
struct SkippedFaces {
  std::uint64_t short_faces = 0;     ///< faces with fewer than 3 corners
  std::uint64_t non_finite = 0;      ///< triangles with a corner that is not finite
  std::uint64_t repeated_index = 0;  ///< triangles that name one vertex twice (no area, no edge of their own)
  std::uint64_t total() const { return short_faces + non_finite + repeated_index; }
};

/// A thick edge or point read from a file (PLY elements "edge" and "point", OBJ "l"
/// and "p" lines; see ThickPrimitives): vertices a and b, equal for a point, and the
/// thickness in model units, 0 where the file gives none (OBJ).
struct LinePrimitive {
  std::uint64_t a = 0, b = 0;
  float thickness = 0;
};

/// Hears the thick edges and points a TriangleStream meets, a batch at a time.
using PrimitiveSink = std::function<void(const LinePrimitive* primitives, std::size_t count)>;

/// A sequential source of triangles as vertex-index triples, in file order.
///
/// MeshInput::triangles only yields triangles with three distinct vertex indices whose
/// vertices are all finite: every clustering method and `measure` read it, so this is
/// the one place where such faces are dropped (and counted, see skipped()).
/// Zero-area triangles with three distinct indices are kept: they still connect their
/// vertices, and the clusterers weight them by their area (zero).
class TriangleStream {
 public:
  virtual ~TriangleStream() = default;
  /// Writes up to `max_triangles` triangles (3 indices each) into `out` and returns how
  /// many; 0 means the stream is exhausted. Indices are validated against the vertex
  /// count; a bad record throws InputError naming the file and position.
  virtual std::size_t read(std::uint64_t* out, std::size_t max_triangles) = 0;
  /// Input bytes consumed so far (compressed bytes for .zst), for progress reports.
  virtual std::uint64_t bytes_consumed() const = 0;
  /// Faces left out so far, by reason.
  virtual SkippedFaces skipped() const { return {}; }
  /// Where the thick edges and points go that reading the triangles meets (a PLY
  /// file's "edge" and "point" elements after its faces, an OBJ file's "l" and "p"
  /// lines among them); their indices are validated like the faces'. Set before the
  /// first read(); without a sink they are skipped. A polyline "l a b c" is two edges.
  virtual void set_primitive_sink(PrimitiveSink sink) { (void)sink; }
};

/// An opened mesh: info, positions and a triangle stream. Owns the mappings and
/// temporary files behind them; they are released (and deleted) with it.
class MeshInput {
 public:
  MeshInput();
  MeshInput(MeshInput&&) noexcept;
  MeshInput& operator=(MeshInput&&) noexcept;
  ~MeshInput();

  MeshInfo info;
  PositionArray positions;
  /// The vertex attributes carried (OpenOptions::attributes), with their ranges.
  AttributeArray attributes;
  /// Triangles in file order. Call `restart_triangles()` to read them again.
  std::unique_ptr<TriangleStream> triangles;
  /// Total input size in bytes (compressed size for .zst), the denominator of progress.
  std::uint64_t file_size = 0;

  /// Reopens the triangle stream at the first triangle.
  void restart_triangles();

 private:
  struct Impl;  // the reader's state: mappings, temporary files, the stream's factory
  std::unique_ptr<Impl> impl_;
  friend Impl& reader_state(MeshInput& input);
};

struct OpenOptions {
  std::string temp_dir;  ///< where temporary position arrays (and stream copies) go; empty = $TMPDIR or /tmp
  /// Weld vertices at exactly the same position into one (src/io/vertex_weld.hpp);
  /// STL input is always welded, since it stores every triangle's corners apart.
  bool weld = false;
  /// Heap bytes the welding may use (it works out of core in temp_dir beyond that).
  std::uint64_t memory_budget = std::uint64_t(256) << 20;
  /// Hears the phase "read positions" (input bytes read); see ProgressCallback.
  ProgressCallback progress;
  /// Which vertex attributes are read for carrying (all by default; see
  /// carried_attributes in src/io/attribute_array.hpp).
  AttributeSelection attributes;
};

/// Opens a PLY (ascii / binary LE / binary BE), OBJ or STL (ascii / binary) file,
/// optionally zstd-compressed (".zst"). Detects the format from the content (the
/// extension is only a tie-breaker), maps or converts the positions and computes the
/// bounding box of the finite ones, then welds the vertices (STL, or `options.weld`).
/// NaN or infinite coordinates are counted in info.non_finite_vertices, not rejected.
/// Converting keeps what every coordinate says (see MeshInfo::double_precision). The file
/// is opened once and every pass reads that descriptor; "-" is standard input, and a
/// FIFO, pipe or device is copied into temp_dir as far as it is read (the copy goes
/// with the MeshInput).
MeshInput open_mesh_input(const std::string& path, const OpenOptions& options = {});

inline Vec3d PositionArray::get(std::uint64_t i) const {
  const unsigned char* rec = base + i * stride;
  double v[3];
  if (type == ScalarType::f32) {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t u;
      std::memcpy(&u, rec + offset[k], 4);
      if (swap) u = __builtin_bswap32(u);
      float f;
      std::memcpy(&f, &u, 4);
      v[k] = f;
    }
  } else {
    for (int k = 0; k < 3; ++k) {
      std::uint64_t u;
      std::memcpy(&u, rec + offset[k], 8);
      if (swap) u = __builtin_bswap64(u);
      std::memcpy(&v[k], &u, 8);
    }
  }
  return {v[0], v[1], v[2]};
}

/// The default temporary directory: $TMPDIR if set and non-empty, else /tmp.
std::string default_temp_dir();

}  // namespace oocsimp
