// The consumer program of the README: a coloured grid in memory, simplified through the
// installed library's one header, then written as PLY.
#include <cstdio>
#include <vector>

#include "oocsimp/oocsimp.hpp"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const int n = 200;  // an n x n grid of quads on the unit square, red growing with x
  std::vector<float> xyz;
  std::vector<unsigned char> red;
  std::vector<std::uint32_t> tri;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      xyz.insert(xyz.end(), {float(i) / n, float(j) / n, 0.0f});
      red.push_back((unsigned char)(255 * i / n));
    }
  for (std::uint32_t j = 0; j < n; ++j)
    for (std::uint32_t i = 0; i < n; ++i) {
      std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      tri.insert(tri.end(), {a, b, d, a, d, c});
    }
  oocsimp::MeshView mesh;
  mesh.positions = xyz.data();
  mesh.vertex_count = red.size();
  mesh.indices = tri.data();
  mesh.triangle_count = tri.size() / 3;
  mesh.attributes.add({"red", oocsimp::AttributeType::u8}, red.data(), 1);
  oocsimp::SimplifyOptions options;
  options.sizing.grid = 16;
  options.floating.representative = oocsimp::RepresentativeRule::quadric;  // per-method options
  int reports = 0;
  options.progress = [&](const oocsimp::Progress&) { return ++reports > 0; };  // false would cancel
  oocsimp::SimplifiedMesh out = oocsimp::simplify_mesh(mesh, options);
  oocsimp::write_mesh(std::string(argv[1]) + "/consumer.ply", out.positions, out.triangles,
                      oocsimp::MeshFormat::ply_binary, out.precision, &out.attributes);
  std::printf("%zu -> %zu triangles\n", tri.size() / 3, out.triangles.size() / 3);
  const bool ok = !out.triangles.empty() && out.triangles.size() < tri.size() &&
                  out.attributes.attributes.size() == 1 && reports > 0;
  return ok ? 0 : 1;
}
