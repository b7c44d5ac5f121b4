// Streaming mesh input.
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
#include "oocsimp/mesh.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

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

/// A thick edge or point read from a file (PLY elements "edge" and "point", OBJ "l"
/// and "p" lines; see ThickPrimitives): vertices a and b, equal for a point, and the
/// thickness in model units, 0 where the file gives none (OBJ).
struct LinePrimitive {
  std::uint64_t a = 0, b = 0;
  float thickness = 0;
};

/// Hears the thick edges and points a TriangleStream meets, a batch at a time.
using PrimitiveSink = std::function<void(const LinePrimitive* primitives, std::size_t count)>;

/// Whether a triangle names one vertex twice: no area and no edge of its own (a
/// cluster could only ever collapse it), so MeshInput::triangles drops it.
inline bool names_a_vertex_twice(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return a == b || b == c || a == c;
}

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

/// Where the faces of a binary file lie when every face is a triangle in a record of
/// one size (binary PLY whose last element is the faces, "list uchar int|uint"
/// alone): face i at base + i * kStride, if faces 0..i-1 were all triangles. Parts
/// that run at once may then each read only their range of the faces
/// (face_range.hpp). Empty (count 0, base null) for other inputs.
struct FixedFaceTable {
  static constexpr std::size_t kStride = 13;  ///< the count byte and three 4-byte indices
  const unsigned char* base = nullptr;        ///< face 0's record, in the input's mapping
  std::uint64_t count = 0;                    ///< face records
  std::uint64_t file_offset = 0;              ///< face 0's byte in the file, for messages
  bool swap = false;                          ///< big-endian indices
  bool signed_index = false;                  ///< "int" (a negative index is an error) or "uint"
  bool available() const { return base != nullptr; }
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
  /// The faces' records when they can be read by range (see FixedFaceTable).
  FixedFaceTable fixed_faces;

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

}  // namespace oocsimp
