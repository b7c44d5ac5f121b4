// Per-vertex normals of the output (--normals): area-weighted face normals.
#include <cmath>
#include <string>
#include <vector>

#include "common/vec3_math.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

void add_vertex_normals(SimplifiedMesh* mesh) {
  const std::size_t n = mesh->positions.size() / 3;
  auto position = [&](std::uint32_t v) {
    return Vec3d{mesh->positions[3 * std::size_t(v)], mesh->positions[3 * std::size_t(v) + 1],
                 mesh->positions[3 * std::size_t(v) + 2]};
  };
  // The cross product's length is twice the area: summing them weights by area.
  std::vector<Vec3d> sum(n);
  for (std::size_t f = 0; f + 2 < mesh->triangles.size(); f += 3) {
    const std::uint32_t* t = &mesh->triangles[f];
    const Vec3d p = position(t[0]);
    const Vec3d normal = cross(position(t[1]) - p, position(t[2]) - p);
    if (!is_finite(normal)) continue;
    for (int k = 0; k < 3; ++k) sum[t[k]] += normal;
  }
  // The attributes kept: all but carried nx, ny, nz; the new ones go last.
  AttributeValues& a = mesh->attributes;
  const std::size_t width = a.attributes.size();
  std::vector<std::size_t> kept;
  for (std::size_t k = 0; k < width; ++k)
    if (a.attributes[k].name != "nx" && a.attributes[k].name != "ny" && a.attributes[k].name != "nz") kept.push_back(k);
  AttributeValues out;
  for (std::size_t k : kept) out.attributes.push_back(a.attributes[k]);
  for (const char* name : {"nx", "ny", "nz"}) out.attributes.push_back({name, AttributeType::f32, -1, 1});
  out.values.reserve(n * out.attributes.size());
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t k : kept) out.values.push_back(a.values[v * width + k]);
    const double l = length(sum[v]);
    const Vec3d unit = l > 0 ? sum[v] / l : Vec3d{};
    out.values.insert(out.values.end(), {unit.x, unit.y, unit.z});
  }
  a = std::move(out);
}

}  // namespace oocsimp
