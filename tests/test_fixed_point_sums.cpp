// Tests of the partition-independent cluster sums (src/cluster/fixed_point_sums.hpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "cluster/fixed_point_sums.hpp"

using namespace oocsimp;

TEST_CASE("fixed-point sums do not depend on the order or grouping of their terms", "[fixed]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3, 3);
  std::vector<double> terms(5000);
  for (double& t : terms) t = u(rng) * std::pow(10.0, double(int(rng() % 7)) - 3);
  Fixed forward;
  for (double t : terms) forward.add(Fixed::of(t));
  // Another order, in groups (as tiles and threads would sum them), then merged.
  std::shuffle(terms.begin(), terms.end(), rng);
  Fixed groups[7];
  for (std::size_t i = 0; i < terms.size(); ++i) groups[i % 7].add(Fixed::of(terms[i]));
  Fixed merged;
  for (const Fixed& g : groups) merged.add(g.v);
  CHECK(merged.v == forward.v);
  // And the value is the sum to within the rounding of each term (2^-33).
  double exact = 0;
  for (double t : terms) exact += t;
  CHECK(std::fabs(forward.value() - exact) <= double(terms.size()) * std::ldexp(1.0, -33) + 1e-9);
}

TEST_CASE("fixed-point conversion rounds to nearest, ties to even, like nearbyint", "[fixed]") {
  for (double x : {0.0, 1.0, -1.0, 0.5, -0.5, 1.5, 2.5, -2.5, 1e-12, 123456.789, -98765.4321, 3.0e5, 1.0e6, -1.0e8})
    for (double k : {1.0, 1.0 + 1e-16, 1.0 - 1e-16}) {
      double v = x * k;
      INFO("x = " << v);
      CHECK(Fixed::of(v) == std::int64_t(std::nearbyint(v * Fixed::kScale)));
    }
  // Ties in fixed-point units: 0.5 and 1.5 units round to 0 and 2.
  CHECK(Fixed::of(0.5 / Fixed::kScale) == 0);
  CHECK(Fixed::of(1.5 / Fixed::kScale) == 2);
  CHECK(Fixed::of(-2.5 / Fixed::kScale) == -2);
}

TEST_CASE("fixed-point sums refuse values and totals out of range", "[fixed]") {
  CHECK_THROWS_AS(Fixed::of(3.0e9), std::overflow_error);  // beyond 2^31 in 32.32
  CHECK_THROWS_AS(Fixed::of(std::numeric_limits<double>::quiet_NaN()), std::overflow_error);
  CHECK_THROWS_AS(Fixed::of(std::numeric_limits<double>::infinity()), std::overflow_error);
  Fixed f;
  f.add(Fixed::of(2.0e9));
  CHECK_THROWS_AS(f.add(Fixed::of(2.0e9)), std::overflow_error);
}

namespace {

Quadric random_quadric(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-2, 2);
  Quadric q;
  q.a00 = u(rng);
  q.a01 = u(rng);
  q.a02 = u(rng);
  q.a11 = u(rng);
  q.a12 = u(rng);
  q.a22 = u(rng);
  q.b0 = u(rng);
  q.b1 = u(rng);
  q.b2 = u(rng);
  q.c = u(rng);
  return q;
}

}  // namespace

TEST_CASE("cluster records merge their sums and member counts", "[fixed]") {
  ClusterRecord a, b;
  Quadric qa, qb;
  qa.a00 = 1, qa.a01 = 2, qa.a02 = 3, qa.a11 = 4, qa.a12 = 5, qa.a22 = 6, qa.b0 = 7, qa.b1 = 8, qa.b2 = 9;
  qb.a00 = -0.5, qb.a01 = -1, qb.a02 = -1.5, qb.a11 = -2, qb.a12 = -2.5, qb.a22 = -3, qb.b0 = -3.5, qb.b1 = -4,
  qb.b2 = -4.5;
  a.add_vertex(qa, {0.25, -0.5, 0.125});
  a.add_vertex(qa, {0.25, 0.5, 0.125});
  b.add_vertex(qb, {-0.5, 0.25, 0.375});
  a.add(b);
  CHECK(a.members == 3);
  // Every term is a multiple of 2^-3: the fixed-point sums are exact.
  Quadric q = a.quadric();
  CHECK(q.a00 == 1.5);
  CHECK(q.a01 == 3);
  CHECK(q.a02 == 4.5);
  CHECK(q.a11 == 6);
  CHECK(q.a12 == 7.5);
  CHECK(q.a22 == 9);
  CHECK(q.b0 == 10.5);
  CHECK(q.b1 == 12);
  CHECK(q.b2 == 13.5);
  CHECK(q.c == 0);  // not summed
  Vec3d m = a.mean();
  CHECK(m.x == 0);
  CHECK(m.y == 0.25 / 3);
  CHECK(m.z == 0.625 / 3);
  CHECK(ClusterRecord().mean().x == 0);  // no members: no division by zero
}

TEST_CASE("cluster records give the same fixed-point totals for any grouping of their vertices", "[fixed]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<std::pair<Quadric, Vec3d>> vertices(2000);
  for (auto& v : vertices) v = {random_quadric(rng), {u(rng), u(rng), u(rng)}};
  auto fields = [](const ClusterRecord& r) {
    const FixedQuadric& q = r.quadric_sum;
    const FixedVec3& o = r.offset_sum;
    return std::vector<std::int64_t>{q.a00.v,
                                     q.a01.v,
                                     q.a02.v,
                                     q.a11.v,
                                     q.a12.v,
                                     q.a22.v,
                                     q.b0.v,
                                     q.b1.v,
                                     q.b2.v,
                                     o.x.v,
                                     o.y.v,
                                     o.z.v,
                                     std::int64_t(r.members)};
  };
  ClusterRecord one;
  for (const auto& v : vertices) one.add_vertex(v.first, v.second);
  // Reference: each field is the integer sum of Fixed::of of that coefficient.
  std::vector<std::int64_t> expected(13, 0);
  for (const auto& v : vertices) {
    const Quadric& q = v.first;
    const double terms[12] = {q.a00, q.a01, q.a02, q.a11,      q.a12,      q.a22,
                              q.b0,  q.b1,  q.b2,  v.second.x, v.second.y, v.second.z};
    for (int k = 0; k < 12; ++k) expected[k] += Fixed::of(terms[k]);
  }
  expected[12] = std::int64_t(vertices.size());
  CHECK(fields(one) == expected);
  // Shuffled into 13 shares (as tiles would hold them), merged in another order.
  std::shuffle(vertices.begin(), vertices.end(), rng);
  ClusterRecord shares[13];
  for (std::size_t i = 0; i < vertices.size(); ++i)
    shares[(i * 7) % 13].add_vertex(vertices[i].first, vertices[i].second);
  ClusterRecord merged = shares[12];
  for (int i = 11; i >= 0; --i) merged.add(shares[i]);
  CHECK(fields(merged) == expected);
}
