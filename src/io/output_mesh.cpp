#include "io/output_mesh.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "common/vec3_math.hpp"

namespace oocsimp {

SimplifiedMesh OutputMesh::take() {
  SimplifiedMesh m;
  m.positions = positions.take();
  m.triangles = triangles.take();
  m.attributes.attributes = std::move(attributes);
  m.attributes.values = attribute_values.take();
  m.attributes.materials = std::move(materials);
  m.primitives = std::move(primitives);
  m.precision = precision;
  return m;
}

OutputMesh OutputMesh::of(SimplifiedMesh&& mesh) {
  OutputMesh m;
  m.positions = LargeArray<double>(std::move(mesh.positions));
  m.triangles = LargeArray<std::uint32_t>(std::move(mesh.triangles));
  m.attributes = std::move(mesh.attributes.attributes);
  m.attribute_values = LargeArray<double>(std::move(mesh.attributes.values));
  m.materials = std::move(mesh.attributes.materials);
  m.primitives = std::move(mesh.primitives);
  m.precision = mesh.precision;
  return m;
}

void add_vertex_normals(OutputMesh* mesh, const ArrayPlace& place) {
  const std::size_t n = mesh->vertex_count();
  const double* positions = mesh->positions.data();
  auto position = [&](std::uint32_t v) {
    const double* p = positions + 3 * std::size_t(v);
    return Vec3d{p[0], p[1], p[2]};
  };
  // The cross product's length is twice the area: summing them weights by area.
  LargeArray<Vec3d> sum;
  sum.assign_zeroed(n, place, "normals");
  const std::uint32_t* triangles = mesh->triangles.data();
  for (std::size_t f = 0; f < mesh->triangle_count(); ++f) {
    const std::uint32_t* t = triangles + 3 * f;
    const Vec3d p = position(t[0]);
    const Vec3d normal = cross(position(t[1]) - p, position(t[2]) - p);
    if (!is_finite(normal)) continue;
    for (int k = 0; k < 3; ++k) sum[t[k]] += normal;
  }
  // The attributes kept: all but carried nx, ny, nz; the new ones go last.
  const std::vector<VertexAttribute>& given = mesh->attributes;
  const std::size_t width = given.size();
  std::vector<std::size_t> kept;
  std::vector<VertexAttribute> names;
  for (std::size_t k = 0; k < width; ++k)
    if (given[k].name != "nx" && given[k].name != "ny" && given[k].name != "nz") {
      kept.push_back(k);
      names.push_back(given[k]);
    }
  for (const char* name : {"nx", "ny", "nz"}) names.push_back({name, AttributeType::f32, -1, 1});
  LargeArray<double> values;
  values.assign_zeroed(n * names.size(), place, "attributes");
  const double* old = mesh->attribute_values.data();
  double* out = values.data();
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t k : kept) *out++ = old[v * width + k];
    const double l = length(sum[v]);
    const Vec3d unit = l > 0 ? sum[v] / l : Vec3d{};
    *out++ = unit.x;
    *out++ = unit.y;
    *out++ = unit.z;
  }
  mesh->attributes = std::move(names);
  mesh->attribute_values = std::move(values);
}

}  // namespace oocsimp
