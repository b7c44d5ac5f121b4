// Tests of the partition-independent cluster sums (src/cluster/fixed_point_sums.hpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
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

TEST_CASE("cluster records merge their sums and member counts", "[fixed]") {
  ClusterRecord a, b;
  for (int i = 0; i < 12; ++i) {
    a.sum[i].add(Fixed::of(0.25 * i));
    b.sum[i].add(Fixed::of(-0.125 * i));
  }
  a.members = 3;
  b.members = 4;
  a.add(b);
  CHECK(a.members == 7);
  for (int i = 0; i < 12; ++i) CHECK(a.sum[i].value() == 0.125 * i);
}
