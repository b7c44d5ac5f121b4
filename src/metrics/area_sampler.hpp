// Area-uniform, seeded sampling of a triangle stream (metrics/).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "common/triangle_geometry.hpp"

namespace oocsimp {
namespace metrics {

/// The SplitMix64 output function (Steele, Lea & Flood, 2014): a bijective 64-bit
/// mix, so consecutive seeds give unrelated streams.
inline std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// A small counter-based generator: SplitMix64 from an arbitrary 64-bit state.
class SampleRng {
 public:
  explicit SampleRng(std::uint64_t state) : state_(state) {}
  /// Uniform in [0, 1) with 53 random bits.
  double unit() {
    state_ += 0x9E3779B97F4A7C15ull;
    return double(mix64(state_) >> 11) * (1.0 / 9007199254740992.0);
  }

 private:
  std::uint64_t state_;
};

/// Systematic sampling over the cumulative area of a surface read triangle by triangle:
/// sample positions lie at offset + m * step (m = 0 .. count-1, step = total / count,
/// seeded offset in [0, step)) along the concatenated triangle areas, and triangle k
/// receives the positions that fall in its stretch. Every triangle thus gets its area
/// share to within one sample, zero-area triangles get none, and the counts depend only
/// on the areas in stream order — not on how the stream is cut into chunks or threads.
/// Within a triangle the points are uniform, drawn from a generator seeded by
/// (seed, surface, triangle index).
class SystematicAreaSampler {
 public:
  /// `total_area` must be the sum of the areas passed to take(), added in the same
  /// order; `surface` separates the random sequences of the two surfaces.
  SystematicAreaSampler(double total_area, std::uint64_t count, std::uint64_t seed, std::uint64_t surface)
      : count_(count),
        step_(count > 0 ? total_area / double(count) : 0),
        seed_(mix64(seed ^ mix64(surface))),
        offset_(step_ * SampleRng(seed_).unit()) {}

  /// The number of samples on the next triangle in stream order, whose area is `area`.
  std::uint64_t take(double area) {
    covered_ += area;
    std::uint64_t end = positions_before(covered_);
    std::uint64_t n = end - taken_;
    taken_ = end;
    return n;
  }

  /// Appends `n` points uniformly distributed on triangle (a, b, c), the triangle of
  /// index `triangle` in stream order.
  void place(std::uint64_t triangle, const Vec3d& a, const Vec3d& b, const Vec3d& c, std::uint64_t n,
             std::vector<Vec3d>& out) const {
    SampleRng rng(seed_ + mix64(triangle + 1));
    Vec3d ab = b - a, ac = c - a;
    for (std::uint64_t i = 0; i < n; ++i) {
      // Square-root warp (Osada et al. 2002): uniform by area over the triangle.
      double r = std::sqrt(rng.unit()), s = rng.unit();
      out.push_back(a + r * (1 - s) * ab + r * s * ac);
    }
  }

 private:
  // Sample positions below cumulative area x; monotone in x under rounding, so take()
  // never goes negative, and capped at count_.
  std::uint64_t positions_before(double x) const {
    if (!(x > offset_) || step_ <= 0) return 0;
    double k = std::ceil((x - offset_) / step_);
    return k >= double(count_) ? count_ : std::uint64_t(k);
  }

  std::uint64_t count_;
  double step_;
  std::uint64_t seed_;
  double offset_;
  double covered_ = 0;
  std::uint64_t taken_ = 0;
};

}  // namespace metrics
}  // namespace oocsimp
