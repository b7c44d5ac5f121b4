#include <catch2/catch.hpp>

#include <cmath>

#include "cluster/vertex_grading.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

TEST_CASE("weight is cos(theta/2) times the longest edge", "[grading]") {
  // Three orthogonal edges (a cube corner): theta = 90 degrees.
  Vec3d corner[3] = {{1, 0, 0}, {0, 2, 0}, {0, 0, 1}};
  CHECK(vertex_weight(corner, 3) == Approx(std::cos(M_PI / 4) * 2));
  // A flat fan with opposite edges: theta = 180 degrees, weight 0.
  Vec3d flat[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  CHECK(vertex_weight(flat, 4) == Approx(0).margin(1e-12));
  // A sharp spike: every edge within 20 degrees of the others.
  double t = 10 * M_PI / 180;
  Vec3d spike[2] = {{std::cos(t), std::sin(t), 0}, {std::cos(t), -std::sin(t), 0}};
  CHECK(vertex_weight(spike, 2) == Approx(std::cos(t)));
  // Zero-length edges count for the length only; no edges at all weigh nothing.
  Vec3d degenerate[2] = {{0, 0, 0}, {0, 3, 0}};
  CHECK(vertex_weight(degenerate, 2) == Approx(3));
  CHECK(vertex_weight(nullptr, 0) == 0);
}

TEST_CASE("grading a cube with unshared face vertices: only corners carry weight", "[grading]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 4);
  MeshInput in = open_mesh_input(d.file("cube.ply"));
  std::vector<std::uint64_t> tris(3 * 2 * 16 * 6);
  std::size_t n = in.triangles->read(tris.data(), tris.size() / 3);
  REQUIRE(n == tris.size() / 3);
  std::vector<std::uint64_t> all;
  for (std::uint64_t i = 0; i < in.positions.count; ++i) all.push_back(i);
  auto g = grade_vertices(all, tris.data(), n, in.positions);
  REQUIRE(g.size() == all.size());
  // The cube's faces have their own vertices, so a vertex sees one face's fan: a
  // corner has edges along two sides at 90 degrees (and, at two of the four
  // corners, the quad diagonal between them); a vertex on a side or inside is flat
  // (edges 180 degrees apart).
  for (const auto& v : g) {
    int on_edge = 0;
    for (double c : {v.p.x, v.p.y, v.p.z}) on_edge += (c == 0 || c == 1);
    INFO("vertex " << v.index << " at " << v.p.x << " " << v.p.y << " " << v.p.z);
    bool corner = on_edge == 3;
    double side = std::cos(M_PI / 4) * 0.25, diagonal = side * std::sqrt(2.0);
    if (corner) CHECK((v.weight == Approx(side) || v.weight == Approx(diagonal)));
    else CHECK(v.weight == Approx(0).margin(1e-12));
  }
}
