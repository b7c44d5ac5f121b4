// The stages of the floating path, each alone, against expectations computed
// independently on the whole mesh (docs/design.md, "Code:").
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "cluster/centre_sweeps.hpp"
#include "cluster/cluster_accumulation.hpp"
#include "cluster/fixed_point_sums.hpp"
#include "cluster/kept_tiles.hpp"
#include "cluster/tile_grading.hpp"
#include "cluster/vertex_grading.hpp"
#include "floating_cells_reference.hpp"
#include "grid/tile_binning.hpp"
#include "grid/tile_plan.hpp"
#include "methods/cluster_methods.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/generate.hpp"
#include "api/simplify.hpp"
#include "stitch/mesh_assembly.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

// A generated sphere of about `tris` triangles, its whole mesh in memory, its
// MeshInput and a cell of 1/`per_axis` of its longest side.
struct Fixture {
  ScratchDir dir;
  std::string path;
  LoadedMesh mesh;
  double cell = 0;

  explicit Fixture(std::uint64_t tris = 20000, int per_axis = 24) {
    path = dir.file("s.ply");
    GenerateOptions g;
    g.triangles = tris;
    generate_mesh(path, g);
    mesh = load_mesh(path);
    const Box3d& b = mesh.info.bounds;
    cell = std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z}) / per_axis;
  }
  Vec3d position(std::uint64_t v) const {
    return {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
  }
  SpillSettings spill() const {
    SpillSettings s;
    s.dir = dir.path();
    s.compress = false;
    return s;
  }
  // Every vertex some triangle uses, graded over the whole mesh at once.
  std::vector<GradedVertex> graded_whole_mesh(const MeshInput& in) const {
    std::vector<std::uint64_t> used(mesh.triangles.begin(), mesh.triangles.end());
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    return grade_vertices(used, mesh.triangles.data(), mesh.triangle_count(), in.positions);
  }
};

// The tile of p for tiles of side `side`, with std::floor (the binning truncates).
std::array<std::int64_t, 3> tile_of(const Vec3d& p, double side) {
  return {std::int64_t(std::floor(p.x / side)), std::int64_t(std::floor(p.y / side)),
          std::int64_t(std::floor(p.z / side))};
}

std::array<std::int64_t, 3> coord_array(const GridCoord& c) { return {c.x, c.y, c.z}; }

BinnedTiles bin(Fixture& f, MeshInput& in, double side) {
  in.restart_triangles();
  return bin_triangles(in, side, 64u << 20, f.spill(), nullptr);
}

// A cluster sum's terms: the quadric's a00 a01 a02 a11 a12 a22 b0 b1 b2, then the
// member positions' sum relative to the centre, in cells.
double term(const ClusterRecord& r, int k) {
  const Fixed* terms[12] = {&r.quadric_sum.a00, &r.quadric_sum.a01, &r.quadric_sum.a02, &r.quadric_sum.a11,
                            &r.quadric_sum.a12, &r.quadric_sum.a22, &r.quadric_sum.b0,  &r.quadric_sum.b1,
                            &r.quadric_sum.b2,  &r.offset_sum.x,    &r.offset_sum.y,    &r.offset_sum.z};
  return terms[k]->value();
}

}  // namespace

TEST_CASE("binning files every triangle in exactly the tiles of its corners, with their owned-corner masks",
          "[floating][stages]") {
  Fixture f;
  MeshInput in = open_mesh_input(f.path);
  for (double side : {f.cell, 2.5 * f.cell, 7 * f.cell, 100 * f.cell}) {
    INFO("tile side " << side);
    BinnedTiles tiles = bin(f, in, side);
    CHECK(tiles.triangle_count == f.mesh.triangle_count());
    CHECK(tiles.skipped.total() == 0);
    // Expected: (triangle, tile) -> mask of the corners in that tile.
    std::map<std::pair<std::uint64_t, std::array<std::int64_t, 3>>, unsigned> expected;
    std::set<std::array<std::int64_t, 3>> occupied;
    for (std::uint64_t t = 0; t < f.mesh.triangle_count(); ++t)
      for (int k = 0; k < 3; ++k) {
        auto c = tile_of(f.position(f.mesh.triangles[3 * t + std::size_t(k)]), side);
        expected[{t, c}] |= 1u << k;
        occupied.insert(c);
      }
    REQUIRE(tiles.count() == occupied.size());
    std::map<std::pair<std::uint64_t, std::array<std::int64_t, 3>>, unsigned> got;
    std::uint64_t records = 0, most = 0;
    for (std::uint32_t tile = 0; tile < tiles.count(); ++tile) {
      auto c = coord_array(tiles.grid.coord(tile));
      CHECK(tiles.grid.find(tiles.grid.coord(tile)) == std::int64_t(tile));
      const TriangleRecords r = tiles.load(tile);
      records += r.size();
      most = std::max<std::uint64_t>(most, r.size());
      for (std::size_t i = 0; i < r.size(); ++i) {
        if (i > 0) CHECK(r[i - 1].index() < r[i].index());  // input order, each triangle once per tile
        unsigned mask = unsigned(r[i].owned(0)) | unsigned(r[i].owned(1)) << 1 | unsigned(r[i].owned(2)) << 2;
        for (int k = 0; k < 3; ++k) CHECK(r[i].v[k] == f.mesh.triangles[3 * r[i].index() + std::size_t(k)]);
        got[{r[i].index(), c}] = mask;
      }
    }
    CHECK(records == expected.size());
    CHECK(got == expected);
    CHECK(tiles.largest_tile_records() == most);
  }
}

TEST_CASE("the tiling's neighbours are the occupied tiles around, and colour classes never touch",
          "[floating][stages]") {
  Fixture f;
  MeshInput in = open_mesh_input(f.path);
  BinnedTiles tiles = bin(f, in, 2 * f.cell);
  const TileGrid& g = tiles.grid;
  REQUIRE(g.count() > 27);
  for (std::uint32_t a = 0; a < g.count(); ++a) {
    std::vector<std::uint32_t> expected;
    for (std::uint32_t b = 0; b < g.count(); ++b) {
      const GridCoord &ca = g.coord(a), &cb = g.coord(b);
      std::int64_t d = std::max({std::abs(ca.x - cb.x), std::abs(ca.y - cb.y), std::abs(ca.z - cb.z)});
      if (d == 1) {
        expected.push_back(b);
        CHECK(g.colour(a) != g.colour(b));
      }
    }
    CHECK(g.neighbours(a) == expected);
    Box3d box = g.box(a);
    CHECK(box.max.x - box.min.x == Approx(2 * f.cell));
  }
}

TEST_CASE("tile planning: never below a cell, a given --tile kept, one whose tiles overflow --mem refused",
          "[floating][stages]") {
  Fixture f;
  MeshInput in = open_mesh_input(f.path);
  TileSettings o;
  o.memory_budget = 64u << 20;
  CHECK(plan_tile_side(in, o, f.cell) >= f.cell);
  o.tile_side = 3 * f.cell;
  CHECK(plan_tile_side(in, o, f.cell) == 3 * f.cell);
  CHECK(plan_tile_side(in, o, 5 * f.cell) == 5 * f.cell);  // a cell wider than the tile wins
  // 32 MiB: at most 32 MiB / 4 / 9 KiB = 910 tiles; the sphere at 1/1000 of its side has more.
  o.memory_budget = 32u << 20;
  o.tile_side = f.cell * 24 / 1000;
  CHECK_THROWS_AS(plan_tile_side(in, o, o.tile_side), UsageError);
}

TEST_CASE("grading a tile's owned vertices equals grading the whole mesh", "[floating][stages]") {
  Fixture f;
  MeshInput in = open_mesh_input(f.path);
  std::vector<GradedVertex> whole = f.graded_whole_mesh(in);
  std::map<std::uint64_t, const GradedVertex*> by_index;
  for (const GradedVertex& v : whole) by_index[v.index] = &v;
  for (double side : {f.cell, 3 * f.cell}) {
    INFO("tile side " << side);
    BinnedTiles tiles = bin(f, in, side);
    std::set<std::uint64_t> seen;
    for (std::uint32_t tile = 0; tile < tiles.count(); ++tile) {
      std::vector<GradedVertex> g = grade_tile(tiles.load(tile), in.positions);
      for (std::size_t i = 0; i < g.size(); ++i) {
        if (i > 0) CHECK(precedes(g[i - 1], g[i]));
        CHECK(coord_array(tiles.grid.coord(tile)) == tile_of(g[i].p, side));  // owned: in the tile's box
        CHECK(seen.insert(g[i].index).second);                                // owned by one tile
        REQUIRE(by_index.count(g[i].index));
        const GradedVertex& w = *by_index[g[i].index];
        CHECK(g[i].weight == w.weight);  // exactly: the same fan, in the same order
        CHECK(g[i].p.x == w.p.x);
        CHECK(g[i].p.y == w.p.y);
        CHECK(g[i].p.z == w.p.z);
      }
    }
    CHECK(seen.size() == whole.size());
  }
}

TEST_CASE("decided centres equal the sequential greedy for several tilings, with the sweeps counted",
          "[floating][stages]") {
  Fixture f;
  MeshInput in = open_mesh_input(f.path);
  std::vector<GradedVertex> whole = f.graded_whole_mesh(in);
  for (CellShape shape : {CellShape::cube, CellShape::sphere}) {
    ReferenceClustering ref = reference_floating_cells(whole, f.cell, shape, AssignRule::nearest);
    std::set<std::uint64_t> expected(ref.centres.begin(), ref.centres.end());
    for (double side : {f.cell, 1.7 * f.cell, 4 * f.cell, 100 * f.cell}) {
      INFO("shape " << cell_shape_name(shape) << ", tile side " << side);
      BinnedTiles tiles = bin(f, in, side);
      FloatingCellShape cell{f.cell, shape};
      BorderDecisions decisions(tiles.grid, cell);
      FirstChoice first = [&](std::uint32_t t, const std::vector<GradedVertex>& s) {
        return decisions.choose_first(t, s);
      };
      std::unique_ptr<BlockStore> blocks =
          grade_tiles(tiles, in.positions, first, GradingSettings{{f.cell, f.dir.path(), 0}});
      FloatingStats st;
      decisions.sweep(*blocks, &st);
      TileBorders borders = decisions.take_borders();
      std::set<std::uint64_t> got;
      for (std::uint32_t tile = 0; tile < tiles.count(); ++tile) {
        std::vector<GradedVertex> centres = TileVertexBlock(blocks->block(tile)).centres();
        std::set<std::uint64_t> own;
        for (const GradedVertex& c : centres) {
          got.insert(c.index);
          own.insert(c.index);
        }
        // A border centre is one of the tile's centres whose cell pokes out of its box.
        Box3d box = tiles.grid.box(tile);
        for (const GradedVertex& b : borders[tile]) {
          CHECK(own.count(b.index) == 1);
          double h = 0.5 * f.cell;
          CHECK((b.p.x - h < box.min.x || b.p.x + h >= box.max.x || b.p.y - h < box.min.y || b.p.y + h >= box.max.y ||
                 b.p.z - h < box.min.z || b.p.z + h >= box.max.z));
        }
      }
      CHECK(got == expected);
      // At least the sweep that finds every tile's input unchanged; rounds are the
      // first greedy and the sweeps that re-ran a tile.
      REQUIRE(st.sweeps.size() >= 1);
      std::uint64_t rounds = 1;
      for (const FloatingStats::SweepCount& s : st.sweeps) {
        CHECK(s.rerun <= s.looked_at);
        CHECK(s.looked_at <= tiles.count());
        rounds += s.rerun > 0;
      }
      CHECK(st.rounds == rounds);
    }
  }
}

TEST_CASE("cluster shares summed over tiles equal the whole mesh's vertex quadrics per cluster", "[floating][stages]") {
  Fixture f(8000, 12);
  MeshInput in = open_mesh_input(f.path);
  std::vector<GradedVertex> whole = f.graded_whole_mesh(in);
  ReferenceClustering ref = reference_floating_cells(whole, f.cell, CellShape::cube, AssignRule::nearest);
  // Whole mesh: per centre, the members, their positions and the area-weighted plane
  // quadrics of each member's faces, relative to the centre in cells (Garland & Heckbert).
  std::map<std::uint64_t, std::uint64_t> cluster;  // vertex -> centre
  for (std::size_t i = 0; i < whole.size(); ++i) cluster[whole[i].index] = ref.cluster[i];
  struct Sums {
    double t[12] = {};
    std::uint64_t members = 0;
  };
  std::map<std::uint64_t, Sums> expected;
  const double s = f.cell;
  for (const auto& [v, c] : cluster) {
    Vec3d p = f.position(v), pc = f.position(c);
    Sums& e = expected[c];
    ++e.members;
    e.t[9] += (p.x - pc.x) / s;
    e.t[10] += (p.y - pc.y) / s;
    e.t[11] += (p.z - pc.z) / s;
  }
  for (std::size_t t = 0; t < f.mesh.triangle_count(); ++t) {
    Vec3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = f.position(f.mesh.triangles[3 * t + std::size_t(k)]);
    double ux = p[1].x - p[0].x, uy = p[1].y - p[0].y, uz = p[1].z - p[0].z;
    double vx = p[2].x - p[0].x, vy = p[2].y - p[0].y, vz = p[2].z - p[0].z;
    double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    double len = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (len == 0) continue;
    double area = 0.5 * len / (s * s);  // in cells^2
    nx /= len, ny /= len, nz /= len;
    for (int k = 0; k < 3; ++k) {
      std::uint64_t c = cluster[f.mesh.triangles[3 * t + std::size_t(k)]];
      Vec3d pc = f.position(c);
      double d = (nx * (p[0].x - pc.x) + ny * (p[0].y - pc.y) + nz * (p[0].z - pc.z)) / s;  // plane offset, cells
      double q[9] = {nx * nx, nx * ny, nx * nz, ny * ny, ny * nz, nz * nz, d * nx, d * ny, d * nz};
      for (int j = 0; j < 9; ++j) expected[c].t[j] += area * q[j];
    }
  }
  for (double side : {f.cell, 2.5 * f.cell, 100 * f.cell}) {
    INFO("tile side " << side);
    BinnedTiles tiles = bin(f, in, side);
    FloatingCellShape cell{f.cell, CellShape::cube};
    BorderDecisions decisions(tiles.grid, cell);
    FirstChoice first = [&](std::uint32_t t, const std::vector<GradedVertex>& v) {
      return decisions.choose_first(t, v);
    };
    // Blocks in memory here, in a file in the test above.
    std::unique_ptr<BlockStore> blocks =
        grade_tiles(tiles, in.positions, first, GradingSettings{{f.cell, f.dir.path(), std::uint64_t(1) << 30}});
    decisions.sweep(*blocks, nullptr);
    TileBorders borders = decisions.take_borders();
    AccumulationSettings settings{cell, AssignRule::nearest, 64u << 20, f.spill(), nullptr};
    ClusterShares shares = accumulate_clusters(tiles, in.positions, *blocks, borders, in.positions.count, settings);
    std::map<std::uint64_t, ClusterRecord> got;
    for (std::uint32_t b = 0; b < shares.partials->stream_count(); ++b) {
      std::vector<PartialCluster> v;
      shares.partials->read(b, &v);
      for (const PartialCluster& p : v) {
        CHECK(p.centre / shares.cluster_span == b);
        auto it = got.find(p.centre);
        if (it == got.end())
          got[p.centre] = p.sums;
        else
          it->second.add(p.sums);
      }
    }
    REQUIRE(got.size() == expected.size());
    for (const auto& [c, e] : expected) {
      INFO("centre " << c);
      REQUIRE(got.count(c));
      const ClusterRecord& r = got[c];
      CHECK(r.members == e.members);
      CHECK(r.centre.x == f.position(c).x);
      for (int k = 0; k < 12; ++k) CHECK(term(r, k) == Approx(e.t[k]).margin(1e-7));
    }
    // Every triangle is decided inside a tile or has each of its corners reported once.
    std::uint64_t corners = 0, inside = 0;
    for (std::uint32_t b = 0; b < shares.corners->stream_count(); ++b) corners += shares.corners->record_count(b);
    for (std::uint32_t b = 0; b < shares.inside->stream_count(); ++b) inside += shares.inside->record_count(b);
    std::uint64_t crossing = 0, kept_inside = 0;
    std::set<std::array<std::uint64_t, 3>> inside_triples;
    for (std::size_t t = 0; t < f.mesh.triangle_count(); ++t) {
      std::set<std::array<std::int64_t, 3>> in_tiles;
      std::array<std::uint64_t, 3> cl;
      for (int k = 0; k < 3; ++k) {
        std::uint64_t v = f.mesh.triangles[3 * t + std::size_t(k)];
        in_tiles.insert(tile_of(f.position(v), side));
        cl[std::size_t(k)] = cluster[v];
      }
      if (in_tiles.size() > 1) {
        crossing += 3;
      } else if (cl[0] != cl[1] && cl[1] != cl[2] && cl[0] != cl[2]) {
        std::sort(cl.begin(), cl.end());
        kept_inside += inside_triples.insert(cl).second;  // at most once per tile; one tile here
      }
    }
    CHECK(corners == crossing);
    if (side == 100 * f.cell) CHECK(inside == kept_inside);  // one tile: no duplicates across tiles
    CHECK(inside >= kept_inside);
  }
}

TEST_CASE("stitch and assembly on a hand-made case: first occurrences in input order, vertices by first use",
          "[floating][stages]") {
  ScratchDir d;
  // Clusters 10, 20, 30, 40 centred at (i, 0, 0) for centre index 10 i; cell 2.
  auto share = [](std::uint64_t centre, double mx, std::uint64_t members) {
    PartialCluster p{};
    p.centre = centre;
    p.sums.centre = {double(centre / 10), 0, 0};
    p.sums.offset_sum.x.add(Fixed::of(mx));
    p.sums.members = members;
    return p;
  };
  for (RepresentativeRule rule : {RepresentativeRule::centre, RepresentativeRule::mean}) {
    StreamSpill partials(d.path(), "p", sizeof(PartialCluster), 64, false);
    partials.add_stream();
    partials.add_stream();
    // Cluster 20's shares come from two tiles: its mean is (0.25 + 0.5) / 3 cells.
    PartialCluster bucket0[] = {share(20, 0.25, 1), share(10, 0, 1), share(20, 0.5, 2)};
    PartialCluster bucket1[] = {share(40, -0.5, 1), share(30, 0.125, 1)};
    partials.append(0, bucket0, 3);
    partials.append(1, bucket1, 2);
    // Triangles decided in tiles (bucket 0: indices 0-7), and a cross-tile triangle 1
    // whose corners 30 and 40 came from one tile and 10 from another.
    StreamSpill inside(d.path(), "i", sizeof(KeptTriangle), 16, false);
    StreamSpill corners(d.path(), "c", sizeof(CornerRecord), 16, false);
    inside.add_stream();
    corners.add_stream();
    KeptTriangle kept[] = {KeptTriangle::of(5, 20, 30, 40), KeptTriangle::of(3, 10, 20, 30),
                           KeptTriangle::of(7, 30, 20, 10)};  // 7: the same clusters as 3, later
    inside.append(0, kept, 3);
    CornerRecord cr[] = {{1 << 2 | 1, 40, 0}, {1 << 2 | 0, 30, 0}, {1 << 2 | 2, 10, 0}};
    corners.append(0, cr, 3);
    inside.flush();
    corners.flush();
    LargeArray<KeptTriangle> stitched = stitch_kept_triangles(inside, corners);
    CHECK(stitched.size() == 4);
    AssemblyCounts counts;
    AssemblySettings assembly;
    assembly.cell = FloatingCellShape{2, CellShape::cube};
    assembly.rule = rule;
    assembly.cluster_span = 64;
    SimplifiedMesh m = assemble_mesh(std::move(stitched), partials, assembly, &counts).take();
    CHECK(counts.clusters == 4);
    // Input order of first occurrence: 1 (30 40 10), 3 (10 20 30), 5 (20 30 40); 7 is 3 again.
    // Vertices by first use: 30 -> 0, 40 -> 1, 10 -> 2, 20 -> 3.
    CHECK(m.triangles == std::vector<std::uint32_t>{0, 1, 2, 2, 3, 0, 3, 0, 1});
    std::vector<double> x = {3, 4, 1, 2};  // centres
    if (rule == RepresentativeRule::mean) x = {3 + 0.125 * 2, 4 - 0.5 * 2, 1, 2 + 0.25 * 2};
    REQUIRE(m.positions.size() == 12);
    for (int v = 0; v < 4; ++v) {
      CHECK(m.positions[3 * std::size_t(v)] == Approx(x[std::size_t(v)]).margin(1e-9));
      CHECK(m.positions[3 * std::size_t(v) + 1] == 0);
    }
  }
}

TEST_CASE("kept tiles: what one run keeps, the next reloads as the same binned and graded tiles",
          "[floating][stages][keep]") {
  Fixture f;
  SpillSettings spill = f.spill();
  spill.compress = true;  // as --keep-tmp has it
  MeshInput in = open_mesh_input(f.path);
  std::vector<std::string> warnings;
  const double side = 3 * f.cell;
  std::vector<TriangleRecords> records;
  std::vector<std::vector<GradedVertex>> graded_before;
  std::vector<GridCoord> coords;
  {
    KeptTileStore store(in, f.dir.path(), &warnings);
    BinnedTiles none;
    std::unique_ptr<StreamSpill> no_graded;
    CHECK_FALSE(store.resume(f.cell, &none, &no_graded));  // nothing kept yet
    REQUIRE(store.start());
    BinnedTiles tiles = bin_triangles(in, side, 64u << 20, spill, nullptr);
    StreamSpill graded(f.dir.path(), "vertices", sizeof(GradedVertex), 4096, false);
    for (std::uint32_t t = 0; t < tiles.count(); ++t) {
      graded.add_stream();
      records.push_back(tiles.load(t));
      graded_before.push_back(grade_tile(records.back(), in.positions));
      graded.append(t, graded_before.back().data(), graded_before.back().size());
      coords.push_back(tiles.grid.coord(t));
    }
    store.keep(tiles, graded);
  }
  CHECK(warnings.empty());
  KeptTileStore store(in, f.dir.path(), &warnings);
  BinnedTiles tiles;
  std::unique_ptr<StreamSpill> graded;
  CHECK_FALSE(store.resume(side * 1.01, &tiles, &graded));  // a cell wider than the kept tiles: bin again
  CHECK(warnings.empty());                                  // (the options, not the files: no warning)
  REQUIRE(store.resume(f.cell, &tiles, &graded));
  CHECK(tiles.grid.side == side);
  CHECK(tiles.triangle_count == f.mesh.triangle_count());
  REQUIRE(tiles.count() == coords.size());
  for (std::uint32_t t = 0; t < tiles.count(); ++t) {
    CHECK(tiles.grid.coord(t) == coords[t]);
    const TriangleRecords r = tiles.load(t);
    REQUIRE(r.size() == records[t].size());
    for (std::size_t i = 0; i < r.size(); ++i) CHECK(r[i].tm == records[t][i].tm);
    std::vector<GradedVertex> g;
    graded->read(t, &g);
    REQUIRE(g.size() == graded_before[t].size());
    for (std::size_t i = 0; i < g.size(); ++i) {
      CHECK(g[i].index == graded_before[t][i].index);
      CHECK(g[i].weight == graded_before[t][i].weight);
    }
  }
}

TEST_CASE("the stats report the fullest tile and every sweep, in SimplifyStats and the --stats JSON",
          "[floating][stages][stats]") {
  Fixture f(40000, 40);
  MeshInput in = open_mesh_input(f.path);
  SimplifyOptions o;
  o.sizing.cell = f.cell;
  o.floating.tile_side = 3 * f.cell;
  SimplifyStats st;
  simplify(in, o, &st);
  CHECK(st.floating.tiles > 8);
  CHECK(st.floating.largest_tile_records >= st.input_triangles / st.floating.tiles);  // at least the average
  CHECK(st.floating.largest_tile_records <= st.input_triangles);                      // a triangle is once per tile
  REQUIRE(st.floating.sweeps.size() >= 2);  // tiles this small share borders: something to re-decide
  CHECK(st.floating.sweeps[0].looked_at > 0);
  for (const FloatingStats::SweepCount& s : st.floating.sweeps) {
    CHECK(s.rerun <= s.looked_at);
    CHECK(s.looked_at <= st.floating.tiles);
  }
  CHECK(st.floating.rounds <= 1 + st.floating.sweeps.size());
  // What the tiles hand on: whole records; a sweep publishes only from tiles it re-ran.
  CHECK(st.floating.border_centre_bytes == sizeof(GradedVertex));
  CHECK(st.floating.border_bytes > 0);
  CHECK(st.floating.border_bytes % sizeof(GradedVertex) == 0);
  for (const FloatingStats::SweepCount& s : st.floating.sweeps)
    if (s.rerun == 0) CHECK(s.published == 0);
  CHECK(st.floating.stitch_corner_bytes > 0);  // tiles this small: triangles cross them
  CHECK(st.floating.stitch_corner_bytes % sizeof(CornerRecord) == 0);
  CHECK(st.floating.inside_triangle_bytes % sizeof(KeptTriangle) == 0);
  // Each kept triangle is decided in one place: inside a tile, or in the stitch.
  CHECK(st.floating.inside_triangle_bytes / sizeof(KeptTriangle) <= st.input_triangles);
  CHECK(st.floating.cluster_share_bytes >= st.occupied_cells * sizeof(PartialCluster));

  CliResult r = run_cli("simplify --quiet --cell " + std::to_string(f.cell) + " --tile " + std::to_string(3 * f.cell) +
                        " '" + f.path + "' -o '" + f.dir.file("o.ply") + "' --stats '" + f.dir.file("st.json") + "'");
  REQUIRE(r.exit_code == 0);
  std::string js = read_file(f.dir.file("st.json"));
  INFO(js);
  CHECK(js.find("\"largest_tile_records\": ") != std::string::npos);
  CHECK(js.find("\"sweeps\": [{\"looked_at\": ") != std::string::npos);
  CHECK(js.find("\"rerun\": ") != std::string::npos);
  CHECK(js.find("\"published\": ") != std::string::npos);
  CHECK(js.find("\"exchange\": {\"border_bytes\": ") != std::string::npos);
}

TEST_CASE("the methods are rows of one table that simplify() and the CLI use", "[stages][methods]") {
  const std::vector<ClusterMethodEntry>& m = cluster_method_table();
  REQUIRE(m.size() == 4);
  CHECK(m[0].method == ClusterMethod::floating);  // the default first
  CHECK(cluster_methods() == std::vector<ClusterMethod>{ClusterMethod::floating, ClusterMethod::uniform,
                                                        ClusterMethod::curvature, ClusterMethod::qem});
  std::set<std::string> names;
  for (const ClusterMethodEntry& e : m) {
    CHECK((e.run != nullptr) == (e.method != ClusterMethod::qem));  // qem clusters nothing
    CHECK(names.insert(method_name(e.method)).second);
    CHECK(&cluster_method(e.method) == &e);
  }
  CHECK(names == std::set<std::string>{"floating", "uniform", "curvature", "qem"});
  CHECK(run_cli("simplify --method nosuch in.ply -o out.ply").exit_code == 2);
}
