#include <catch2/catch.hpp>

#include <algorithm>
#include <map>
#include <random>

#include "cluster/floating_cells.hpp"
#include "floating_cells_reference.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

// Random points in a box with weights drawn from a few levels, so that ties are
// common and broken by index; some points are exact duplicates.
std::vector<GradedVertex> random_vertices(std::uint32_t seed, std::size_t n, double extent, int weight_levels) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, extent);
  std::uniform_int_distribution<int> w(0, weight_levels - 1);
  std::vector<GradedVertex> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    v[i].index = i * 3 + 7;  // indices need not be dense
    if (i > 0 && i % 17 == 0)
      v[i].p = v[i - 1].p;  // duplicate point
    else
      v[i].p = {u(rng), u(rng), u(rng) * 0.3};
    v[i].weight = weight_levels > 0 ? double(w(rng)) : u(rng);
  }
  return v;
}

std::vector<GradedVertex> sorted_copy(std::vector<GradedVertex> v) {
  std::sort(v.begin(), v.end(), precedes);
  return v;
}

std::vector<std::uint64_t> indices(const std::vector<GradedVertex>& v) {
  std::vector<std::uint64_t> out;
  for (const auto& x : v) out.push_back(x.index);
  return out;
}

// The rounds scheme of docs/design.md on an in-memory split of the
// vertices into slabs along x: each tile runs the greedy with the other tiles'
// centres of the previous round as external input, until nothing changes.
std::vector<std::uint64_t> tiled_centres(const std::vector<GradedVertex>& all, const FloatingCellShape& cell,
                                         double tile_width, int* rounds) {
  std::map<std::int64_t, std::vector<GradedVertex>> tiles;
  for (const auto& v : all) tiles[std::int64_t(std::floor(v.p.x / tile_width))].push_back(v);
  for (auto& t : tiles) std::sort(t.second.begin(), t.second.end(), precedes);
  std::map<std::int64_t, std::vector<GradedVertex>> centres;
  *rounds = 0;
  for (bool changed = true; changed;) {
    changed = false;
    ++*rounds;
    std::map<std::int64_t, std::vector<GradedVertex>> next;
    for (auto& t : tiles) {
      std::vector<GradedVertex> external;
      for (auto& c : centres)
        if (c.first != t.first) external.insert(external.end(), c.second.begin(), c.second.end());
      next[t.first] = choose_centres(t.second, external, cell);
      if (indices(next[t.first]) != indices(centres[t.first])) changed = true;
    }
    centres = next;
    REQUIRE(*rounds < 1000);
  }
  std::vector<GradedVertex> flat;
  for (auto& c : centres) flat.insert(flat.end(), c.second.begin(), c.second.end());
  std::sort(flat.begin(), flat.end(), precedes);
  return indices(flat);
}

}  // namespace

TEST_CASE("floating cells equal the sequential reference on random inputs", "[floating]") {
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    for (CellShape shape : {CellShape::cube, CellShape::sphere}) {
      for (AssignRule rule : {AssignRule::nearest, AssignRule::heaviest}) {
        auto v = random_vertices(seed, 600, 10.0, seed % 3 == 0 ? 0 : int(seed % 4) + 1);
        FloatingCellShape cell{0.9 + 0.1 * seed, shape};
        ReferenceClustering ref = reference_floating_cells(v, cell.size, shape, rule);
        auto centres = choose_centres(sorted_copy(v), {}, cell);
        INFO("seed " << seed << " shape " << int(shape) << " rule " << int(rule));
        REQUIRE(indices(centres) == ref.centres);
        std::vector<std::uint64_t> cluster;
        for (std::uint32_t c : assign_to_centres(v, centres, cell, rule)) cluster.push_back(centres[c].index);
        CHECK(cluster == ref.cluster);
      }
    }
  }
}

TEST_CASE("floating cells equal the sequential reference when the lookup grid is sparse", "[floating]") {
  // Groups of points far apart: the lookup box has far more cubes than points, so
  // the cube heads are a hash map rather than a dense array.
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> spot(0, 1000), near(-1.5, 1.5);
  std::vector<GradedVertex> v;
  for (int g = 0; g < 40; ++g) {
    Vec3d s{spot(rng), spot(rng), spot(rng)};
    for (int i = 0; i < 15; ++i) {
      GradedVertex x;
      x.index = v.size();
      x.p = {s.x + near(rng), s.y + near(rng), s.z + near(rng)};
      x.weight = double(rng() % 3);
      v.push_back(x);
    }
  }
  for (CellShape shape : {CellShape::cube, CellShape::sphere})
    for (AssignRule rule : {AssignRule::nearest, AssignRule::heaviest}) {
      FloatingCellShape cell{1.0, shape};
      ReferenceClustering ref = reference_floating_cells(v, cell.size, shape, rule);
      auto centres = choose_centres(sorted_copy(v), {}, cell);
      REQUIRE(indices(centres) == ref.centres);
      std::vector<std::uint64_t> cluster;
      for (std::uint32_t c : assign_to_centres(v, centres, cell, rule)) cluster.push_back(centres[c].index);
      CHECK(cluster == ref.cluster);
    }
}

TEST_CASE("every vertex is within half a cell of its centre", "[floating]") {
  auto v = random_vertices(99, 2000, 20.0, 3);
  FloatingCellShape cell{1.5, CellShape::cube};
  auto centres = choose_centres(sorted_copy(v), {}, cell);
  auto cluster = assign_to_centres(v, centres, cell, AssignRule::nearest);
  for (std::size_t i = 0; i < v.size(); ++i) {
    REQUIRE(cluster[i] < centres.size());
    CHECK(cell.contains(centres[cluster[i]].p, v[i].p));
  }
  // No centre lies in another centre's cell.
  for (std::size_t i = 0; i < centres.size(); ++i)
    for (std::size_t j = i + 1; j < centres.size(); ++j) CHECK_FALSE(cell.contains(centres[i].p, centres[j].p));
}

TEST_CASE("tiles exchanging border centres in rounds reach the sequential result", "[floating]") {
  for (std::uint32_t seed = 1; seed <= 8; ++seed) {
    // Many ties (1 weight level): decisions chain along the index order, the hard
    // case for a partitioned greedy.
    auto v = random_vertices(seed, 1500, 12.0, seed % 2 ? 1 : 0);
    FloatingCellShape cell{1.0, seed % 4 < 2 ? CellShape::cube : CellShape::sphere};
    ReferenceClustering ref = reference_floating_cells(v, cell.size, cell.shape, AssignRule::nearest);
    for (double width : {1.3, 2.0, 5.0}) {
      int rounds = 0;
      INFO("seed " << seed << " tile width " << width);
      CHECK(tiled_centres(v, cell, width, &rounds) == ref.centres);
      CHECK(rounds >= 1);
    }
  }
}

TEST_CASE("an external centre only covers the vertices it precedes", "[floating]") {
  FloatingCellShape cell{1.0, CellShape::cube};
  GradedVertex a{10, {0, 0, 0}, 5.0}, b{11, {0.2, 0, 0}, 1.0};
  GradedVertex light_external{3, {0.3, 0, 0}, 0.5}, heavy_external{4, {0.3, 0, 0}, 9.0};
  CHECK(indices(choose_centres({a, b}, {light_external}, cell)) == std::vector<std::uint64_t>{10});
  CHECK(choose_centres({a, b}, {heavy_external}, cell).empty());
  // Equal weights: the smaller index precedes.
  GradedVertex tie{2, {0.3, 0, 0}, 5.0};
  CHECK(choose_centres({a, b}, {tie}, cell).empty());
}

namespace {

// Random external centres around (and inside) the tile of `v`, in precedes order.
std::vector<GradedVertex> random_externals(std::uint32_t seed, std::size_t n, double extent, int weight_levels) {
  auto e = random_vertices(seed + 1000, n, extent, weight_levels);
  for (auto& x : e) x.index += 1;  // indices not shared with the tile's (those are 7 mod 3)
  return sorted_copy(e);
}

std::vector<GradedVertex> every_other(const std::vector<GradedVertex>& v, std::size_t phase) {
  std::vector<GradedVertex> out;
  for (std::size_t i = phase; i < v.size(); i += 2) out.push_back(v[i]);
  return out;
}

}  // namespace

TEST_CASE("a vertex block finds every vertex near a point", "[floating]") {
  auto v = sorted_copy(random_vertices(5, 800, 8.0, 0));
  FloatingCellShape cell{0.7, CellShape::cube};
  std::vector<unsigned char> bytes = TileVertexBlock::build(v, {}, cell.size);
  TileVertexBlock block(bytes.data());
  REQUIRE(block.size() == v.size());
  for (std::size_t q = 0; q < v.size(); q += 7) {
    std::vector<std::uint32_t> found;
    block.any_near(v[q].p, [&](std::uint32_t j) {
      if (cell.contains(v[q].p, block.vertex(j).p)) found.push_back(j);
      return false;
    });
    std::sort(found.begin(), found.end());
    std::vector<std::uint32_t> expected;
    for (std::uint32_t j = 0; j < v.size(); ++j)
      if (cell.contains(v[q].p, v[j].p)) expected.push_back(j);
    CHECK(found == expected);
  }
}

TEST_CASE("a re-run in a vertex block equals the greedy with the new external centres", "[floating]") {
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    for (CellShape shape : {CellShape::cube, CellShape::sphere}) {
      int levels = seed % 3 == 0 ? 0 : int(seed % 3);  // continuous weights, or ties
      auto v = sorted_copy(random_vertices(seed, 700, 9.0, levels));
      auto ext = random_externals(seed, 120, 9.0, levels);
      FloatingCellShape cell{0.8 + 0.05 * seed, shape};
      // External inputs of two rounds: two overlapping halves of the same set.
      std::vector<GradedVertex> before = every_other(ext, 0), after = every_other(ext, seed % 2);
      after.insert(after.end(), ext.begin(), ext.begin() + 10);
      std::sort(after.begin(), after.end(), precedes);
      after.erase(std::unique(after.begin(), after.end(),
                              [](const GradedVertex& a, const GradedVertex& b) { return a.index == b.index; }),
                  after.end());
      std::vector<unsigned char> bytes = TileVertexBlock::build(v, choose_centres(v, before, cell), cell.size);
      TileVertexBlock block(bytes.data());
      INFO("seed " << seed << " shape " << int(shape));
      CHECK(indices(block.centres()) == indices(choose_centres(v, before, cell)));
      bool changed = rechoose_centres(block, before, after, cell);
      std::vector<GradedVertex> expected = choose_centres(v, after, cell);
      CHECK(indices(block.centres()) == indices(expected));
      CHECK(changed == (indices(expected) != indices(choose_centres(v, before, cell))));
      // No change in the input: nothing to do.
      CHECK_FALSE(rechoose_centres(block, after, after, cell));
    }
  }
}

TEST_CASE("a locked vertex is a centre whose cell is its own point, in one pass, in rounds and re-runs",
          "[floating][locks]") {
  for (std::uint32_t seed = 1; seed <= 8; ++seed) {
    for (CellShape shape : {CellShape::cube, CellShape::sphere}) {
      // Every 13th vertex locked; every 17th stands where the one before it does, so
      // some locked vertices share their point with a free or a locked one.
      std::vector<GradedVertex> v = random_vertices(seed, 900, 10.0, seed % 3 == 0 ? 0 : 2);
      std::vector<char> flags(v.size(), 0);
      std::vector<std::uint64_t> locked;
      for (std::size_t i = 0; i < v.size(); i += 13) {
        flags[i] = 1;
        locked.push_back(v[i].index);
      }
      for (std::size_t i = 16; i + 1 < v.size(); i += 17 * 13)  // a locked pair at one point
        for (std::size_t k : {i, i + 1})
          if (!flags[k]) {
            flags[k] = 1;
            locked.push_back(v[k].index);
          }
      std::sort(locked.begin(), locked.end());
      std::vector<GradedVertex> sorted = sorted_copy(v);
      lock_graded(&sorted, locked);
      REQUIRE(std::is_sorted(sorted.begin(), sorted.end(), precedes));
      std::vector<GradedVertex> graded = v;  // in input order, with the locked weights
      for (std::size_t i = 0; i < v.size(); ++i)
        if (flags[i]) graded[i].weight = kLockedWeight;
      const FloatingCellShape cell{1.1 + 0.1 * seed, shape};
      INFO("seed " << seed << " shape " << int(shape));
      for (AssignRule rule : {AssignRule::nearest, AssignRule::heaviest}) {
        const ReferenceClustering ref = reference_floating_cells(v, cell.size, shape, rule, flags);
        const std::vector<GradedVertex> centres = choose_centres(sorted, {}, cell);
        REQUIRE(indices(centres) == ref.centres);
        std::vector<std::uint64_t> cluster;
        for (std::uint32_t c : assign_to_centres(graded, centres, cell, rule)) cluster.push_back(centres[c].index);
        CHECK(cluster == ref.cluster);
        // A locked vertex's cluster is the vertices at its point, and nothing else.
        for (std::size_t i = 0; i < v.size(); ++i) {
          const auto centre =
              std::find_if(v.begin(), v.end(), [&](const GradedVertex& x) { return x.index == ref.cluster[i]; });
          const std::size_t c = std::size_t(centre - v.begin());
          if (flags[c]) CHECK((v[i].p.x == v[c].p.x && v[i].p.y == v[c].p.y && v[i].p.z == v[c].p.z));
          if (flags[i]) CHECK(flags[c]);
        }
      }
      const ReferenceClustering ref = reference_floating_cells(v, cell.size, shape, AssignRule::nearest, flags);
      for (double width : {1.3, 4.0}) {
        int rounds = 0;
        CHECK(tiled_centres(graded, cell, width, &rounds) == ref.centres);
      }
      // A re-run with external centres, some of them locked, equals the greedy.
      // Some locked externals stand on a vertex of the block, which they then hold.
      std::vector<GradedVertex> ext = random_externals(seed, 100, 10.0, 2);
      for (std::size_t i = 0; i < ext.size(); i += 3) ext[i].weight = kLockedWeight;
      for (std::size_t i = 0; i < ext.size(); i += 9) ext[i].p = v[(i * 37) % v.size()].p;
      std::sort(ext.begin(), ext.end(), precedes);
      const std::vector<GradedVertex> before = every_other(ext, 0), after = every_other(ext, 1);
      std::vector<unsigned char> bytes =
          TileVertexBlock::build(sorted, choose_centres(sorted, before, cell), cell.size);
      TileVertexBlock block(bytes.data());
      rechoose_centres(block, before, after, cell);
      CHECK(indices(block.centres()) == indices(choose_centres(sorted, after, cell)));
    }
  }
}
