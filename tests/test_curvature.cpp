// Principal curvatures by integral invariants (Hua et al. §3.4) on analytic meshes made
// here: the expected values are the surfaces' own curvatures.
#include <tbb/global_control.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <utility>

#include "common/vec3_math.hpp"
#include "curvature/integral_invariants.hpp"
#include "curvature/vertex_curvatures.hpp"

using namespace oocsimp;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct TestMesh {
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;
};

// An icosahedron subdivided `levels` times, projected onto the sphere of `radius`
// about the origin, wound counter-clockwise seen from outside.
TestMesh icosphere(double radius, int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  TestMesh m;
  m.positions = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {0, 11, 5, 0, 5,  1,  0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
                 3, 9,  4, 3, 4,  2,  3, 2, 6, 3, 6,  8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};
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
  TestMesh m = icosphere(1, 4);
  for (std::size_t f = 0; f < m.triangles.size(); f += 3) std::swap(m.triangles[f + 1], m.triangles[f + 2]);
  const Curvatures c = estimate(m, 0.3);
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    CHECK(c.k1[v] == Approx(-1).epsilon(0.05));
    CHECK(c.k2[v] == Approx(-1).epsilon(0.05));
  }
}

TEST_CASE("curvature: a cylinder's side has 1/R and 0 within 5%; its open ends fall back to the fit") {
  const double R = 1.5, length = 6;
  const int around = 256, along = 240;
  // Vertices around the circle at angle 2 pi i / around, the seam joined by mapping
  // the last column onto the first.
  TestMesh m = grid(around, along, [&](int i, int j) {
    const double a = 2 * kPi * (i % around) / around;
    return Vec3d{R * std::cos(a), R * std::sin(a), length * j / along - length / 2};
  });
  for (std::uint32_t& v : m.triangles)
    if (v % (around + 1) == std::uint32_t(around)) v -= std::uint32_t(around);
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
  CHECK(checked > 100 * around);
}

TEST_CASE("curvature: the saddle z = (x^2 - y^2) / 2 has +1 and -1 at the origin within 5%") {
  const int n = 200;  // spacing 0.01 over [-1, 1]^2
  const TestMesh m = grid(n, n, [&](int i, int j) {
    const double x = 2.0 * i / n - 1, y = 2.0 * j / n - 1;
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
