// glTF 2.0 binary (.glb, Khronos glTF 2.0 specification §4.4): one mesh of one
// triangle primitive, positions and indices, with vertex normals and colours when the
// mesh carries them, streamed through a ByteSink in one pass over the arrays after a
// pass for the positions' bounds (the file's lengths and the bounds come first). With
// materials, one primitive per material, each with the vertices it uses.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

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
  /// Each triangle's material, an index into material_names or kNoMaterial; null for
  /// a mesh without materials.
  const std::uint32_t* face_materials = nullptr;
  std::vector<std::string> material_names;
  std::vector<std::string> material_libraries;  ///< OBJ's mtllib, kept as the root's extras.mtllib
};

constexpr std::uint32_t kNoMaterial = ~std::uint32_t(0);

/// Writes `m` as a .glb: POSITION (float, with its bounds), NORMAL (made unit length),
/// TEXCOORD_0 (v turned to glTF's top-left origin, §3.7.2.1) and COLOR_0 (float RGB
/// or RGBA in [0, 1]) when present, and indices as unsigned int. With face_materials,
/// the triangles of each material (in the order of material_names, then those of none)
/// are a primitive of their own naming a material {"name": ...}, each in the order the
/// triangles come, with accessors of their own holding the vertices they use (in the
/// vertices' order; a vertex used by two materials is in both). A mesh without triangles is a glTF with an empty scene.
void write_glb(ByteSink& sink, const GlbArrays& m);

}  // namespace oocsimp
