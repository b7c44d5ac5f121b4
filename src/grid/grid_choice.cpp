// Choosing the grid from --cell, --grid or --ratio.
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "oocsimp/error.hpp"
#include "oocsimp/simplify.hpp"

namespace oocsimp {

namespace {

// Occupied cells at two coarse resolutions (kCoarse and 2 * kCoarse cells along the
// longest axis), counted over every vertex with per-thread bitmaps.
constexpr std::uint32_t kCoarse = 128;

struct Occupancy {
  std::uint64_t coarse = 0, fine = 0;
};

Occupancy count_occupancy(const PositionArray& positions, const Box3d& bounds) {
  GridSpec g0 = GridSpec::with_divisions(bounds, kCoarse);
  GridSpec g1 = GridSpec::with_divisions(bounds, 2 * kCoarse);
  auto cells = [](const GridSpec& g) { return std::size_t(g.dims[0]) * g.dims[1] * g.dims[2]; };
  auto index = [](const GridSpec& g, std::uint64_t k) {
    return (std::size_t((k >> 42) & GridSpec::kMaxDim) * g.dims[1] + ((k >> 21) & GridSpec::kMaxDim)) * g.dims[0] +
           (k & GridSpec::kMaxDim);
  };
  struct Bits {
    std::vector<bool> b0, b1;
  };
  tbb::combinable<Bits> local([&] { return Bits{std::vector<bool>(cells(g0)), std::vector<bool>(cells(g1))}; });
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, positions.count, 1 << 16),
                    [&](const tbb::blocked_range<std::uint64_t>& r) {
                      Bits& b = local.local();
                      for (std::uint64_t i = r.begin(); i != r.end(); ++i) {
                        Vec3d p = positions.get(i);
                        b.b0[index(g0, g0.key(p))] = true;
                        b.b1[index(g1, g1.key(p))] = true;
                      }
                    });
  std::vector<bool> b0(cells(g0)), b1(cells(g1));
  local.combine_each([&](const Bits& b) {
    for (std::size_t i = 0; i < b0.size(); ++i) if (b.b0[i]) b0[i] = true;
    for (std::size_t i = 0; i < b1.size(); ++i) if (b.b1[i]) b1[i] = true;
  });
  Occupancy o;
  o.coarse = std::uint64_t(std::count(b0.begin(), b0.end(), true));
  o.fine = std::uint64_t(std::count(b1.begin(), b1.end(), true));
  return o;
}

}  // namespace

GridSpec choose_grid(const MeshInput& input, const CellSizing& s, unsigned) {
  int given = (s.cell > 0) + (s.grid > 0) + (s.ratio > 0);
  if (given != 1) throw UsageError("give exactly one of --cell, --grid and --ratio");
  const Box3d& bounds = input.info.bounds;
  if (s.cell > 0) return GridSpec::with_cell(bounds, s.cell);
  if (s.grid > 0) return GridSpec::with_divisions(bounds, s.grid);
  if (!(s.ratio > 0 && s.ratio <= 1)) throw UsageError("--ratio must be in (0, 1]");
  if (input.positions.count == 0 || input.info.face_count == 0) return GridSpec::with_divisions(bounds, 1);
  // A clustered surface keeps about two triangles per occupied cell (Euler: F ~ 2V),
  // so the target is ratio * F / 2 cells. Occupancy grows as resolution^k with k ~ 2
  // for surfaces; k is measured between the two coarse grids and the target
  // resolution extrapolated from the finer one.
  Occupancy o = count_occupancy(input.positions, bounds);
  double target = std::max(1.0, s.ratio * double(input.info.face_count) / 2);
  double k = (o.coarse > 0 && o.fine > o.coarse) ? std::log2(double(o.fine) / double(o.coarse)) : 2.0;
  k = std::clamp(k, 1.0, 3.0);
  double res = 2.0 * kCoarse * std::pow(target / double(std::max<std::uint64_t>(o.fine, 1)), 1.0 / k);
  res = std::clamp(res, 1.0, double(GridSpec::kMaxDim));
  return GridSpec::with_divisions(bounds, std::uint32_t(std::lround(res)));
}

}  // namespace oocsimp
