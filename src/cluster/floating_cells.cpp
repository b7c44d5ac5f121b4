#include "cluster/floating_cells.hpp"

#include "common/flat_hash_map.hpp"
#include "common/vec3_math.hpp"
#include "grid/grid_coord.hpp"

#include <algorithm>
#include <cstring>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>
#include <utility>

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
    // Dense when the heads are not much more than the items (clearing them must not
    // cost more than the lookups save) and fit kDenseCubes.
    dense_ = cubes <= double(kDenseCubes) && cubes <= 64.0 * double(expected_items) + 4096;
    if (dense_)
      dense_heads_.assign(std::size_t(cubes), kNone);
    else
      sparse_heads_ = FlatHashMap<GridCoord, std::uint32_t, GridCoordHash>(4 * expected_items + 16);
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
    GridCoord lo, hi;
    cubes_near(p, size_, &lo, &hi);
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
  std::size_t dense_index(const GridCoord& c) const {
    return std::size_t(((c.x - box_.lo.x) * dims_[1] + (c.y - box_.lo.y)) * dims_[2] + (c.z - box_.lo.z));
  }
  std::uint32_t find(const GridCoord& c) const {
    if (dense_) return dense_heads_[dense_index(c)];
    std::int64_t cube = sparse_heads_.find(c);
    return cube < 0 ? kNone : sparse_heads_.value(std::size_t(cube));
  }
  std::uint32_t& head_of(const GridCoord& c) {
    if (dense_) {
      if (c.x < box_.lo.x || c.x > box_.hi.x || c.y < box_.lo.y || c.y > box_.hi.y || c.z < box_.lo.z ||
          c.z > box_.hi.z)
        throw std::logic_error("floating cells: a point outside the lookup box");
      return dense_heads_[dense_index(c)];
    }
    std::pair<std::uint32_t, bool> cube = sparse_heads_.try_insert(c);
    std::uint32_t& head = sparse_heads_.value(cube.first);
    if (cube.second) head = kNone;  // a new cube: the caller links the item in
    return head;
  }

  double size_;
  CubeBox box_;
  std::int64_t dims_[3] = {1, 1, 1};
  bool dense_ = true;
  std::vector<std::uint32_t> dense_heads_;
  std::vector<std::uint32_t> next_;
  FlatHashMap<GridCoord, std::uint32_t, GridCoordHash> sparse_heads_;
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
      if (!covered && precedes(*filed[id], v) && cell.holds(*filed[id], v.p)) covered = true;
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

// The externals added (true) or removed (false): the symmetric difference of two
// precedes-sorted lists.
std::vector<std::pair<const GradedVertex*, bool>> changed_externals(const std::vector<GradedVertex>& old_external,
                                                                    const std::vector<GradedVertex>& new_external) {
  std::vector<std::pair<const GradedVertex*, bool>> changed;
  for (std::size_t i = 0, j = 0; i < old_external.size() || j < new_external.size();) {
    if (j == new_external.size() || (i < old_external.size() && precedes(old_external[i], new_external[j])))
      changed.push_back({&old_external[i++], false});
    else if (i == old_external.size() || precedes(new_external[j], old_external[i]))
      changed.push_back({&new_external[j++], true});
    else {  // same priority: the same vertex
      ++i;
      ++j;
    }
  }
  return changed;
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

// --- TileVertexBlock ---

struct TileVertexBlock::Header {
  std::uint64_t count, cubes;
  std::int64_t origin[3];
  std::int64_t dims[3];  // the box of cubes; all 0 when the block has no dense table
  double cell_size;
};

std::vector<unsigned char> TileVertexBlock::build(const std::vector<GradedVertex>& sorted,
                                                  const std::vector<GradedVertex>& centres, double cell_size) {
  Header h{};
  h.count = sorted.size();
  h.cell_size = cell_size;
  CubeBox box;
  box.add(sorted, cell_size);
  if (sorted.empty()) box.lo = box.hi = GridCoord{};
  h.origin[0] = box.lo.x;
  h.origin[1] = box.lo.y;
  h.origin[2] = box.lo.z;
  if (box.hi.x - box.lo.x >= kKeyRange || box.hi.y - box.lo.y >= kKeyRange || box.hi.z - box.lo.z >= kKeyRange)
    throw std::logic_error("floating cells: a tile spans more than 2^21 cells");
  // A dense table of the box's cubes turns the 8 binary searches of every lookup
  // into arithmetic; it is kept when it is not much larger than the vertices (a
  // surface occupies a small fraction of its box, so allow 4 entries per vertex).
  const std::int64_t dims[3] = {box.hi.x - box.lo.x + 1, box.hi.y - box.lo.y + 1, box.hi.z - box.lo.z + 1};
  const double box_cubes = double(dims[0]) * double(dims[1]) * double(dims[2]);
  const bool dense = !sorted.empty() && box_cubes <= 4.0 * double(sorted.size()) + 4096;
  if (dense)
    for (int a = 0; a < 3; ++a) h.dims[a] = dims[a];
  // (cube key, position) sorted: positions grouped by cube, in precedes order within.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> filed(sorted.size());
  std::vector<std::uint32_t> dense_index(dense ? sorted.size() : 0);  // per vertex, its cube in the box
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    GridCoord c = GridCoord::of(sorted[i].p, cell_size);
    const std::int64_t x = c.x - h.origin[0], y = c.y - h.origin[1], z = c.z - h.origin[2];
    filed[i] = {pack(x, y, z), std::uint32_t(i)};
    if (dense) dense_index[i] = std::uint32_t((x * dims[1] + y) * dims[2] + z);
  }
  if (dense) {
    // A counting sort over the box (stable, and the box's order is the keys'
    // order): linear, where a comparison sort of the pairs showed in a run's profile.
    std::vector<std::uint32_t> at(std::size_t(box_cubes) + 1, 0);
    for (std::uint32_t d : dense_index) ++at[d + 1];
    for (std::size_t c = 1; c < at.size(); ++c) at[c] += at[c - 1];
    std::vector<std::pair<std::uint64_t, std::uint32_t>> grouped(filed.size());
    for (std::size_t i = 0; i < filed.size(); ++i) grouped[at[dense_index[i]]++] = filed[i];
    filed.swap(grouped);
  } else {
    std::sort(filed.begin(), filed.end());
  }
  std::vector<std::uint64_t> keys;
  std::vector<std::uint32_t> starts;
  for (std::size_t i = 0; i < filed.size(); ++i)
    if (i == 0 || filed[i].first != filed[i - 1].first) {
      keys.push_back(filed[i].first);
      starts.push_back(std::uint32_t(i));
    }
  starts.push_back(std::uint32_t(filed.size()));
  h.cubes = keys.size();

  TileVertexBlock layout(h);
  std::vector<unsigned char> bytes(layout.bytes_, 0);
  std::memcpy(bytes.data(), &h, sizeof h);
  TileVertexBlock b(bytes.data());
  if (!sorted.empty()) std::memcpy(b.vertices_, sorted.data(), sorted.size() * sizeof(GradedVertex));
  if (!keys.empty()) std::memcpy(b.cube_keys_, keys.data(), keys.size() * sizeof(std::uint64_t));
  std::memcpy(b.cube_starts_, starts.data(), starts.size() * sizeof(std::uint32_t));
  for (std::size_t i = 0; i < filed.size(); ++i) b.by_cube_[i] = filed[i].second;
  if (b.dense_cubes_) {
    std::fill(b.dense_cubes_, b.dense_cubes_ + std::size_t(box_cubes), ~std::uint32_t(0));
    for (std::size_t c = 0; c < keys.size(); ++c)
      b.dense_cubes_[dense_index[filed[starts[c]].second]] = std::uint32_t(c);
  }
  std::vector<char> is_centre = decisions(sorted, centres);
  if (!is_centre.empty()) std::memcpy(b.is_centre_, is_centre.data(), is_centre.size());
  // Each cube's centres, ascending (a cube's vertices are filed ascending).
  for (std::size_t c = 0; c < keys.size(); ++c) {
    std::uint32_t k = 0;
    for (std::uint32_t j = starts[c]; j < starts[c + 1]; ++j)
      if (is_centre[b.by_cube_[j]]) b.centre_by_cube_[starts[c] + k++] = b.by_cube_[j];
    b.centres_in_cube_[c] = k;
  }
  return bytes;
}

TileVertexBlock::TileVertexBlock(const Header& h) { lay_out(nullptr, h); }

TileVertexBlock::TileVertexBlock(unsigned char* block) {
  Header h;
  std::memcpy(&h, block, sizeof h);
  lay_out(block, h);
}

void TileVertexBlock::lay_out(unsigned char* base, const Header& h) {
  count_ = std::size_t(h.count);
  cubes_ = std::size_t(h.cubes);
  for (int a = 0; a < 3; ++a) {
    origin_[a] = h.origin[a];
    dims_[a] = h.dims[a];
  }
  cell_size_ = h.cell_size;
  std::size_t at = sizeof(Header);
  auto take = [&](std::size_t bytes) {
    unsigned char* p = base ? base + at : nullptr;
    at += (bytes + 7) & ~std::size_t(7);
    return p;
  };
  vertices_ = reinterpret_cast<GradedVertex*>(take(count_ * sizeof(GradedVertex)));
  cube_keys_ = reinterpret_cast<std::uint64_t*>(take(cubes_ * sizeof(std::uint64_t)));
  cube_starts_ = reinterpret_cast<std::uint32_t*>(take((cubes_ + 1) * sizeof(std::uint32_t)));
  by_cube_ = reinterpret_cast<std::uint32_t*>(take(count_ * sizeof(std::uint32_t)));
  centre_by_cube_ = reinterpret_cast<std::uint32_t*>(take(count_ * sizeof(std::uint32_t)));
  centres_in_cube_ = reinterpret_cast<std::uint32_t*>(take(cubes_ * sizeof(std::uint32_t)));
  is_centre_ = reinterpret_cast<char*>(take(count_));
  std::size_t dense = std::size_t(dims_[0] * dims_[1] * dims_[2]);
  dense_cubes_ = dense ? reinterpret_cast<std::uint32_t*>(take(dense * sizeof(std::uint32_t))) : nullptr;
  bytes_ = at;
}

void TileVertexBlock::set_centre(std::size_t i, bool c) {
  if (is_centre(i) == c) return;
  is_centre_[i] = char(c);
  GridCoord g = GridCoord::of(vertices_[i].p, cell_size_);
  std::size_t cube = cube_at(g.x - origin_[0], g.y - origin_[1], g.z - origin_[2]);
  if (cube == kNoCube) throw std::logic_error("floating cells: a vertex outside its block's cubes");
  std::uint32_t* first = centre_by_cube_ + cube_starts_[cube];
  std::uint32_t& n = centres_in_cube_[cube];
  std::uint32_t* at = std::lower_bound(first, first + n, std::uint32_t(i));
  if (c) {
    std::copy_backward(at, first + n, first + n + 1);
    *at = std::uint32_t(i);
    ++n;
  } else {
    std::copy(at + 1, first + n, at);
    --n;
  }
}

std::vector<GradedVertex> TileVertexBlock::centres() const {
  std::vector<GradedVertex> out;
  for (std::size_t i = 0; i < count_; ++i)
    if (is_centre_[i]) out.push_back(vertices_[i]);
  return out;
}

bool rechoose_centres(TileVertexBlock& block, const std::vector<GradedVertex>& old_external,
                      const std::vector<GradedVertex>& new_external, const FloatingCellShape& cell) {
  std::vector<std::pair<const GradedVertex*, bool>> changed = changed_externals(old_external, new_external);
  if (changed.empty()) return false;
  const std::size_t n = block.size();
  CubeBox box;
  box.add(new_external, cell.size);
  CubeLists externals(cell.size, box, new_external.size());
  for (const GradedVertex& e : new_external) externals.add(e.p);  // id == position

  // Only a vertex whose cell holds a changed item preceding it can change: an
  // external added or removed, or a vertex of the tile whose decision flipped.
  // Vertices are re-decided heaviest first and a flip queues only lighter ones, so
  // when a vertex is decided every heavier decision is final; the others keep theirs.
  // A centre that appears only adds cover: of the vertices in its cell only the
  // present centres can change (to covered). One that disappears only takes cover
  // away: only the covered ones can change. (A vertex's own flag changes only when
  // it is re-decided, after every heavier item, so the filter at queueing holds.)
  // Queueing tests the whole cube even for a locked item, whose cell is a point in
  // it: a vertex queued in vain is decided again to what it was.
  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, std::greater<std::uint32_t>> queue;
  std::vector<char> queued(n, 0);
  auto queue_reached = [&](const Vec3d& p, bool appeared, auto&& preceded_by) {
    auto visit = [&](std::uint32_t j) {
      if (!queued[j] && preceded_by(j) && cell.contains(p, block.vertex(j).p)) {
        queued[j] = 1;
        queue.push(j);
      }
      return false;
    };
    if (appeared)
      block.any_centre_near(p, visit);
    else
      block.any_near(p, [&](std::uint32_t j) { return !block.is_centre(j) && visit(j); });
  };
  for (const auto& c : changed)
    queue_reached(c.first->p, c.second, [&](std::uint32_t j) { return precedes(*c.first, block.vertex(j)); });
  bool any = false;
  while (!queue.empty()) {
    std::uint32_t i = queue.top();
    queue.pop();
    const GradedVertex& v = block.vertex(i);
    bool covered = block.any_centre_near(
        v.p, [&](std::uint32_t k) { return cell.holds(block.vertex(k), v.p); }, i);
    if (!covered)
      externals.for_each_near(v.p, [&](std::uint32_t id) {
        const GradedVertex& e = new_external[id];
        if (!covered && precedes(e, v) && cell.holds(e, v.p)) covered = true;
      });
    if (!covered == block.is_centre(i)) continue;
    block.set_centre(i, !covered);
    any = true;
    queue_reached(v.p, !covered, [&](std::uint32_t j) { return j > i; });
  }
  return any;
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
      if (!precedes(c, v) || !cell.holds(c, v.p)) return;
      double d2 = squared_distance(v.p, c.p);
      bool better;
      if (!best)
        better = true;
      else if (rule == AssignRule::heaviest)
        better = precedes(c, *best);
      else
        better = d2 < best_d2 || (d2 == best_d2 && precedes(c, *best));
      if (better) {
        best = &c;
        best_d2 = d2;
      }
    });
    if (self)
      out[i] = std::uint32_t(self - centres.data());
    else if (best)
      out[i] = std::uint32_t(best - centres.data());
    else
      throw std::logic_error("floating cells: vertex " + std::to_string(v.index) + " is covered by no centre");
  }
  return out;
}

}  // namespace oocsimp
