// Tests of the internal vector arithmetic (src/common/vec3_math.hpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

#include "common/vec3_math.hpp"

using namespace oocsimp;

namespace {
bool same(const Vec3d& a, const Vec3d& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
}  // namespace

TEST_CASE("cross product of the axes is the right-handed one", "[vec3]") {
  const Vec3d x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  CHECK(same(cross(x, y), z));
  CHECK(same(cross(y, z), x));
  CHECK(same(cross(z, x), y));
  CHECK(same(cross(y, x), -z));
  CHECK(same(cross(x, x), {0, 0, 0}));
}

TEST_CASE("cross and dot satisfy the vector identities", "[vec3]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int i = 0; i < 1000; ++i) {
    Vec3d a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    Vec3d c = cross(a, b);
    double scale = squared_length(a) * squared_length(b);
    // Orthogonal to both factors, and |a x b|^2 = |a|^2 |b|^2 - (a.b)^2 (Lagrange).
    CHECK(std::fabs(dot(c, a)) <= 1e-12 * scale);
    CHECK(std::fabs(dot(c, b)) <= 1e-12 * scale);
    CHECK(squared_length(c) == Approx(scale - dot(a, b) * dot(a, b)).margin(1e-9 * scale));
    CHECK(same(cross(b, a), -c));
  }
}

TEST_CASE("lengths, distances and component-wise operations", "[vec3]") {
  CHECK(length(Vec3d{3, 4, 12}) == 13);
  CHECK(squared_length(Vec3d{1, 2, 2}) == 9);
  CHECK(distance(Vec3d{1, 1, 1}, Vec3d{4, 5, 1}) == 5);
  CHECK(squared_distance(Vec3d{1, 1, 1}, Vec3d{4, 5, 1}) == 25);
  CHECK(dot(Vec3d{1, 2, 3}, Vec3d{4, -5, 6}) == 12);
  CHECK(same(Vec3d{1, 2, 3} + Vec3d{10, 20, 30}, {11, 22, 33}));
  CHECK(same(Vec3d{1, 2, 3} - Vec3d{10, 20, 30}, {-9, -18, -27}));
  CHECK(same(Vec3d{1, 2, 3} * 2.0, {2, 4, 6}));
  CHECK(same(0.5 * Vec3d{1, 2, 3}, {0.5, 1, 1.5}));
  // Division divides each coordinate (1/3 is not multiplied in).
  CHECK(same(Vec3d{1, 2, 3} / 3.0, {1.0 / 3.0, 2.0 / 3.0, 1.0}));
  Vec3d v{1, 1, 1};
  v += Vec3d{1, 2, 3};
  v -= Vec3d{0.5, 0.5, 0.5};
  CHECK(same(v, {1.5, 2.5, 3.5}));
  CHECK(same(min(Vec3d{1, 5, -2}, Vec3d{3, 4, -7}), {1, 4, -7}));
  CHECK(same(max(Vec3d{1, 5, -2}, Vec3d{3, 4, -7}), {3, 5, -2}));
  // Like std::min/std::max: a NaN in the second argument is ignored.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(same(min(Vec3d{1, 2, 3}, Vec3d{nan, nan, nan}), {1, 2, 3}));
  CHECK(same(max(Vec3d{1, 2, 3}, Vec3d{nan, nan, nan}), {1, 2, 3}));
}
