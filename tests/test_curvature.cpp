// Principal curvatures by integral invariants (Hua et al. §3.4) on analytic meshes made
// here: the expected values are the surfaces' own curvatures.
#include <tbb/global_control.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <utility>

#include <sstream>

#include "common/math_constants.hpp"
#include "common/vec3_math.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"
#include "curvature/integral_invariants.hpp"
#include "curvature/mesh_curvatures.hpp"
#include "curvature/vertex_curvatures.hpp"

using namespace oocsimp;

namespace {

struct TestMesh {
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;
};

// An icosahedron subdivided `levels` times, projected onto the sphere of `radius`
// about the origin, wound counter-clockwise seen from outside.
TestMesh icosphere(double radius, int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  TestMesh m;
  m.positions = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
                 3, 9,  4, 3, 4, 2, 3, 2, 6, 3, 6, 8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      m.positions.push_back((m.positions[a] + m.positions[b]) * 0.5);
      return middle[key] = std::uint32_t(m.positions.size() - 1);
    };
    std::vector<std::uint32_t> finer;
    for (std::size_t f = 0; f < m.triangles.size(); f += 3) {
      const std::uint32_t a = m.triangles[f], b = m.triangles[f + 1], c = m.triangles[f + 2];
      const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      finer.insert(finer.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.triangles = std::move(finer);
  }
  for (Vec3d& p : m.positions) p = p * (radius / length(p));
  return m;
}

// A grid of (nu + 1) x (nv + 1) vertices, each quad cut into two triangles wound
// counter-clockwise seen along +u x +v.
template <class Point>
TestMesh grid(int nu, int nv, const Point& point) {
  TestMesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) m.positions.push_back(point(i, j));
  auto at = [&](int i, int j) { return std::uint32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      m.triangles.insert(m.triangles.end(),
                         {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

// An open tube of radius R along z over [-length/2, length/2]: `around` vertices on
// each circle (at angle 2 pi i / around), `along` rings of faces, the seam joined by
// mapping the grid's last column onto its first.
TestMesh tube(double R, double length, int around, int along) {
  TestMesh m = grid(around, along, [&](int i, int j) {
    const double a = 2 * kPi * (i % around) / around;
    return Vec3d{R * std::cos(a), R * std::sin(a), length * j / along - length / 2};
  });
  for (std::uint32_t& v : m.triangles)
    if (v % (around + 1) == std::uint32_t(around)) v -= std::uint32_t(around);
  return m;
}

// A MeshView of a test mesh, over its positions as packed doubles.
struct ViewOf {
  std::vector<double> xyz;
  MeshView view;
  explicit ViewOf(const TestMesh& m) {
    for (const Vec3d& p : m.positions) xyz.insert(xyz.end(), {p.x, p.y, p.z});
    view.positions = xyz.data();
    view.position_type = ScalarType::f64;
    view.vertex_count = m.positions.size();
    view.indices = m.triangles.data();
    view.triangle_count = m.triangles.size() / 3;
  }
};

struct Curvatures {
  std::vector<float> k1, k2;
  VertexCurvatureCounts counts;
};

Curvatures estimate(const TestMesh& m, double radius, CurvatureNeighbourhood n = CurvatureNeighbourhood::ball) {
  Curvatures c;
  VertexCurvatureSettings s;
  s.radius = radius;
  s.neighbourhood = n;
  c.counts = vertex_curvatures(m.positions, m.triangles, s, &c.k1, &c.k2);
  return c;
}

}  // namespace

TEST_CASE("curvature: a sphere has k1 = k2 = 1/R within 3% at every vertex, both neighbourhoods") {
  const double R = 2;
  const TestMesh m = icosphere(R, 5);  // 10242 vertices, edges about 0.07 R
  for (CurvatureNeighbourhood n : {CurvatureNeighbourhood::ball, CurvatureNeighbourhood::sphere}) {
    const Curvatures c = estimate(m, 0.3 * R, n);
    CHECK(c.counts.invariant == m.positions.size());
    double worst = 0;
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      worst = std::max(worst, std::fabs(c.k1[v] * R - 1));
      worst = std::max(worst, std::fabs(c.k2[v] * R - 1));
    }
    INFO("neighbourhood " << int(n) << ": worst relative error " << worst);
    CHECK(worst < 0.03);
  }
}

TEST_CASE("curvature: the sign follows the outward normal: a sphere wound inside out is concave") {
  TestMesh m = icosphere(1, 4);  // coarser than above (edges 0.14 R): within 10%
  for (std::size_t f = 0; f < m.triangles.size(); f += 3) std::swap(m.triangles[f + 1], m.triangles[f + 2]);
  const Curvatures c = estimate(m, 0.3);
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    CHECK(c.k1[v] == Approx(-1).epsilon(0.1));
    CHECK(c.k2[v] == Approx(-1).epsilon(0.1));
  }
}

TEST_CASE("curvature: a cylinder's side has 1/R and 0 within 5%, and its open ends fall back to the fit") {
  const double R = 1.5, length = 2.4;
  const int around = 256, along = 96;
  const TestMesh m = tube(R, length, around, along);
  const double radius = 0.3;
  const Curvatures c = estimate(m, radius);
  CHECK(c.counts.fitted > 0);  // the ends
  int checked = 0;
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    if (v % (around + 1) == std::size_t(around) || std::fabs(m.positions[v].z) > length / 2 - 2 * radius) continue;
    ++checked;
    CHECK(c.k1[v] * R == Approx(1).epsilon(0.05));
    CHECK(std::fabs(c.k2[v]) * R < 0.05);
  }
  CHECK(checked > 20 * around);
}

TEST_CASE("curvature: the saddle z = (x^2 - y^2) / 2 has +1 and -1 at the origin within 5%") {
  const int n = 60;  // spacing 0.01 over [-0.3, 0.3]^2
  const TestMesh m = grid(n, n, [&](int i, int j) {
    const double x = 0.6 * i / n - 0.3, y = 0.6 * j / n - 0.3;
    return Vec3d{x, y, (x * x - y * y) / 2};
  });
  const std::size_t origin = std::size_t(n / 2) * (n + 1) + std::size_t(n / 2);
  REQUIRE(length(m.positions[origin]) == 0);
  for (CurvatureNeighbourhood neighbourhood : {CurvatureNeighbourhood::ball, CurvatureNeighbourhood::sphere}) {
    const Curvatures c = estimate(m, 0.1, neighbourhood);
    CHECK(c.k1[origin] == Approx(1).epsilon(0.05));
    CHECK(c.k2[origin] == Approx(-1).epsilon(0.05));
  }
}

TEST_CASE("curvature: the same values for any thread count") {
  const TestMesh m = icosphere(1, 4);
  Curvatures one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = estimate(m, 0.25);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = estimate(m, 0.25);
  }
  CHECK(one.k1 == two.k1);
  CHECK(one.k2 == two.k2);
}

TEST_CASE("curvature: a lone triangle, a soup and an unused vertex give finite values and say how") {
  TestMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}};
  m.triangles = {0, 1, 2};
  const Curvatures c = estimate(m, 0.5);
  CHECK(c.counts.invariant == 0);
  CHECK(c.counts.none == 4);  // too few points to fit, and the unused vertex
  for (std::size_t v = 0; v < 4; ++v) CHECK((c.k1[v] == 0 && c.k2[v] == 0));
  // A soup: the sphere's triangles, each with corners of its own. No triangle reaches
  // another, so every vertex has only its own face: too little for either estimate.
  const TestMesh sphere = icosphere(1, 2);
  TestMesh soup;
  for (std::uint32_t v : sphere.triangles) {
    soup.triangles.push_back(std::uint32_t(soup.positions.size()));
    soup.positions.push_back(sphere.positions[v]);
  }
  const Curvatures s = estimate(soup, 0.3);
  CHECK(s.counts.none == soup.positions.size());
  for (std::size_t v = 0; v < soup.positions.size(); ++v) CHECK((std::isfinite(s.k1[v]) && std::isfinite(s.k2[v])));
}

TEST_CASE("curvature: the quadratic fit recovers a paraboloid's curvatures") {
  std::vector<Vec3d> points;
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j) {
      if (i == 0 && j == 0) continue;
      const double x = 0.01 * i, y = 0.01 * j;
      points.push_back({x, y, -(2 * x * x + 0.5 * y * y) / 2});  // convex: 2 and 0.5
    }
  PrincipalCurvatures k;
  REQUIRE(quadratic_fit_curvatures(points, &k));
  CHECK(k.k1 == Approx(2).epsilon(1e-9));
  CHECK(k.k2 == Approx(0.5).epsilon(1e-9));
}

namespace {

void write_mesh_ply(const std::string& path, const TestMesh& m) {
  std::vector<float> xyz;
  for (const Vec3d& p : m.positions) xyz.insert(xyz.end(), {float(p.x), float(p.y), float(p.z)});
  oocsimp_test::write_binary_ply(path, xyz, m.triangles);
}

// The k1 and k2 columns of an ascii PLY that `oocsimp curvature --ascii` wrote.
std::vector<std::pair<double, double>> read_curvature_ply(const std::string& path, std::size_t vertices) {
  std::istringstream in(oocsimp_test::read_file(path));
  std::string line;
  bool k1 = false, k2 = false;
  while (std::getline(in, line) && line != "end_header") {
    k1 = k1 || line == "property float k1";
    k2 = k2 || line == "property float k2";
  }
  REQUIRE((k1 && k2));
  std::vector<std::pair<double, double>> k(vertices);
  for (auto& [a, b] : k) {
    double x, y, z;
    in >> x >> y >> z >> a >> b;
  }
  return k;
}

}  // namespace

TEST_CASE("curvature CLI: a sphere's PLY gets k1 and k2 of 1/R, and bad radii and outputs exit 2") {
  oocsimp_test::ScratchDir dir;
  // Level 4 (edges 0.075 R): within 5% here; test_curvature's first case holds the
  // 3% of a finer sphere.
  const double R = 3;
  const TestMesh m = icosphere(R, 4);
  write_mesh_ply(dir.file("sphere.ply"), m);
  const oocsimp_test::CliResult ok = oocsimp_test::run_cli("curvature " + dir.file("sphere.ply") + " -o " +
                                                           dir.file("k.ply") + " --ascii --radius 1.2");
  REQUIRE(ok.exit_code == 0);
  CHECK(ok.out.find("estimated 2562 by the invariants") != std::string::npos);
  for (const auto& [k1, k2] : read_curvature_ply(dir.file("k.ply"), m.positions.size())) {
    CHECK(k1 * R == Approx(1).epsilon(0.05));
    CHECK(k2 * R == Approx(1).epsilon(0.05));
  }
  // The default radius (5 mean edges) and the sphere's neighbourhood.
  REQUIRE(oocsimp_test::run_cli("curvature " + dir.file("sphere.ply") + " -o " + dir.file("d.ply") +
                                " --ascii --neighbourhood sphere")
              .exit_code == 0);
  for (const auto& [k1, k2] : read_curvature_ply(dir.file("d.ply"), m.positions.size())) {
    CHECK(k1 * R == Approx(1).epsilon(0.05));
    CHECK(k2 * R == Approx(1).epsilon(0.05));
  }
  for (const char* bad : {"--radius 0", "--radius -1", "--radius nan", "--radius inf", "--radius 100"}) {
    const oocsimp_test::CliResult r =
        oocsimp_test::run_cli("curvature " + dir.file("sphere.ply") + " -o " + dir.file("x.ply") + " " + bad);
    INFO(bad << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("--radius") != std::string::npos);
  }
  const oocsimp_test::CliResult obj =
      oocsimp_test::run_cli("curvature " + dir.file("sphere.ply") + " -o " + dir.file("x.obj"));
  CHECK(obj.exit_code == 2);
  const oocsimp_test::CliResult mem =
      oocsimp_test::run_cli("curvature " + dir.file("sphere.ply") + " -o " + dir.file("x.ply") + " --mem 100k");
  CHECK(mem.exit_code == 2);
  CHECK(mem.err.find("--mem") != std::string::npos);
  oocsimp_test::write_file(dir.file("bad.ply"),
                           "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                           "property float x\nproperty float y\nproperty float z\nend_header\n");
  CHECK(oocsimp_test::run_cli("curvature " + dir.file("bad.ply") + " -o " + dir.file("x.ply")).exit_code == 3);
  // Nothing but the inputs and the two outputs that succeeded is left.
  CHECK(dir.entries() == std::vector<std::string>{"bad.ply", "d.ply", "k.ply", "sphere.ply"});
}

TEST_CASE("curvature library: estimate_curvatures on a MeshView gives what the command writes, with its counts") {
  const TestMesh m = icosphere(1, 3);
  const ViewOf of(m);
  const MeshView& view = of.view;
  CurvatureOptions o;
  o.radius = 0.4;
  const VertexCurvatures k = estimate_curvatures(view, o);
  const Curvatures direct = estimate(m, 0.4);
  CHECK(k.k1 == direct.k1);
  CHECK(k.k2 == direct.k2);
  CHECK(k.stats.vertices == m.positions.size());
  CHECK(k.stats.invariant == m.positions.size());
  CHECK(k.stats.radius == 0.4);
  o.radius = -1;
  CHECK_THROWS_AS(estimate_curvatures(view, o), UsageError);
}

TEST_CASE("curvature in tiles: the values in memory, for any tile side and thread count, outlines included") {
  // An open tube: its ends are outlines, and tiles cut it across and along.
  const double R = 1;
  const int around = 64, along = 40;
  const TestMesh m = tube(R, 2, around, along);
  const ViewOf of(m);
  const MeshView& view = of.view;
  CurvatureOptions o;
  o.radius = 0.35;
  const VertexCurvatures whole = estimate_curvatures(view, o);
  REQUIRE(whole.stats.tile_side == 0);
  CHECK(whole.stats.fitted > 0);
  o.neighbourhood = CurvatureNeighbourhood::sphere;
  const VertexCurvatures whole_sphere = estimate_curvatures(view, o);
  for (double side : {0.45, 0.8, 1.7}) {
    o.tile_side = side;
    o.threads = 1;
    const VertexCurvatures tiled = estimate_curvatures(view, o);
    INFO("the sphere's neighbourhood, tile side " << side);
    CHECK(tiled.k1 == whole_sphere.k1);
    CHECK(tiled.k2 == whole_sphere.k2);
  }
  o.neighbourhood = CurvatureNeighbourhood::ball;
  for (double side : {0.45, 0.8, 1.7}) {
    for (unsigned threads : {1u, 2u}) {
      o.tile_side = side;
      o.threads = threads;
      const VertexCurvatures tiled = estimate_curvatures(view, o);
      INFO("tile side " << side << ", " << threads << " threads");
      CHECK(tiled.stats.tile_side == side);
      CHECK(tiled.k1 == whole.k1);
      CHECK(tiled.k2 == whole.k2);
      CHECK(tiled.stats.invariant == whole.stats.invariant);
      CHECK(tiled.stats.fitted == whole.stats.fitted);
      CHECK(tiled.stats.none == whole.stats.none);
    }
  }
}

TEST_CASE("curvature CLI in tiles: the same bytes as in memory, and a budget too small for a tile exits 2") {
  oocsimp_test::ScratchDir dir;
  write_mesh_ply(dir.file("sphere.ply"), icosphere(1, 3));
  const std::string in = dir.file("sphere.ply");
  REQUIRE(oocsimp_test::run_cli("curvature " + in + " -o " + dir.file("whole.ply") + " --radius 0.4").exit_code == 0);
  const oocsimp_test::CliResult tiled = oocsimp_test::run_cli("curvature " + in + " -o " + dir.file("tiled.ply") +
                                                              " --radius 0.4 --tile 0.6 --threads 1");
  REQUIRE(tiled.exit_code == 0);
  CHECK(tiled.out.find("in tiles of side 0.6") != std::string::npos);
  CHECK(oocsimp_test::read_file(dir.file("tiled.ply")) == oocsimp_test::read_file(dir.file("whole.ply")));
  const oocsimp_test::CliResult small =
      oocsimp_test::run_cli("curvature " + in + " -o " + dir.file("x.ply") + " --radius 0.4 --mem 20k");
  CHECK(small.exit_code == 2);
  CHECK(small.err.find("--mem") != std::string::npos);
  CHECK(small.err.find("give at least") != std::string::npos);
  CHECK(dir.entries() == std::vector<std::string>{"sphere.ply", "tiled.ply", "whole.ply"});
}

TEST_CASE("curvature parts: the deals of 1 to 5 parts give each finite vertex to exactly one part, in balance") {
  // An icosphere and a far outlier (the box's blocks then hold the sphere in a corner),
  // and a non-finite vertex, which no part estimates.
  TestMesh m = icosphere(1, 4);
  m.positions.push_back({40, 40, 40});
  std::vector<float> xyz;
  for (const Vec3d& p : m.positions) xyz.insert(xyz.end(), {float(p.x), float(p.y), float(p.z)});
  xyz.insert(xyz.end(), {std::nanf(""), 0, 0});
  PositionArray positions;
  positions.base = reinterpret_cast<const unsigned char*>(xyz.data());
  positions.count = xyz.size() / 3;
  Box3d bounds;
  for (std::uint64_t v = 0; v + 1 < positions.count; ++v) bounds.add(positions.get(v));
  for (std::uint32_t parts = 1; parts <= 5; ++parts) {
    std::vector<int> owners(positions.count, 0);
    std::vector<std::uint64_t> share(parts, 0);
    for (std::uint32_t part = 0; part < parts; ++part) {
      const VertexDeal deal(positions, bounds, part, parts);
      for (std::uint64_t v = 0; v < positions.count; ++v)
        if (deal.owns(positions.get(v))) {
          ++owners[v];
          ++share[part];
        }
    }
    INFO(parts << " parts");
    for (std::uint64_t v = 0; v + 1 < positions.count; ++v) CHECK(owners[v] == 1);
    CHECK(owners.back() == 0);
    // Blocks of 1/32 of the box dealt by weight: no part more than a few blocks'
    // vertices past an even share.
    const double even = double(positions.count - 1) / parts;
    for (std::uint64_t n : share) CHECK(double(n) <= even * 1.1 + 64);
  }
}
