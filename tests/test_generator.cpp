#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <utility>

#include "oocsimp/generate.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

LoadedMesh generate(const ScratchDir& d, const char* name, SyntheticShape shape, std::uint64_t tris,
                    std::uint64_t seed = 1) {
  GenerateOptions o;
  o.shape = shape;
  o.triangles = tris;
  o.seed = seed;
  GenerateResult r = generate_mesh(d.file(name), o);
  LoadedMesh m = load_mesh(d.file(name));
  REQUIRE(m.vertex_count() == r.vertices);
  REQUIRE(m.triangle_count() == r.triangles);
  return m;
}

// Signed volume (divergence theorem): positive when a closed surface faces outwards.
double signed_volume(const LoadedMesh& m) {
  double v = 0;
  for (std::size_t i = 0; i < m.triangles.size(); i += 3) {
    const double* a = &m.positions[3 * m.triangles[i]];
    const double* b = &m.positions[3 * m.triangles[i + 1]];
    const double* c = &m.positions[3 * m.triangles[i + 2]];
    v +=
        (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) /
        6;
  }
  return v;
}

// Directed edge -> count.
std::map<std::pair<std::uint64_t, std::uint64_t>, int> directed_edges(const LoadedMesh& m) {
  std::map<std::pair<std::uint64_t, std::uint64_t>, int> e;
  for (std::size_t i = 0; i < m.triangles.size(); i += 3)
    for (int k = 0; k < 3; ++k) ++e[{m.triangles[i + k], m.triangles[i + (k + 1) % 3]}];
  return e;
}

}  // namespace

TEST_CASE("generated triangle counts are within 2% of the request", "[generator]") {
  ScratchDir d;
  for (auto shape : {SyntheticShape::sphere, SyntheticShape::terrain, SyntheticShape::parts}) {
    for (std::uint64_t n : {20000ull, 123457ull}) {
      GenerateOptions o;
      o.shape = shape;
      o.triangles = n;
      GenerateResult r = generate_mesh(d.file("g.ply"), o);
      INFO("shape " << int(shape) << " n " << n << " got " << r.triangles);
      CHECK(std::fabs(double(r.triangles) - double(n)) <= 0.02 * double(n));
    }
  }
}

TEST_CASE("the sphere is closed, manifold, genus 0 and outward", "[generator]") {
  ScratchDir d;
  LoadedMesh m = generate(d, "s.ply", SyntheticShape::sphere, 5000);
  auto e = directed_edges(m);
  for (const auto& kv : e) {
    CHECK(kv.second == 1);                                   // consistently oriented
    CHECK(e.count({kv.first.second, kv.first.first}) == 1);  // closed: every edge has a twin
  }
  // Euler characteristic V - E + F = 2.
  long long V = (long long)m.vertex_count(), E = (long long)e.size() / 2, F = (long long)m.triangle_count();
  CHECK(V - E + F == 2);
  CHECK(signed_volume(m) > 3.0);  // about 4/3 pi
}

TEST_CASE("the terrain is an open height field with a boundary", "[generator]") {
  ScratchDir d;
  LoadedMesh m = generate(d, "t.ply", SyntheticShape::terrain, 2 * 49 * 49);
  auto e = directed_edges(m);
  int boundary = 0;
  for (const auto& kv : e)
    if (!e.count({kv.first.second, kv.first.first})) ++boundary;
  CHECK(boundary == 4 * 49);
  for (std::size_t i = 0; i < m.positions.size(); i += 3) {
    CHECK(m.positions[i] >= 0);
    CHECK(m.positions[i] <= 1);
  }
}

TEST_CASE("parts are closed outward solids", "[generator]") {
  ScratchDir d;
  LoadedMesh m = generate(d, "p.ply", SyntheticShape::parts, 200000, 7);
  CHECK(signed_volume(m) > 0);
  CHECK(m.triangle_count() > 190000);
}

TEST_CASE("generation is deterministic by seed", "[generator]") {
  ScratchDir d;
  for (auto shape : {SyntheticShape::sphere, SyntheticShape::terrain, SyntheticShape::parts}) {
    GenerateOptions o;
    o.shape = shape;
    o.triangles = 30000;
    o.seed = 5;
    generate_mesh(d.file("a.ply"), o);
    generate_mesh(d.file("b.ply"), o);
    o.seed = 6;
    generate_mesh(d.file("c.ply"), o);
    CHECK(read_file(d.file("a.ply")) == read_file(d.file("b.ply")));
    CHECK(read_file(d.file("a.ply")) != read_file(d.file("c.ply")));
  }
}

TEST_CASE("compressed and ascii generation give the same mesh", "[generator]") {
  ScratchDir d;
  GenerateOptions o;
  o.triangles = 10000;
  generate_mesh(d.file("a.ply"), o);
  generate_mesh(d.file("a.ply.zst"), o);
  o.ascii = true;
  generate_mesh(d.file("t.ply"), o);
  LoadedMesh a = load_mesh(d.file("a.ply")), z = load_mesh(d.file("a.ply.zst")), t = load_mesh(d.file("t.ply"));
  CHECK(a.positions == z.positions);
  CHECK(a.triangles == z.triangles);
  CHECK(a.positions == t.positions);
  CHECK(a.triangles == t.triangles);
}
