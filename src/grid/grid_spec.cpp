#include "grid/grid_spec.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "oocsimp/error.hpp"

namespace oocsimp {

GridSpec GridSpec::with_cell(const Box3d& bounds, double cell) {
  if (!(cell > 0) || !std::isfinite(cell))
    throw UsageError("options.sizing.cell", "options.sizing.cell must be a positive number");
  GridSpec g;
  g.cell = cell;
  if (bounds.empty()) return g;
  g.origin = bounds.min;
  double ext[3] = {bounds.max.x - bounds.min.x, bounds.max.y - bounds.min.y, bounds.max.z - bounds.min.z};
  for (int a = 0; a < 3; ++a) {
    double n = std::floor(ext[a] / cell) + 1;  // the max coordinate lies in the last cell
    if (n > double(kMaxDim)) {
      std::ostringstream msg;
      msg << "cell size " << cell << " gives " << n << " cells along an axis (at most " << kMaxDim << ")";
      throw UsageError(msg.str());
    }
    g.dims[a] = std::uint32_t(n);
  }
  return g;
}

GridSpec GridSpec::with_divisions(const Box3d& bounds, std::uint32_t n) {
  if (n == 0) throw UsageError("options.sizing.grid", "options.sizing.grid must be at least 1");
  if (n > kMaxDim)
    throw UsageError("options.sizing.grid", "options.sizing.grid must be at most " + std::to_string(kMaxDim));
  double longest = 0;
  if (!bounds.empty())
    longest = std::max({bounds.max.x - bounds.min.x, bounds.max.y - bounds.min.y, bounds.max.z - bounds.min.z});
  // A flat or point-like input still gets a valid (if trivial) grid.
  double cell = longest > 0 ? longest / n : 1.0;
  if (!(cell > 0)) cell = longest;  // a subnormal extent over many cells: one cell holds it all
  GridSpec g;
  g.cell = cell;
  if (bounds.empty()) return g;
  g.origin = bounds.min;
  // Exactly n along the longest axis: its maximum falls on the far boundary, which
  // key() clamps into the last cell. (with_cell would count that boundary as cell n + 1
  // and refuse n = kMaxDim.)
  double ext[3] = {bounds.max.x - bounds.min.x, bounds.max.y - bounds.min.y, bounds.max.z - bounds.min.z};
  for (int a = 0; a < 3; ++a) g.dims[a] = std::uint32_t(std::min(std::floor(ext[a] / cell) + 1, double(n)));
  return g;
}

}  // namespace oocsimp
