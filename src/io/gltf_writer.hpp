// glTF 2.0 binary (.glb, Khronos glTF 2.0 specification §4.4): one mesh of one
// triangle primitive, positions and indices, with vertex normals and colours when the
// mesh carries them, streamed through a ByteSink in one pass over the arrays after a
// pass for the positions' bounds (the file's lengths and the bounds come first).
#pragma once

#include <cstddef>
#include <cstdint>

#include "io/byte_sink.hpp"

namespace oocsimp {

/// What write_glb reads: the mesh's arrays and where its normals and colours are among
/// the vertex attributes (values `attribute_width` per vertex), -1 where absent.
struct GlbArrays {
  const double* positions = nullptr;  ///< 3 per vertex, written as float
  std::size_t vertex_count = 0;
  const std::uint32_t* triangles = nullptr;  ///< 3 per triangle
  std::size_t triangle_count = 0;
  const double* attributes = nullptr;  ///< attribute_width per vertex
  std::size_t attribute_width = 0;
  int normal[3] = {-1, -1, -1};           ///< nx, ny, nz
  int uv[2] = {-1, -1};                   ///< texture coordinates, origin at the image's bottom left
  int colour[4] = {-1, -1, -1, -1};       ///< red, green, blue and alpha (alpha may be absent)
  double colour_scale[4] = {1, 1, 1, 1};  ///< the divisor that takes each colour into [0, 1]
};

/// Writes `m` as a .glb: POSITION (float, with its bounds), NORMAL (made unit length),
/// TEXCOORD_0 (v turned to glTF's top-left origin, §3.7.2.1) and COLOR_0 (float RGB
/// or RGBA in [0, 1]) when present, and indices as unsigned int. A mesh without triangles is a glTF with an empty
/// scene.
void write_glb(ByteSink& sink, const GlbArrays& m);

}  // namespace oocsimp
