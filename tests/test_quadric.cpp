#include <catch2/catch.hpp>

#include <cmath>

#include "oocsimp/quadric.hpp"

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
