#include <catch2/catch.hpp>

#include <cmath>

#include "cluster/plane_quadric.hpp"
#include "common/vec3_math.hpp"
#include "cluster/quadric.hpp"

using namespace oocsimp;

namespace {
const Vec3d kLo{-10, -10, -10}, kHi{10, 10, 10};

double dist(const Vec3d& a, const Vec3d& b) {
  return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}
}  // namespace

TEST_CASE("plane quadric measures area-weighted squared distance", "[quadric]") {
  Quadric q;
  q.add_triangle({0, 0, 2}, {2, 0, 2}, {0, 2, 2});  // area 2, plane z = 2
  CHECK(q.error({5, -3, 2}) == Approx(0).margin(1e-12));
  CHECK(q.error({0, 0, 5}) == Approx(2 * 9));
  CHECK(q.error({1, 1, 1}) == Approx(2 * 1));
}

TEST_CASE("zero-area triangle adds nothing", "[quadric]") {
  Quadric q;
  q.add_triangle({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  CHECK(q.a00 == 0);
  CHECK(q.c == 0);
}

TEST_CASE("three planes pin down their corner", "[quadric]") {
  Quadric q;
  q.add_triangle({1, 0, 0}, {1, 1, 0}, {1, 0, 1});  // x = 1
  q.add_triangle({0, 2, 0}, {0, 2, 1}, {1, 2, 0});  // y = 2
  q.add_triangle({0, 0, 3}, {1, 0, 3}, {0, 1, 3});  // z = 3
  Vec3d x = minimize_quadric(q, {0, 0, 0}, kLo, kHi);
  CHECK(dist(x, {1, 2, 3}) < 1e-12);
}

TEST_CASE("a flat quadric projects the anchor onto its plane", "[quadric]") {
  Quadric q;
  q.add_triangle({0, 0, 1}, {1, 0, 1}, {0, 1, 1});
  q.add_triangle({3, 3, 1}, {4, 3, 1}, {3, 4, 1});
  Vec3d x = minimize_quadric(q, {0.25, -0.5, 7}, kLo, kHi);
  CHECK(dist(x, {0.25, -0.5, 1}) < 1e-12);
}

TEST_CASE("a crease quadric projects the anchor onto its line", "[quadric]") {
  Quadric q;
  q.add_triangle({0, 0, 0}, {0, 1, 0}, {0, 0, 1});  // x = 0
  q.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 0, 1});  // y = 0: the line is the z axis
  Vec3d x = minimize_quadric(q, {0.3, 0.4, 0.7}, kLo, kHi);
  CHECK(dist(x, {0, 0, 0.7}) < 1e-12);
}

TEST_CASE("a nearly flat quadric is treated as flat (relative threshold)", "[quadric]") {
  // A large plane and a tiny sliver of a steep one: the small eigenvalue is below
  // 1e-3 of the largest, so the solve must not jump along the weak direction.
  Quadric q;
  q.add_triangle({0, 0, 0}, {10, 0, 0}, {0, 10, 0});
  q.add_triangle({0, 0, 0}, {0, 0.001, 0}, {0, 0, 0.001});
  Vec3d x = minimize_quadric(q, {1, 1, 0.5}, kLo, kHi);
  CHECK(std::fabs(x.z) < 1e-12);
  CHECK(x.x == Approx(1));
  CHECK(x.y == Approx(1));
}

TEST_CASE("minimiser is clamped into the cell", "[quadric]") {
  Quadric q;
  q.add_triangle({5, 0, 0}, {5, 1, 0}, {5, 0, 1});
  q.add_triangle({0, 5, 0}, {0, 5, 1}, {1, 5, 0});
  q.add_triangle({0, 0, 5}, {1, 0, 5}, {0, 1, 5});
  Vec3d x = minimize_quadric(q, {0.5, 0.5, 0.5}, {0, 0, 0}, {1, 1, 1});
  CHECK(dist(x, {1, 1, 1}) < 1e-12);
}

TEST_CASE("an empty quadric returns the anchor", "[quadric]") {
  Quadric q;
  Vec3d x = minimize_quadric(q, {0.1, 0.2, 0.3}, kLo, kHi);
  CHECK(dist(x, {0.1, 0.2, 0.3}) == 0);
}

TEST_CASE("triangle_plane gives the normal and twice the area, degenerate triangles no plane", "[quadric]") {
  TrianglePlane t = triangle_plane({3, 0, 0}, {0, 4, 0});  // legs 3 and 4: area 6
  CHECK(t.m.x == 0);
  CHECK(t.m.y == 0);
  CHECK(t.m.z == 12);
  CHECK(t.len == 12);
  CHECK_FALSE(t.degenerate());
  CHECK(triangle_plane({1, 2, 3}, {2, 4, 6}).degenerate());  // collinear
  CHECK(triangle_plane({0, 0, 0}, {0, 0, 0}).degenerate());
}

TEST_CASE("a plane quadric added in a shifted, scaled frame measures the same area-weighted distances", "[quadric]") {
  // The floating method adds each face in cell units relative to a cluster centre:
  // lengths scale by s, so area * distance^2 scales by s^4.
  const Vec3d p{1.5, -2, 0.25}, q{3, 1, -1}, r{-0.5, 2.5, 2};
  Quadric world;
  world.add_triangle(p, q, r);
  const Vec3d c{0.75, 0.5, -0.25};
  const double s = 1.0 / 0.3;  // 1 / cell size
  TrianglePlane plane = triangle_plane((q - p) * s, (r - p) * s);
  Quadric local;
  add_plane_quadric(&local, plane, dot(plane.m, (p - c) * s));
  for (const Vec3d& x : {Vec3d{0, 0, 0}, Vec3d{1, 2, 3}, Vec3d{-4, 0.5, 2}, p, q}) {
    double e = world.error(x) * s * s * s * s;
    CHECK(local.error((x - c) * s) == Approx(e).margin(1e-9 * (1 + e)));
  }
  // And a point of the plane has no error; one at distance h, area * h^2.
  double area = 0.5 * length(cross(q - p, r - p));
  Vec3d n = cross(q - p, r - p) / length(cross(q - p, r - p));
  CHECK(world.error((p + q + r) / 3) == Approx(0).margin(1e-12));
  CHECK(world.error(p + n * 0.7) == Approx(area * 0.49));
}

TEST_CASE("a quadric translated by an offset measures the same distances at the moved points", "[quadric]") {
  // Two triangles' planes summed in a frame whose origin is o; in model units the
  // same planes pass through their points plus o, so the translated quadric at x + o
  // is the first at x, and so is the quadric of the triangles added in model units.
  const Vec3d o{1000.5, -250.25, 40};
  const Vec3d p{1.5, -2, 0.25}, q{3, 1, -1}, r{-0.5, 2.5, 2}, t{0.5, 0.5, 4};
  Quadric local, model;
  local.add_triangle(p, q, r);
  local.add_triangle(p, r, t);
  model.add_triangle(p + o, q + o, r + o);
  model.add_triangle(p + o, r + o, t + o);
  const Quadric moved = local.translated(o);
  for (const Vec3d& x : {Vec3d{0, 0, 0}, Vec3d{1, 2, 3}, Vec3d{-4, 0.5, 2}, p, q, t}) {
    const double e = local.error(x);
    CHECK(moved.error(x + o) == Approx(e).margin(1e-6 * (1 + e)));
    CHECK(model.error(x + o) == Approx(e).margin(1e-6 * (1 + e)));
  }
  // A is unchanged; only the linear and constant terms move.
  CHECK(moved.a00 == local.a00);
  CHECK(moved.a12 == local.a12);
  // No offset: the same quadric.
  const Quadric same = local.translated({0, 0, 0});
  CHECK(same.b0 == local.b0);
  CHECK(same.c == local.c);
}
