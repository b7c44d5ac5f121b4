// A run's output on its way to the writer: SimplifiedMesh's arrays as LargeArrays, so
// that an output larger than the memory budget lives in mapped temporary files and is
// written from there, never whole in the heap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/large_array.hpp"
#include "oocsimp/mesh.hpp"

namespace oocsimp {

/// SimplifiedMesh with its positions, triangles and attribute values in LargeArrays.
/// Thick primitives (few, and only from clustering without a target) stay in the heap.
struct OutputMesh {
  LargeArray<double> positions;         ///< 3 per vertex
  LargeArray<std::uint32_t> triangles;  ///< 3 per face
  std::vector<VertexAttribute> attributes;
  LargeArray<double> attribute_values;  ///< attributes.size() per vertex
  ThickPrimitives primitives;
  ScalarType precision = ScalarType::f32;
  Materials materials;  ///< what the material_K attributes stand for

  std::size_t vertex_count() const { return positions.size() / 3; }
  std::size_t triangle_count() const { return triangles.size() / 3; }

  /// The mesh in the heap (the arrays moved, or copied out of their files).
  SimplifiedMesh take();
  /// `mesh` as an OutputMesh in the heap (moved).
  static OutputMesh of(SimplifiedMesh&& mesh);
};

/// Adds nx, ny, nz (float) to the attributes of `mesh`, replacing carried ones: per
/// vertex the unit sum of its faces' cross products (area-weighted normals), zero
/// where that sum is. The sums and new values are placed by `place`.
void add_vertex_normals(OutputMesh* mesh, const ArrayPlace& place);

}  // namespace oocsimp
