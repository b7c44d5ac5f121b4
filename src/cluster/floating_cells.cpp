#include "cluster/floating_cells.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace oocsimp {

namespace {

// Centres filed by the grid cell (side = cell size, anchored at the origin) that
// holds them (§4). Cells are chained lists in arrays: head per grid cell, next per
// centre. A grid cell holds at most 8 final centres, but provisional external
// centres of a round may crowd it, so the lists are unbounded.
class CentreGrid {
 public:
  explicit CentreGrid(double size) : size_(size) {}

  void add(const GradedVertex& c) {
    std::uint32_t id = std::uint32_t(centres_.size());
    centres_.push_back(c);
    std::uint32_t& head = heads_.try_emplace(key(cell_of(c.p.x), cell_of(c.p.y), cell_of(c.p.z)), kNone).first->second;
    next_.push_back(head);
    head = id;
  }

  /// Calls f(centre) for every filed centre whose cell may hold p.
  template <class F>
  void for_each_near(const Vec3d& p, F&& f) const {
    // The cell around p spans [p - s/2, p + s/2] on each axis: at most 2 grid cells.
    // The range is widened by a relative epsilon so rounding in the division never
    // drops a candidate; contains() decides exactly.
    double h = 0.5 * size_ * (1 + 1e-12);
    std::int64_t lo[3] = {cell_of(p.x - h), cell_of(p.y - h), cell_of(p.z - h)};
    std::int64_t hi[3] = {cell_of(p.x + h), cell_of(p.y + h), cell_of(p.z + h)};
    for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
      for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
          auto it = heads_.find(key(x, y, z));
          if (it == heads_.end()) continue;
          for (std::uint32_t id = it->second; id != kNone; id = next_[id]) f(centres_[id]);
        }
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  struct Key {
    std::int64_t x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = std::uint64_t(k.x) * 0x9E3779B97F4A7C15ull ^ std::uint64_t(k.y) * 0xC2B2AE3D27D4EB4Full ^
                        std::uint64_t(k.z) * 0x165667B19E3779F9ull;
      return std::size_t(h ^ (h >> 31));
    }
  };
  std::int64_t cell_of(double v) const { return std::int64_t(std::floor(v / size_)); }
  static Key key(std::int64_t x, std::int64_t y, std::int64_t z) { return {x, y, z}; }

  double size_;
  std::vector<GradedVertex> centres_;
  std::vector<std::uint32_t> next_;
  std::unordered_map<Key, std::uint32_t, KeyHash> heads_;
};

}  // namespace

std::vector<GradedVertex> choose_centres(const std::vector<GradedVertex>& sorted,
                                         const std::vector<GradedVertex>& external, const FloatingCellShape& cell) {
  CentreGrid grid(cell.size);
  for (const GradedVertex& c : external) grid.add(c);
  std::vector<GradedVertex> centres;
  for (const GradedVertex& v : sorted) {
    bool covered = false;
    // Every own centre found precedes v (it was chosen earlier); an external one
    // counts only if it precedes v, as in the sequential visit.
    grid.for_each_near(v.p, [&](const GradedVertex& c) {
      if (!covered && precedes(c, v) && cell.contains(c.p, v.p)) covered = true;
    });
    if (!covered) {
      centres.push_back(v);
      grid.add(v);
    }
  }
  return centres;
}

std::vector<std::uint64_t> assign_to_centres(const std::vector<GradedVertex>& vertices,
                                             const std::vector<GradedVertex>& centres, const FloatingCellShape& cell,
                                             AssignRule rule) {
  CentreGrid grid(cell.size);
  for (const GradedVertex& c : centres) grid.add(c);
  std::vector<std::uint64_t> out(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const GradedVertex& v = vertices[i];
    const GradedVertex* best = nullptr;
    double best_d2 = 0;
    bool is_centre = false;
    grid.for_each_near(v.p, [&](const GradedVertex& c) {
      if (c.index == v.index) is_centre = true;
      if (!precedes(c, v) || !cell.contains(c.p, v.p)) return;
      double dx = v.p.x - c.p.x, dy = v.p.y - c.p.y, dz = v.p.z - c.p.z;
      double d2 = dx * dx + dy * dy + dz * dz;
      bool better;
      if (!best) better = true;
      else if (rule == AssignRule::heaviest) better = precedes(c, *best);
      else better = d2 < best_d2 || (d2 == best_d2 && precedes(c, *best));
      if (better) {
        best = &c;
        best_d2 = d2;
      }
    });
    if (is_centre) out[i] = v.index;
    else if (best) out[i] = best->index;
    else throw std::logic_error("floating cells: vertex " + std::to_string(v.index) + " is covered by no centre");
  }
  return out;
}

}  // namespace oocsimp
