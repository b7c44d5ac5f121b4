// Choosing the grid from --cell, --grid or --ratio.
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "grid/grid_choice.hpp"
#include "grid/occupancy.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

std::vector<std::uint64_t> count_occupancy(const PositionArray& positions, const Box3d& bounds, std::uint64_t stride) {
  stride = std::max<std::uint64_t>(stride, 1);
  std::vector<GridSpec> grids;
  for (std::uint32_t n : kLevels) grids.push_back(GridSpec::with_divisions(bounds, n));
  auto cells = [](const GridSpec& g) { return std::size_t(g.dims[0]) * g.dims[1] * g.dims[2]; };
  auto index = [](const GridSpec& g, std::uint64_t k) {
    return (std::size_t((k >> 42) & GridSpec::kMaxDim) * g.dims[1] + ((k >> 21) & GridSpec::kMaxDim)) * g.dims[0] +
           (k & GridSpec::kMaxDim);
  };
  // Bitmaps in 64-bit words: merged and counted a word at a time.
  using Bits = std::vector<std::vector<std::uint64_t>>;
  auto empty_bits = [&] {
    Bits b;
    for (const GridSpec& g : grids) b.emplace_back((cells(g) + 63) / 64, 0);
    return b;
  };
  tbb::combinable<Bits> local(empty_bits);
  const std::uint64_t samples = (positions.count + stride - 1) / stride;
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, samples, 1 << 16),
                    [&](const tbb::blocked_range<std::uint64_t>& r) {
                      Bits& b = local.local();
                      for (std::uint64_t i = r.begin(); i != r.end(); ++i) {
                        Vec3d p = positions.get(i * stride);
                        if (!is_finite(p)) continue;  // outside every grid (see is_finite)
                        for (int l = 0; l < kLevelCount; ++l) {
                          const std::size_t i = index(grids[l], grids[l].key(p));
                          b[l][i >> 6] |= std::uint64_t(1) << (i & 63);
                        }
                      }
                    });
  Bits all = empty_bits();
  local.combine_each([&](const Bits& b) {
    for (int l = 0; l < kLevelCount; ++l)
      for (std::size_t w = 0; w < all[l].size(); ++w) all[l][w] |= b[l][w];
  });
  std::vector<std::uint64_t> counts;
  for (const auto& b : all) {
    std::uint64_t n = 0;
    for (std::uint64_t w : b) n += std::uint64_t(__builtin_popcountll(w));
    counts.push_back(n);
  }
  return counts;
}

OccupancyGrowth occupancy_growth(const std::vector<std::uint64_t>& occ, std::uint64_t samples) {
  int l = 0;
  while (l + 2 < kLevelCount && occ[l + 2] * 8 <= samples) ++l;
  double k = occ[l + 1] > occ[l] && occ[l] > 0 ? std::log2(double(occ[l + 1]) / double(occ[l])) : 2.0;
  return {double(kLevels[l + 1]), double(std::max<std::uint64_t>(occ[l + 1], 1)), std::clamp(k, 1.0, 3.0)};
}

double OccupancyGrowth::cells_at(double r) const { return cells * std::pow(r / resolution, k); }

double OccupancyGrowth::resolution_for(double target) const { return resolution * std::pow(target / cells, 1.0 / k); }

double OccupancyGrowth::occupied_by(double r, std::uint64_t vertices) const {
  const double c = cells_at(r);
  return c > 0 ? -c * std::expm1(-double(vertices) / c) : 0.0;
}

OccupancyGrowth sampled_occupancy_growth(const PositionArray& positions, const Box3d& bounds) {
  const std::uint64_t stride = std::max<std::uint64_t>(1, positions.count >> 20);
  const std::uint64_t samples = (positions.count + stride - 1) / stride;
  return occupancy_growth(count_occupancy(positions, bounds, stride), samples);
}

GridSpec choose_grid(const MeshInput& input, const CellSizing& sizing, unsigned) {
  // Zero means "not given"; anything else given is checked, never replaced.
  int given = (sizing.cell != 0) + (sizing.grid != 0) + (sizing.ratio != 0);
  if (given > 1)
    throw UsageError("give at most one of options.sizing.cell, options.sizing.grid and options.sizing.ratio");
  CellSizing s = sizing;
  if (given == 0) s.ratio = kDefaultRatio;
  const Box3d& bounds = input.info.bounds;
  if (s.cell != 0) return GridSpec::with_cell(bounds, s.cell);
  if (s.grid != 0) return GridSpec::with_divisions(bounds, s.grid);
  if (!(s.ratio > 0 && s.ratio <= 1))
    throw UsageError("options.sizing.ratio", "options.sizing.ratio must be in (0, 1]");
  if (input.positions.count == 0 || input.info.face_count == 0) return GridSpec::with_divisions(bounds, 1);
  // A clustered surface keeps about two triangles per occupied cell (Euler: F ~ 2V),
  // so the target is ratio * F / 2 cells. Occupancy grows as resolution^k (k ~ 2 for
  // surfaces). k is measured between two coarse grids fine enough to resolve the
  // shape yet coarse enough that the vertices sample every occupied cell (at most
  // one cell per 8 vertices), and the target resolution extrapolated from there.
  const OccupancyGrowth g = occupancy_growth(count_occupancy(input.positions, bounds), input.positions.count);
  double target = std::max(1.0, s.ratio * double(input.info.face_count) / 2);
  double res = g.resolution_for(target);
  res = std::clamp(res, 1.0, double(GridSpec::kMaxDim));
  return GridSpec::with_divisions(bounds, std::uint32_t(std::lround(res)));
}

}  // namespace oocsimp
