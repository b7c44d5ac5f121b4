#include <catch2/catch.hpp>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/math_constants.hpp"
#include "io/attribute_array.hpp"
#include "io/content_hash.hpp"
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

// A mesh generated with attributes, read back through oocsimp's reader: the geometry,
// the attributes' names and types, and their values (6 per vertex).
struct AttributedMesh {
  LoadedMesh mesh;
  std::vector<VertexAttribute> attributes;
  std::vector<double> values;
  const double* colour(std::size_t i) const { return &values[6 * i]; }
  const double* normal(std::size_t i) const { return &values[6 * i + 3]; }
};

AttributedMesh generate_attributed(const ScratchDir& d, const std::string& name, SyntheticShape shape,
                                   std::uint64_t tris, std::uint64_t seed = 1, bool ascii = false) {
  GenerateOptions o;
  o.shape = shape;
  o.triangles = tris;
  o.seed = seed;
  o.ascii = ascii;
  o.attributes = true;
  generate_mesh(d.file(name), o);
  AttributedMesh a;
  a.mesh = load_mesh(d.file(name));
  MeshInput in = open_mesh_input(d.file(name));
  a.attributes = in.attributes.attributes;
  REQUIRE(in.attributes.count == a.mesh.vertex_count());
  for (std::uint64_t i = 0; i < in.attributes.count; ++i)
    for (std::size_t k = 0; k < in.attributes.size(); ++k) a.values.push_back(attribute_value(in.attributes, i, k));
  return a;
}

// Per vertex, the sum of its triangles' area-weighted normals (the mesh's own normal).
std::vector<double> mesh_normals(const LoadedMesh& m) {
  std::vector<double> n(m.positions.size(), 0.0);
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const double* a = &m.positions[3 * m.triangles[t]];
    const double* b = &m.positions[3 * m.triangles[t + 1]];
    const double* c = &m.positions[3 * m.triangles[t + 2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double cross[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) n[3 * m.triangles[t + std::size_t(k)] + std::size_t(j)] += cross[j];
  }
  return n;
}

// The angle between a and b in degrees.
double degrees_between(const double* a, const double* b) {
  const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
  return std::acos(std::max(-1.0, std::min(1.0, dot / (la * lb)))) * 180 / kPi;
}

// The largest angle between the written normals and the mesh's own.
double worst_against_mesh_normals(const AttributedMesh& a) {
  const std::vector<double> n = mesh_normals(a.mesh);
  double worst = 0;
  for (std::size_t i = 0; i < a.mesh.vertex_count(); ++i)
    worst = std::max(worst, degrees_between(a.normal(i), &n[3 * i]));
  return worst;
}

}  // namespace

TEST_CASE("generated triangle counts are within 2% of the request", "[generator]") {
  ScratchDir d;
  for (auto shape : {SyntheticShape::sphere, SyntheticShape::terrain, SyntheticShape::parts, SyntheticShape::boxes}) {
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

TEST_CASE("the boxes are apart, closed, manifold, outward, of long thin triangles and zero-area slivers",
          "[generator]") {
  ScratchDir d;
  for (std::uint64_t tris : {40000ull, 200000ull}) {
    if (OOCSIMP_TEST_UNDER_ASAN && tris > 40000) continue;
    INFO(tris << " triangles asked");
    const LoadedMesh m = generate(d, "b.ply", SyntheticShape::boxes, tris, 3);
    const std::uint64_t boxes = std::min(kBoxesMostCount, tris / kBoxesTrianglesEach);
    CHECK(std::fabs(double(m.triangle_count()) - double(tris)) <= 0.02 * double(tris));
    // Closed and consistently oriented: each directed edge once, its reverse once.
    const auto e = directed_edges(m);
    std::size_t unpaired = 0;
    for (const auto& kv : e) unpaired += kv.second != 1 || e.count({kv.first.second, kv.first.first}) != 1;
    CHECK(unpaired == 0);
    // Manifold at every vertex: the far edges of its triangles form one cycle (one fan).
    std::vector<std::vector<std::pair<std::uint64_t, std::uint64_t>>> link(m.vertex_count());
    for (std::size_t t = 0; t < m.triangles.size(); t += 3)
      for (int k = 0; k < 3; ++k)
        link[m.triangles[t + std::size_t(k)]].push_back(
            {m.triangles[t + std::size_t(k + 1) % 3], m.triangles[t + std::size_t(k + 2) % 3]});
    std::size_t fans_apart = 0;
    for (const auto& l : link) {
      std::map<std::uint64_t, std::uint64_t> next(l.begin(), l.end());
      std::size_t steps = 0;
      for (std::uint64_t at = l.front().first; steps < l.size(); ++steps) {
        at = next[at];
        if (at == l.front().first) break;
      }
      fans_apart += next.size() != l.size() || steps + 1 != l.size();
    }
    CHECK(fans_apart == 0);
    // The pieces: union-find over the triangles' corners.
    std::vector<std::uint64_t> parent(m.vertex_count());
    for (std::uint64_t v = 0; v < parent.size(); ++v) parent[v] = v;
    auto root = [&](std::uint64_t v) {
      while (parent[v] != v) v = parent[v] = parent[parent[v]];
      return v;
    };
    for (std::size_t t = 0; t < m.triangles.size(); t += 3)
      for (int k = 1; k < 3; ++k) parent[root(m.triangles[t + std::size_t(k)])] = root(m.triangles[t]);
    struct Piece {
      double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
      double volume = 0;
      long long vertices = 0, triangles = 0, slivers = 0;
      std::set<std::pair<std::uint64_t, std::uint64_t>> edges;
    };
    std::map<std::uint64_t, Piece> pieces;
    for (std::uint64_t v = 0; v < m.vertex_count(); ++v) {
      Piece& p = pieces[root(v)];
      ++p.vertices;
      for (int a = 0; a < 3; ++a) {
        p.lo[a] = std::min(p.lo[a], m.positions[3 * v + std::size_t(a)]);
        p.hi[a] = std::max(p.hi[a], m.positions[3 * v + std::size_t(a)]);
      }
    }
    std::vector<double> ratios;  // longest edge over shortest, of the triangles with area
    for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
      Piece& p = pieces[root(m.triangles[t])];
      const double* c[3];
      for (int k = 0; k < 3; ++k) c[k] = &m.positions[3 * m.triangles[t + std::size_t(k)]];
      const double u[3] = {c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2]};
      const double w[3] = {c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2]};
      const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      ++p.triangles;
      p.volume += (c[0][0] * n[0] + c[0][1] * n[1] + c[0][2] * n[2]) / 6;
      for (int k = 0; k < 3; ++k) {
        const std::uint64_t a = m.triangles[t + std::size_t(k)], b = m.triangles[t + std::size_t(k + 1) % 3];
        p.edges.insert({std::min(a, b), std::max(a, b)});
      }
      if (n[0] == 0 && n[1] == 0 && n[2] == 0) {
        ++p.slivers;  // three collinear corners, exactly
        continue;
      }
      double shortest = HUGE_VAL, longest = 0;
      for (int k = 0; k < 3; ++k) {
        const double* a = c[k];
        const double* b = c[(k + 1) % 3];
        const double l = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
        shortest = std::min(shortest, l), longest = std::max(longest, l);
      }
      ratios.push_back(longest / shortest);
    }
    REQUIRE(pieces.size() == boxes);
    std::vector<const Piece*> list;
    for (const auto& kv : pieces) {
      const Piece& p = kv.second;
      list.push_back(&p);
      // A sphere's topology (V - E + F = 2), enclosing its bounding box's volume
      // outwards: the surface of an axis-aligned box, standing on z = 0.
      CHECK(p.vertices - (long long)p.edges.size() + p.triangles == 2);
      const double box = (p.hi[0] - p.lo[0]) * (p.hi[1] - p.lo[1]) * (p.hi[2] - p.lo[2]);
      CHECK(box > 0);
      CHECK(std::fabs(p.volume - box) <= 1e-6 * box);
      CHECK(p.lo[2] == 0);
      CHECK(p.slivers > 0);
    }
    // Apart: no two bounding boxes meet.
    std::size_t meeting = 0;
    for (std::size_t i = 0; i < list.size(); ++i)
      for (std::size_t j = i + 1; j < list.size(); ++j) {
        bool apart = false;
        for (int a = 0; a < 2; ++a) apart = apart || list[i]->hi[a] < list[j]->lo[a] || list[j]->hi[a] < list[i]->lo[a];
        meeting += !apart;
      }
    CHECK(meeting == 0);
    // Long thin triangles: the top and bottom cells, most of the triangles, are about 4
    // times longer than wide (their counts rounded), the walls' thinner still, so the
    // median triangle's longest edge is about sqrt(17) = 4.12 times its shortest (a
    // 1 x 4 cell's diagonal against its short side); an equilateral one's is 1.
    std::nth_element(ratios.begin(), ratios.begin() + std::ptrdiff_t(ratios.size() / 2), ratios.end());
    CHECK(ratios[ratios.size() / 2] > 3.5);
  }
}

TEST_CASE("generation is deterministic by seed", "[generator]") {
  ScratchDir d;
  for (auto shape : {SyntheticShape::sphere, SyntheticShape::terrain, SyntheticShape::parts, SyntheticShape::boxes}) {
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

TEST_CASE("the plain output is the bytes it always was", "[generator]") {
  // XXH64 of whole files recorded from the generator before attributes existed
  // (commit 8e4b8cc): --attributes must leave the plain output alone.
  struct Expected {
    SyntheticShape shape;
    bool ascii;
    std::uint64_t digest;
  };
  const Expected expected[] = {
      {SyntheticShape::sphere, false, 0x8583b02ebe23f014}, {SyntheticShape::terrain, false, 0x24af1eaad4421a97},
      {SyntheticShape::parts, false, 0xc5ed852e02e71ceb},  {SyntheticShape::sphere, true, 0x4c9b305e1a44fead},
      {SyntheticShape::terrain, true, 0x4a999cb4190c821b}, {SyntheticShape::parts, true, 0xd7baebe7a65f0227},
  };
  ScratchDir d;
  for (const Expected& e : expected) {
    GenerateOptions o;
    o.shape = e.shape;
    o.triangles = 30000;
    o.seed = 5;
    o.ascii = e.ascii;
    generate_mesh(d.file("g.ply"), o);
    const std::string bytes = read_file(d.file("g.ply"));
    const std::uint64_t got = content_hash(bytes.data(), bytes.size());
    char line[96];
    std::snprintf(line, sizeof line, "shape %d ascii %d: 0x%016" PRIx64, int(e.shape), int(e.ascii), got);
    INFO(line);
    CHECK(got == e.digest);
  }
}

TEST_CASE("with attributes every vertex gets uchar red, green, blue and float nx, ny, nz", "[generator][attributes]") {
  ScratchDir d;
  for (auto shape : {SyntheticShape::sphere, SyntheticShape::terrain, SyntheticShape::parts, SyntheticShape::boxes}) {
    INFO("shape " << int(shape));
    const AttributedMesh a = generate_attributed(d, "a.ply", shape, 40000, 7);
    const char* names[] = {"red", "green", "blue", "nx", "ny", "nz"};
    REQUIRE(a.attributes.size() == 6);
    for (std::size_t k = 0; k < 6; ++k) {
      CHECK(a.attributes[k].name == names[k]);
      CHECK(a.attributes[k].type == (k < 3 ? AttributeType::u8 : AttributeType::f32));
    }
    // The option adds properties and changes no position or triangle.
    const LoadedMesh plain = generate(d, "p.ply", shape, 40000, 7);
    CHECK(a.mesh.positions == plain.positions);
    CHECK(a.mesh.triangles == plain.triangles);
    // Colours: 255 (p - lo) / (hi - lo) per axis over the bounding box of the positions
    // read back, rounded to nearest: within half a unit of 1/255.
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (std::size_t i = 0; i < a.mesh.positions.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], a.mesh.positions[i]);
      hi[i % 3] = std::max(hi[i % 3], a.mesh.positions[i]);
    }
    double worst_colour = 0, worst_length = 0;
    for (std::size_t i = 0; i < a.mesh.vertex_count(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const double expected = 255 * (a.mesh.positions[3 * i + std::size_t(k)] - lo[k]) / (hi[k] - lo[k]);
        worst_colour = std::max(worst_colour, std::fabs(a.colour(i)[k] - expected));
      }
      const double* n = a.normal(i);
      worst_length = std::max(worst_length, std::fabs(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) - 1));
    }
    CHECK(worst_colour <= 0.5 + 1e-9);
    // Unit in double, then each component rounded to float (relative 2^-24).
    CHECK(worst_length <= 1e-6);
    // Every normal faces the side the triangles face. The terrain's finest waves are
    // too steep for this tessellation to follow (its mesh normals are no reference
    // there); its normal (-h_x, -h_y, 1) points up by construction.
    if (shape == SyntheticShape::terrain) {
      double lowest = 1;
      for (std::size_t i = 0; i < a.mesh.vertex_count(); ++i) lowest = std::min(lowest, a.normal(i)[2]);
      CHECK(lowest > 0);
    } else {
      CHECK(worst_against_mesh_normals(a) < 90);
    }
  }
}

TEST_CASE("the sphere's normals are those of the displaced surface", "[generator][attributes]") {
  ScratchDir d;
  // The mesh's normal (its triangles' area-weighted normals about a vertex) differs from
  // the surface's by the turn of the surface across a triangle; the centred average
  // cancels the first-order term, so the difference shrinks with the square of the
  // spacing: a quarter for four times the triangles. A wrong formula would not shrink.
  const AttributedMesh coarse = generate_attributed(d, "c.ply", SyntheticShape::sphere, 250000);
  const AttributedMesh fine = generate_attributed(d, "f.ply", SyntheticShape::sphere, 1000000);
  const double worst_coarse = worst_against_mesh_normals(coarse), worst_fine = worst_against_mesh_normals(fine);
  INFO("worst angle to the mesh's normals: " << worst_coarse << " degrees at 250k triangles, " << worst_fine
                                             << " at 1M");
  CHECK(worst_fine <= worst_coarse / 3);
  CHECK(worst_fine <= 5.0);
  // Against the radial direction: the displacement f (amplitudes a_i = 0.04 / (i + 1),
  // wavenumbers k_i = 3 * 1.7^i, i < 8) tilts the normal by atan(|grad_s f| / r), and
  // |grad f| <= sum a_i k_i = 2.0, r >= 1 - sum a_i = 0.89: at most 66 degrees. The
  // fine waves are steep (the finest: a = 0.005, k = 123, a slope of 0.6), so the
  // normals are not within a few degrees of radial, and must not be.
  const double bound = std::atan(2.0 / 0.89) * 180 / kPi;
  double worst = 0, sum = 0;
  for (std::size_t i = 0; i < fine.mesh.vertex_count(); ++i) {
    const double angle = degrees_between(fine.normal(i), &fine.mesh.positions[3 * i]);
    worst = std::max(worst, angle);
    sum += angle;
  }
  INFO("angle to radial: worst " << worst << ", mean " << sum / double(fine.mesh.vertex_count()) << " degrees");
  CHECK(worst <= bound);
  CHECK(worst > 10);
}

TEST_CASE("with attributes the output is deterministic, the CLI's, and the same in ascii and compressed",
          "[generator][attributes]") {
  ScratchDir d;
  for (auto shape : {SyntheticShape::sphere, SyntheticShape::terrain, SyntheticShape::parts, SyntheticShape::boxes}) {
    GenerateOptions o;
    o.shape = shape;
    o.triangles = 20000;
    o.seed = 5;
    o.attributes = true;
    generate_mesh(d.file("a.ply"), o);
    generate_mesh(d.file("b.ply"), o);
    CHECK(read_file(d.file("a.ply")) == read_file(d.file("b.ply")));
    const std::string name = name_of(synthetic_shape_names(), shape);
    REQUIRE(run_cli("generate --attributes --quiet --tris 20000 --seed 5 --shape " + name + " -o " + d.file("cli.ply"))
                .exit_code == 0);
    CHECK(read_file(d.file("a.ply")) == read_file(d.file("cli.ply")));
    const AttributedMesh a = generate_attributed(d, "a.ply", shape, 20000, 5);
    const AttributedMesh t = generate_attributed(d, "t.ply", shape, 20000, 5, true);
    const AttributedMesh z = generate_attributed(d, "z.ply.zst", shape, 20000, 5);
    CHECK(a.mesh.positions == t.mesh.positions);
    CHECK(a.values == t.values);
    CHECK(a.values == z.values);
  }
}
