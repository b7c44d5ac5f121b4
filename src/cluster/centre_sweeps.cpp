#include "cluster/centre_sweeps.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace oocsimp {

namespace {

// Whether a centre's cell reaches outside the tile box: only such centres can
// cover a neighbour's vertex (tiles are at least one cell wide).
bool near_border(const Vec3d& c, const Box3d& box, double half) {
  return c.x - half < box.min.x || c.x + half >= box.max.x || c.y - half < box.min.y || c.y + half >= box.max.y ||
         c.z - half < box.min.z || c.z + half >= box.max.z;
}

bool same_centres(const std::vector<GradedVertex>& a, const std::vector<GradedVertex>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].index != b[i].index) return false;
  return true;
}

// A list of tiles' borders as bytes: per tile, u32 tile, u32 count, its centres.
using TileBorderList = std::vector<std::pair<std::uint32_t, const std::vector<GradedVertex>*>>;
std::vector<unsigned char> pack_borders(const TileBorderList& list) {
  std::size_t bytes = 0;
  for (const auto& [tile, border] : list) bytes += 2 * sizeof(std::uint32_t) + border->size() * sizeof(GradedVertex);
  std::vector<unsigned char> out(bytes);
  unsigned char* at = out.data();
  for (const auto& [tile, border] : list) {
    const std::uint32_t head[2] = {tile, std::uint32_t(border->size())};
    std::memcpy(at, head, sizeof head);
    at += sizeof head;
    if (!border->empty()) std::memcpy(at, border->data(), border->size() * sizeof(GradedVertex));
    at += border->size() * sizeof(GradedVertex);
  }
  return out;
}

// f(tile, border) for each tile of every part's list. Throws std::runtime_error when
// a list is malformed (a part of another build).
template <class F>
void unpack_borders(const std::vector<std::vector<unsigned char>>& lists, std::uint32_t tiles, const F& f) {
  for (const std::vector<unsigned char>& list : lists) {
    std::size_t at = 0;
    while (at < list.size()) {
      std::uint32_t head[2];
      if (list.size() - at < sizeof head) throw std::runtime_error("a part sent malformed tile borders");
      std::memcpy(head, list.data() + at, sizeof head);
      at += sizeof head;
      if (head[0] >= tiles || (list.size() - at) / sizeof(GradedVertex) < head[1])
        throw std::runtime_error("a part sent malformed tile borders");
      std::vector<GradedVertex> border(head[1]);
      if (head[1]) std::memcpy(border.data(), list.data() + at, border.size() * sizeof(GradedVertex));
      at += border.size() * sizeof(GradedVertex);
      f(head[0], std::move(border));
    }
  }
}

}  // namespace

std::vector<GradedVertex> external_centres(const TileGrid& grid, std::uint32_t tile, const TileBorders& borders,
                                           double half) {
  Box3d box = grid.box(tile);
  double reach = half * (1 + 1e-9);
  std::vector<GradedVertex> ext;
  for (std::uint32_t n : grid.neighbours(tile))
    for (const GradedVertex& c : borders[n])
      if (c.p.x >= box.min.x - reach && c.p.x <= box.max.x + reach && c.p.y >= box.min.y - reach &&
          c.p.y <= box.max.y + reach && c.p.z >= box.min.z - reach && c.p.z <= box.max.z + reach)
        ext.push_back(c);
  std::sort(ext.begin(), ext.end(), [](const GradedVertex& a, const GradedVertex& b) { return precedes(a, b); });
  ext.shrink_to_fit();  // kept for every tile until the sweeps end: no growth slack
  return ext;
}

std::vector<GradedVertex> border_of(const TileGrid& grid, std::uint32_t tile, const std::vector<GradedVertex>& centres,
                                    double half) {
  Box3d box = grid.box(tile);
  std::vector<GradedVertex> b;
  for (const GradedVertex& c : centres)
    if (near_border(c.p, box, half)) b.push_back(c);
  b.shrink_to_fit();  // published for every tile until the assignment: no growth slack
  return b;
}

BorderDecisions::BorderDecisions(const TileGrid& grid, const FloatingCellShape& cell)
    : grid_(grid), cell_(cell), half_(0.5 * cell.size), border_(grid.count()), ext_(grid.count()) {}

std::vector<GradedVertex> BorderDecisions::choose_first(std::uint32_t tile, const std::vector<GradedVertex>& sorted) {
  ext_[tile] = external_centres(grid_, tile, border_, half_);
  std::vector<GradedVertex> centres = choose_centres(sorted, ext_[tile], cell_);
  border_[tile] = border_of(grid_, tile, centres, half_);
  return centres;
}

void BorderDecisions::gather_borders(const TileShare& share) {
  TileBorderList mine;
  for (std::uint32_t t = 0; t < grid_.count(); ++t)
    if (share.owns(t)) mine.emplace_back(t, &border_[t]);
  const std::vector<std::vector<unsigned char>> all = share.exchange(pack_borders(mine));
  unpack_borders(all, grid_.count(), [&](std::uint32_t tile, std::vector<GradedVertex> border) {
    if (!share.owns(tile)) border_[tile] = std::move(border);
  });
}

void BorderDecisions::sweep(BlockStore& blocks, FloatingStats* stats, const TileShare* share) {
  std::uint32_t n = grid_.count();
  // A tile runs again when the external centres it sees (its neighbours' border
  // centres near it) changed since its last run; rechoose_centres re-decides only
  // the vertices near a change. Tiles are visited by colour class, one class after
  // the other, as in the first round: each class sees the borders the classes
  // before it just published (Gauss-Seidel rather than Jacobi: a chain of
  // decisions crosses several tiles in one sweep). The order depends only on the
  // tiling, not on the threads, and the end is the unique fixed point whatever
  // the order (design note). Parts that run at once each run their own tiles of a
  // class and exchange the borders that changed before the next class: every part
  // then holds the same borders and the same stale tiles, as one process would.
  const bool exchanging = share && share->exchanging();
  std::vector<std::vector<std::uint32_t>> adjacent(n);
  for (std::uint32_t t = 0; t < n; ++t) adjacent[t] = grid_.neighbours(t);
  std::vector<std::vector<GradedVertex>>& ext = ext_;
  // Whether a neighbour's border may have changed since the tile's last run: in
  // the first round the later classes' borders came after it.
  std::vector<char> stale(n, 1);
  // Rounds: the first greedy, then every sweep in which some tile re-ran (the last
  // sweep, which only confirms, is not one).
  std::uint64_t rounds = 1;
  if (stats) {
    stats->border_centre_bytes = sizeof(GradedVertex);
    for (const std::vector<GradedVertex>& b : border_) stats->border_bytes += b.size() * sizeof(GradedVertex);
  }
  for (;;) {
    std::size_t runs = 0, published = 0;
    std::atomic<std::size_t> reran{0};  // of those, the tiles whose input had changed
    for (int k = 0; k < TileGrid::kColours; ++k) {
      std::vector<std::uint32_t> dirty = grid_.tiles_of_colour(k, &stale);
      std::vector<char> border_changed(dirty.size(), 0);
      std::vector<std::vector<GradedVertex>> next_border(dirty.size());
      tbb::parallel_for(std::size_t(0), dirty.size(), [&](std::size_t i) {
        std::uint32_t tile = dirty[i];
        if (exchanging && !share->owns(tile)) return;
        std::vector<GradedVertex> next_ext = external_centres(grid_, tile, border_, half_);
        if (same_centres(next_ext, ext[tile])) return;
        ++reran;
        TileVertexBlock block(blocks.block(tile));
        if (rechoose_centres(block, ext[tile], next_ext, cell_)) {
          next_border[i] = border_of(grid_, tile, block.centres(), half_);
          border_changed[i] = !same_centres(next_border[i], border_[tile]);
        }
        ext[tile] = std::move(next_ext);  // only this tile's own slot
      });
      auto publish = [&](std::uint32_t tile, std::vector<GradedVertex> border) {
        published += border.size();
        border_[tile] = std::move(border);
        for (std::uint32_t nb : adjacent[tile]) stale[nb] = 1;
      };
      for (std::uint32_t tile : dirty) stale[tile] = 0;
      runs += dirty.size();
      if (exchanging) {
        TileBorderList changed;
        for (std::size_t i = 0; i < dirty.size(); ++i)
          if (border_changed[i]) changed.emplace_back(dirty[i], &next_border[i]);
        unpack_borders(share->exchange(pack_borders(changed)), n, publish);
      } else {
        for (std::size_t i = 0; i < dirty.size(); ++i)
          if (border_changed[i]) publish(dirty[i], std::move(next_border[i]));
      }
    }
    if (runs == 0) break;
    if (reran > 0) ++rounds;
    if (stats) stats->sweeps.push_back({runs, reran.load(), published});
  }
  std::vector<std::vector<GradedVertex>>().swap(ext_);
  if (stats) stats->rounds = rounds;
}

}  // namespace oocsimp
