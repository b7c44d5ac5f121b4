// Writing a mesh into an OutputFile the caller opened before the run (simplify_file
// opens every destination first, so a missing folder fails before the work).
#pragma once

#include <string>
#include <vector>

#include "io/byte_sink.hpp"
#include "io/output_mesh.hpp"
#include "io/temp_file.hpp"
#include "oocsimp/formats.hpp"

namespace oocsimp {

/// write_mesh into an OutputFile opened earlier; the caller commits it.
void write_mesh(OutputFile& out, const std::vector<double>& positions, const std::vector<std::uint32_t>& triangles,
                MeshFormat format, ScalarType precision = ScalarType::f32, const AttributeValues* attributes = nullptr,
                const ThickPrimitives* primitives = nullptr);
/// The same for an OutputMesh, read where its arrays are (heap or mapped files).
void write_mesh(OutputFile& out, const OutputMesh& mesh, MeshFormat format);

/// A PLY file written in order, vertex by vertex, then face by face: what write_mesh
/// writes, byte for byte, without holding the mesh. The header comes first, so the
/// counts are known up front; finish() checks they were met (IoError otherwise) and
/// writes what is buffered. Thick edges and points, when counted, follow the faces,
/// written by the caller. `comments` go into the header as "comment" lines after
/// oocsimp's own (one line each).
class PlyStreamWriter {
 public:
  PlyStreamWriter(ByteSink& sink, bool ascii, ScalarType precision, std::uint64_t vertices, std::uint64_t triangles,
                  const std::vector<VertexAttribute>& attributes, std::uint64_t edges = 0, std::uint64_t points = 0,
                  const std::vector<std::string>& comments = {});
  /// The next vertex: its position and its attributes' values (attributes.size()).
  void vertex(const Vec3d& p, const double* attributes);
  /// The next face.
  void triangle(const std::uint32_t corners[3]);
  void finish();

 private:
  void flush_text_past(std::size_t bytes);
  ByteSink& sink_;
  bool ascii_;
  ScalarType precision_;
  std::uint64_t vertices_, triangles_, vertices_written_ = 0, triangles_written_ = 0;
  std::vector<VertexAttribute> attributes_;
  std::vector<std::size_t> offsets_;   // of each attribute in a binary record
  std::vector<unsigned char> record_;  // a binary vertex record
  std::string text_;                   // ascii lines not yet written
};

}  // namespace oocsimp
