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
    if (corner)
      CHECK((v.weight == Approx(side) || v.weight == Approx(diagonal)));
    else
      CHECK(v.weight == Approx(0).margin(1e-12));
  }
}

TEST_CASE("grading deduplicates edges without changing a weight, even in needle fans", "[grading]") {
  // Fans of a vertex at the origin with two neighbours in nearly the same direction,
  // each triangle listed in both orientations: every edge comes twice, and the dot
  // of a direction with its copy (which the weight over all copies includes) is the
  // minimum in these cases. The weight from grade_vertices (edges deduplicated)
  // must be bit for bit vertex_weight over the edges with their copies.
  const float needles[][6] = {{0.789106369f, 0.805135846f, 5.37664127f, 0.789106488f, 0.805135965f, 5.37664223f},
                              {8.86960793f, 4.47936773f, 0.543005347f, 8.86960888f, 4.47936821f, 0.543005466f},
                              {9.40750694f, 8.88822079f, 1.16860771f, 9.4075079f, 8.88822174f, 1.16860795f},
                              {9.03109264f, 7.25404644f, 0.246628612f, 9.0310936f, 7.25404739f, 0.246628657f},
                              {8.37982368f, 7.0258522f, 0.947106481f, 8.37982464f, 7.02585316f, 0.947106659f},
                              {1.0f, 2.0f, 3.0f, 3.0f, -1.0f, 0.5f}};  // and an ordinary fan
  const int fans = int(sizeof needles / sizeof needles[0]);
  std::string v, f;
  char line[128];
  for (int k = 0; k < fans; ++k) {
    v += "0 0 0\n";
    for (int m = 0; m < 2; ++m) {
      std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", double(needles[k][3 * m]), double(needles[k][3 * m + 1]),
                    double(needles[k][3 * m + 2]));
      v += line;
    }
    int c = 3 * k;
    f += "3 " + std::to_string(c) + " " + std::to_string(c + 1) + " " + std::to_string(c + 2) + "\n";
    f += "3 " + std::to_string(c) + " " + std::to_string(c + 2) + " " + std::to_string(c + 1) + "\n";
  }
  ScratchDir d;
  write_file(d.file("needles.ply"), "ply\nformat ascii 1.0\nelement vertex " + std::to_string(3 * fans) +
                                        "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                                        std::to_string(2 * fans) +
                                        "\nproperty list uchar int vertex_indices\nend_header\n" + v + f);
  MeshInput in = open_mesh_input(d.file("needles.ply"));
  std::vector<std::uint64_t> tris(6 * fans);
  REQUIRE(in.triangles->read(tris.data(), std::size_t(2 * fans)) == std::size_t(2 * fans));
  std::vector<std::uint64_t> all;
  for (std::uint64_t i = 0; i < in.positions.count; ++i) all.push_back(i);
  std::vector<GradedVertex> g = grade_vertices(all, tris.data(), std::size_t(2 * fans), in.positions);
  for (int k = 0; k < fans; ++k) {
    Vec3d o = in.positions.get(3 * k), a = in.positions.get(3 * k + 1), b = in.positions.get(3 * k + 2);
    Vec3d ea{a.x - o.x, a.y - o.y, a.z - o.z}, eb{b.x - o.x, b.y - o.y, b.z - o.z};
    const Vec3d with_copies[4] = {ea, eb, eb, ea};
    INFO("fan " << k);
    CHECK(g[std::size_t(3 * k)].weight == vertex_weight(with_copies, 4));
  }
}
