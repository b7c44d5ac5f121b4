#include "cluster/floating_cells.hpp"

#include "grid/grid_coord.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace oocsimp {

namespace {

// Centres filed by the grid cell (side = cell size, anchored at the origin) that
// holds them (§4). Cells are chained lists in arrays: head per grid cell, next per
// centre. A grid cell holds at most 8 final centres, but provisional external
// centres of a round may crowd it, so the lists are unbounded.
class CentreGrid {
 public:
  explicit CentreGrid(double size, std::size_t expected = 16) : size_(size) { rehash(4 * expected + 16); }

  void add(const GradedVertex& c) {
    std::uint32_t id = std::uint32_t(centres_.size());
    centres_.push_back(c);
    std::uint32_t& head = head_of(GridCoord::of(c.p, size_));
    next_.push_back(head);
    head = id;
  }

  /// The position of a filed centre in filing order (0, 1, 2, ...).
  std::uint32_t id_of(const GradedVertex& c) const { return std::uint32_t(&c - centres_.data()); }

  /// Calls f(centre) for every filed centre whose cell may hold p.
  template <class F>
  void for_each_near(const Vec3d& p, F&& f) const {
    // The cell around p spans [p - s/2, p + s/2] on each axis: at most 2 grid cells.
    // The range is widened by a relative epsilon so rounding in the division never
    // drops a candidate; contains() decides exactly.
    double h = 0.5 * size_ * (1 + 1e-12);
    GridCoord lo = GridCoord::of({p.x - h, p.y - h, p.z - h}, size_);
    GridCoord hi = GridCoord::of({p.x + h, p.y + h, p.z + h}, size_);
    for (std::int64_t x = lo.x; x <= hi.x; ++x)
      for (std::int64_t y = lo.y; y <= hi.y; ++y)
        for (std::int64_t z = lo.z; z <= hi.z; ++z)
          for (std::uint32_t id = find(GridCoord{x, y, z}); id != kNone; id = next_[id]) f(centres_[id]);
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  struct Slot {
    GridCoord cell;
    std::uint32_t head = kNone;  // kNone: empty slot
  };

  // Open addressing with linear probing over grid cells: no allocation per lookup,
  // which matters as every vertex probes up to 8 cells.
  std::uint32_t find(const GridCoord& c) const {
    for (std::size_t s = GridCoordHash()(c) & mask_;; s = (s + 1) & mask_) {
      const Slot& slot = slots_[s];
      if (slot.head == kNone) return kNone;
      if (slot.cell == c) return slot.head;
    }
  }
  std::uint32_t& head_of(const GridCoord& c) {
    if (2 * (used_ + 1) > slots_.size()) rehash(2 * slots_.size());
    std::size_t s = GridCoordHash()(c) & mask_;
    while (slots_[s].head != kNone && !(slots_[s].cell == c)) s = (s + 1) & mask_;
    if (slots_[s].head == kNone) {
      slots_[s].cell = c;
      ++used_;
    }
    return slots_[s].head;  // kNone for a new cell: the caller links the centre in
  }
  void rehash(std::size_t n) {
    std::size_t cap = 16;
    while (cap < n) cap *= 2;
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(cap, Slot{});
    mask_ = cap - 1;
    for (const Slot& o : old) {
      if (o.head == kNone) continue;
      std::size_t s = GridCoordHash()(o.cell) & mask_;
      while (slots_[s].head != kNone) s = (s + 1) & mask_;
      slots_[s] = o;
    }
  }

  double size_;
  std::vector<GradedVertex> centres_;
  std::vector<std::uint32_t> next_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0, used_ = 0;
};

// Whether a centre filed in `grid` that precedes v holds v in its cell: in the
// sequential visit, exactly the centres that precede v exist when v is visited.
bool covered_by_preceding(const CentreGrid& grid, const GradedVertex& v, const FloatingCellShape& cell) {
  bool covered = false;
  grid.for_each_near(v.p, [&](const GradedVertex& c) {
    if (!covered && precedes(c, v) && cell.contains(c.p, v.p)) covered = true;
  });
  return covered;
}

}  // namespace

std::vector<GradedVertex> choose_centres(const std::vector<GradedVertex>& sorted,
                                         const std::vector<GradedVertex>& external, const FloatingCellShape& cell) {
  CentreGrid grid(cell.size, external.size() + sorted.size() / 4);
  for (const GradedVertex& c : external) grid.add(c);
  std::vector<GradedVertex> centres;
  for (const GradedVertex& v : sorted) {
    if (!covered_by_preceding(grid, v, cell)) {
      centres.push_back(v);
      grid.add(v);
    }
  }
  return centres;
}

std::vector<GradedVertex> rechoose_centres(const std::vector<GradedVertex>& sorted,
                                           const std::vector<GradedVertex>& old_centres,
                                           const std::vector<GradedVertex>& old_external,
                                           const std::vector<GradedVertex>& new_external, const FloatingCellShape& cell) {
  // The changed items so far: externals added or removed (symmetric difference of
  // two precedes-sorted lists), later also own vertices whose decision flipped.
  CentreGrid changed(cell.size, 64);
  const GradedVertex* heaviest_change = nullptr;
  // Quick rejection: the grid cubes within reach of a changed item (its cube and
  // the 26 around it); a vertex in no such cube is far from every change.
  GridCoordSet reach;
  auto grow = [&](const Vec3d& p) { reach.insert_block(GridCoord::of(p, cell.size)); };
  {
    std::size_t i = 0, j = 0;
    auto note = [&](const GradedVertex& c) {
      changed.add(c);
      grow(c.p);
      if (!heaviest_change || precedes(c, *heaviest_change)) heaviest_change = &c;
    };
    while (i < old_external.size() || j < new_external.size()) {
      if (j == new_external.size() || (i < old_external.size() && precedes(old_external[i], new_external[j]))) {
        note(old_external[i++]);
      } else if (i == old_external.size() || precedes(new_external[j], old_external[i])) {
        note(new_external[j++]);
      } else {  // same priority: the same vertex
        ++i;
        ++j;
      }
    }
  }
  if (!heaviest_change) return old_centres;
  // Nothing that precedes the heaviest change can flip: resume there.
  std::size_t start = std::size_t(std::partition_point(sorted.begin(), sorted.end(), [&](const GradedVertex& v) {
                                    return precedes(v, *heaviest_change);
                                  }) - sorted.begin());
  CentreGrid grid(cell.size, new_external.size() + old_centres.size());
  for (const GradedVertex& c : new_external) grid.add(c);
  std::vector<GradedVertex> centres;
  std::size_t k = 0;  // walks old_centres alongside sorted
  for (; k < old_centres.size() && precedes(old_centres[k], *heaviest_change); ++k) {
    centres.push_back(old_centres[k]);
    grid.add(old_centres[k]);
  }
  for (std::size_t i = start; i < sorted.size(); ++i) {
    const GradedVertex& v = sorted[i];
    bool was_centre = k < old_centres.size() && old_centres[k].index == v.index;
    if (was_centre) ++k;
    bool near_change = false;
    if (reach.contains(GridCoord::of(v.p, cell.size)))
      changed.for_each_near(v.p, [&](const GradedVertex& c) {
        if (!near_change && precedes(c, v) && cell.contains(c.p, v.p)) near_change = true;
      });
    bool is_centre = near_change ? !covered_by_preceding(grid, v, cell) : was_centre;
    if (is_centre != was_centre) {
      changed.add(v);
      grow(v.p);
    }
    if (is_centre) {
      centres.push_back(v);
      grid.add(v);
    }
  }
  return centres;
}

std::vector<std::uint32_t> assign_to_centres(const std::vector<GradedVertex>& vertices,
                                             const std::vector<GradedVertex>& centres, const FloatingCellShape& cell,
                                             AssignRule rule) {
  CentreGrid grid(cell.size, centres.size());
  for (const GradedVertex& c : centres) grid.add(c);
  std::vector<std::uint32_t> out(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const GradedVertex& v = vertices[i];
    const GradedVertex* best = nullptr;
    const GradedVertex* self = nullptr;
    double best_d2 = 0;
    grid.for_each_near(v.p, [&](const GradedVertex& c) {
      if (c.index == v.index) self = &c;
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
    if (self) out[i] = grid.id_of(*self);
    else if (best) out[i] = grid.id_of(*best);
    else throw std::logic_error("floating cells: vertex " + std::to_string(v.index) + " is covered by no centre");
  }
  return out;
}

}  // namespace oocsimp
