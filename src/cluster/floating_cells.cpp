#include "cluster/floating_cells.hpp"

#include "grid/grid_coord.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>

namespace oocsimp {

namespace {

// Cubes of side `size` anchored at the origin (§4's lookup grid) over a box known in
// advance: the cubes holding every point that will be filed or queried, widened by one
// cube on each side (a query reaches half a cube beyond its point).
struct CubeBox {
  GridCoord lo{std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::max(),
               std::numeric_limits<std::int64_t>::max()};
  GridCoord hi{std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::min(),
               std::numeric_limits<std::int64_t>::min()};
  void add(const GradedVertex& x, double size) {
    GridCoord c = GridCoord::of(x.p, size);
    lo = {std::min(lo.x, c.x - 1), std::min(lo.y, c.y - 1), std::min(lo.z, c.z - 1)};
    hi = {std::max(hi.x, c.x + 1), std::max(hi.y, c.y + 1), std::max(hi.z, c.z + 1)};
  }
  void add(const std::vector<GradedVertex>& v, double size) {
    for (const GradedVertex& x : v) add(x, size);
  }
};

// Items (ids 0, 1, 2, ... in filing order) filed by the cube holding their point, as
// chained lists: a head per cube, a next per item. Over a box of at most kDenseCubes
// cubes the heads are a dense array, so a lookup is arithmetic and neighbouring
// cubes are neighbours in memory: every vertex probes up to 8 cubes, in an order
// (by weight) that jumps all over the tile. Larger boxes fall back to open
// addressing over the cube coordinates.
class CubeLists {
 public:
  CubeLists(double size, const CubeBox& box, std::size_t expected_items) : size_(size), box_(box) {
    if (box.lo.x > box.hi.x) box_.lo = box_.hi = GridCoord{};  // nothing will be filed
    dims_[0] = box_.hi.x - box_.lo.x + 1;
    dims_[1] = box_.hi.y - box_.lo.y + 1;
    dims_[2] = box_.hi.z - box_.lo.z + 1;
    double cubes = double(dims_[0]) * double(dims_[1]) * double(dims_[2]);
    dense_ = cubes <= double(kDenseCubes);
    if (dense_) dense_heads_.assign(std::size_t(cubes), kNone);
    else rehash(4 * expected_items + 16);
    next_.reserve(expected_items);
  }

  /// Files an item at p (inside the box) and returns its id.
  std::uint32_t add(const Vec3d& p) {
    std::uint32_t id = std::uint32_t(next_.size());
    std::uint32_t& head = head_of(GridCoord::of(p, size_));
    next_.push_back(head);
    head = id;
    return id;
  }

  /// Calls f(id) for every filed item whose cube may hold a point of the cell
  /// around p: the cell spans [p - s/2, p + s/2] on each axis, at most 2 cubes.
  template <class F>
  void for_each_near(const Vec3d& p, F&& f) const {
    // Widened by a relative epsilon so rounding in the division never drops a
    // candidate; contains() decides exactly.
    double h = 0.5 * size_ * (1 + 1e-12);
    GridCoord lo = GridCoord::of({p.x - h, p.y - h, p.z - h}, size_);
    GridCoord hi = GridCoord::of({p.x + h, p.y + h, p.z + h}, size_);
    lo = {std::max(lo.x, box_.lo.x), std::max(lo.y, box_.lo.y), std::max(lo.z, box_.lo.z)};
    hi = {std::min(hi.x, box_.hi.x), std::min(hi.y, box_.hi.y), std::min(hi.z, box_.hi.z)};
    for (std::int64_t x = lo.x; x <= hi.x; ++x)
      for (std::int64_t y = lo.y; y <= hi.y; ++y)
        for (std::int64_t z = lo.z; z <= hi.z; ++z)
          for (std::uint32_t id = find(GridCoord{x, y, z}); id != kNone; id = next_[id]) f(id);
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  static constexpr std::size_t kDenseCubes = std::size_t(1) << 20;  // 4 MiB of heads
  struct Slot {
    GridCoord cell;
    std::uint32_t head = kNone;  // kNone: empty slot
  };

  std::size_t dense_index(const GridCoord& c) const {
    return std::size_t(((c.x - box_.lo.x) * dims_[1] + (c.y - box_.lo.y)) * dims_[2] + (c.z - box_.lo.z));
  }
  std::uint32_t find(const GridCoord& c) const {
    if (dense_) return dense_heads_[dense_index(c)];
    for (std::size_t s = GridCoordHash()(c) & mask_;; s = (s + 1) & mask_) {
      const Slot& slot = slots_[s];
      if (slot.head == kNone) return kNone;
      if (slot.cell == c) return slot.head;
    }
  }
  std::uint32_t& head_of(const GridCoord& c) {
    if (dense_) {
      if (c.x < box_.lo.x || c.x > box_.hi.x || c.y < box_.lo.y || c.y > box_.hi.y || c.z < box_.lo.z ||
          c.z > box_.hi.z)
        throw std::logic_error("floating cells: a point outside the lookup box");
      return dense_heads_[dense_index(c)];
    }
    if (2 * (used_ + 1) > slots_.size()) rehash(2 * slots_.size());
    std::size_t s = GridCoordHash()(c) & mask_;
    while (slots_[s].head != kNone && !(slots_[s].cell == c)) s = (s + 1) & mask_;
    if (slots_[s].head == kNone) {
      slots_[s].cell = c;
      ++used_;
    }
    return slots_[s].head;  // kNone for a new cube: the caller links the item in
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
  CubeBox box_;
  std::int64_t dims_[3] = {1, 1, 1};
  bool dense_ = true;
  std::vector<std::uint32_t> dense_heads_;
  std::vector<std::uint32_t> next_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0, used_ = 0;
};

}  // namespace

std::vector<GradedVertex> choose_centres(const std::vector<GradedVertex>& sorted,
                                         const std::vector<GradedVertex>& external, const FloatingCellShape& cell) {
  CubeBox box;
  box.add(sorted, cell.size);
  box.add(external, cell.size);
  CubeLists grid(cell.size, box, external.size() + sorted.size() / 4);
  std::vector<const GradedVertex*> filed;  // by id
  filed.reserve(external.size() + sorted.size() / 4);
  for (const GradedVertex& c : external) {
    grid.add(c.p);
    filed.push_back(&c);
  }
  std::vector<GradedVertex> centres;
  for (const GradedVertex& v : sorted) {
    // In the sequential visit, exactly the centres that precede v exist when v is
    // visited; v is a centre unless one of them holds it.
    bool covered = false;
    grid.for_each_near(v.p, [&](std::uint32_t id) {
      if (!covered && precedes(*filed[id], v) && cell.contains(filed[id]->p, v.p)) covered = true;
    });
    if (!covered) {
      centres.push_back(v);
      grid.add(v.p);
      filed.push_back(&v);
    }
  }
  return centres;
}

namespace {

// The externals added or removed: the symmetric difference of two precedes-sorted lists.
std::vector<const GradedVertex*> changed_externals(const std::vector<GradedVertex>& old_external,
                                                   const std::vector<GradedVertex>& new_external) {
  std::vector<const GradedVertex*> changed;
  for (std::size_t i = 0, j = 0; i < old_external.size() || j < new_external.size();) {
    if (j == new_external.size() || (i < old_external.size() && precedes(old_external[i], new_external[j])))
      changed.push_back(&old_external[i++]);
    else if (i == old_external.size() || precedes(new_external[j], old_external[i]))
      changed.push_back(&new_external[j++]);
    else {  // same priority: the same vertex
      ++i;
      ++j;
    }
  }
  return changed;
}

// The core of the re-runs. `vertices` (precedes order) have their old decisions in
// `is_centre`, which receives the new ones. `fixed` are centres that keep their
// decision; `changed` the externals added or removed, `new_external` the externals
// now. Only a vertex whose cell holds a changed item preceding it can change: an
// external added or removed, or a vertex whose decision flipped. Vertices are
// re-decided heaviest first and a flip queues only lighter ones, so when a vertex is
// decided every heavier decision is final; the others keep theirs. Returns false as
// soon as a flipped vertex v has escapes(v): its cell may reach vertices that are
// not in `vertices`, whose decisions this run cannot update.
template <class Escapes>
bool redecide(const std::vector<GradedVertex>& vertices, std::vector<char>& is_centre,
              const std::vector<const GradedVertex*>& fixed, const std::vector<const GradedVertex*>& changed,
              const std::vector<GradedVertex>& new_external, const FloatingCellShape& cell, Escapes&& escapes) {
  const std::size_t n = vertices.size();
  CubeBox box;
  box.add(vertices, cell.size);
  box.add(new_external, cell.size);
  for (const GradedVertex* c : changed) box.add(*c, cell.size);
  for (const GradedVertex* c : fixed) box.add(*c, cell.size);
  // The vertices by cube (id = position), to find those a change reaches.
  CubeLists by_cube(cell.size, box, n);
  for (const GradedVertex& v : vertices) by_cube.add(v.p);
  // The centres: own (item = position; a centre that stops being one stays filed,
  // is_centre says), new externals and fixed ones (item -1 - j, j in `others`).
  std::vector<const GradedVertex*> others(new_external.size());
  for (std::size_t j = 0; j < new_external.size(); ++j) others[j] = &new_external[j];
  others.insert(others.end(), fixed.begin(), fixed.end());
  CubeLists centres(cell.size, box, n / 4 + others.size());
  std::vector<std::int64_t> item;
  item.reserve(n / 4 + others.size());
  for (std::size_t i = 0; i < n; ++i)
    if (is_centre[i]) {
      centres.add(vertices[i].p);
      item.push_back(std::int64_t(i));
    }
  for (std::size_t j = 0; j < others.size(); ++j) {
    centres.add(others[j]->p);
    item.push_back(-1 - std::int64_t(j));
  }

  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, std::greater<std::uint32_t>> queue;
  std::vector<char> queued(n, 0);
  auto queue_reached = [&](const Vec3d& p, auto&& preceded_by) {
    by_cube.for_each_near(p, [&](std::uint32_t j) {
      if (!queued[j] && preceded_by(j) && cell.contains(p, vertices[j].p)) {
        queued[j] = 1;
        queue.push(j);
      }
    });
  };
  for (const GradedVertex* c : changed)
    queue_reached(c->p, [&](std::uint32_t j) { return precedes(*c, vertices[j]); });
  while (!queue.empty()) {
    std::uint32_t i = queue.top();
    queue.pop();
    const GradedVertex& v = vertices[i];
    bool covered = false;
    centres.for_each_near(v.p, [&](std::uint32_t id) {
      if (covered) return;
      std::int64_t k = item[id];
      if (k >= 0) {
        covered = std::size_t(k) < i && is_centre[std::size_t(k)] && cell.contains(vertices[std::size_t(k)].p, v.p);
      } else {
        const GradedVertex& e = *others[std::size_t(-1 - k)];
        covered = precedes(e, v) && cell.contains(e.p, v.p);
      }
    });
    if (char(!covered) == is_centre[i]) continue;
    if (escapes(v)) return false;
    is_centre[i] = char(!covered);
    if (!covered) {  // a new centre (filed at most once: each vertex is decided once)
      centres.add(v.p);
      item.push_back(std::int64_t(i));
    }
    queue_reached(v.p, [&](std::uint32_t j) { return j > i; });
  }
  return true;
}

// is_centre over `vertices` from `centres`, a subsequence of them (both in precedes order).
std::vector<char> decisions(const std::vector<GradedVertex>& vertices, const std::vector<GradedVertex>& centres) {
  std::vector<char> is_centre(vertices.size(), 0);
  for (std::size_t i = 0, k = 0; i < vertices.size() && k < centres.size(); ++i)
    if (centres[k].index == vertices[i].index) {
      is_centre[i] = 1;
      ++k;
    }
  return is_centre;
}

}  // namespace

std::vector<GradedVertex> rechoose_centres(const std::vector<GradedVertex>& sorted,
                                           const std::vector<GradedVertex>& old_centres,
                                           const std::vector<GradedVertex>& old_external,
                                           const std::vector<GradedVertex>& new_external, const FloatingCellShape& cell) {
  std::vector<const GradedVertex*> changed = changed_externals(old_external, new_external);
  if (changed.empty()) return old_centres;
  std::vector<char> is_centre = decisions(sorted, old_centres);
  redecide(sorted, is_centre, {}, changed, new_external, cell, [](const GradedVertex&) { return false; });
  std::vector<GradedVertex> out;
  out.reserve(old_centres.size() + 16);
  for (std::size_t i = 0; i < sorted.size(); ++i)
    if (is_centre[i]) out.push_back(sorted[i]);
  return out;
}

std::vector<std::uint32_t> assign_to_centres(const std::vector<GradedVertex>& vertices,
                                             const std::vector<GradedVertex>& centres, const FloatingCellShape& cell,
                                             AssignRule rule) {
  CubeBox box;
  box.add(vertices, cell.size);
  box.add(centres, cell.size);
  CubeLists grid(cell.size, box, centres.size());
  for (const GradedVertex& c : centres) grid.add(c.p);  // id == position in centres
  std::vector<std::uint32_t> out(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const GradedVertex& v = vertices[i];
    const GradedVertex* best = nullptr;
    const GradedVertex* self = nullptr;
    double best_d2 = 0;
    grid.for_each_near(v.p, [&](std::uint32_t id) {
      const GradedVertex& c = centres[id];
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
    if (self) out[i] = std::uint32_t(self - centres.data());
    else if (best) out[i] = std::uint32_t(best - centres.data());
    else throw std::logic_error("floating cells: vertex " + std::to_string(v.index) + " is covered by no centre");
  }
  return out;
}

}  // namespace oocsimp
