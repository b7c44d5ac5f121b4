#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "oocsimp/error.hpp"
#include "api/simplify.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

SimplifiedMesh simplify_path(const std::string& path, const CellSizing& sizing, unsigned threads = 0,
                             SimplifyStats* stats = nullptr) {
  MeshInput in = open_mesh_input(path);
  SimplifyOptions o;
  o.method = ClusterMethod::uniform;
  o.sizing = sizing;
  o.threads = threads;
  return simplify(in, o, stats);
}

CellSizing grid(std::uint32_t n) {
  CellSizing s;
  s.grid = n;
  return s;
}

}  // namespace

TEST_CASE("a finely tessellated plane simplifies to vertices on the plane", "[uniform]") {
  ScratchDir d;
  // z = 0.3x - 0.2y + 0.1 over the unit square.
  write_plane_ply(d.file("plane.ply"), 200, 0.3, -0.2, 0.1);
  SimplifyStats st;
  SimplifiedMesh m = simplify_path(d.file("plane.ply"), grid(16), 0, &st);
  REQUIRE(m.positions.size() > 100 * 3);
  REQUIRE(st.input_triangles == 2 * 200 * 200);
  double diag = std::sqrt(1 + 1 + 0.5 * 0.5);
  double norm = std::sqrt(0.3 * 0.3 + 0.2 * 0.2 + 1);
  double worst = 0;
  for (std::size_t i = 0; i < m.positions.size(); i += 3) {
    double x = m.positions[i], y = m.positions[i + 1], z = m.positions[i + 2];
    worst = std::max(worst, std::fabs(0.3 * x - 0.2 * y + 0.1 - z) / norm);
  }
  CHECK(worst <= 1e-6 * diag);
}

TEST_CASE("the eight corners of a tessellated cube survive quadric clustering", "[uniform]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 60);
  SimplifiedMesh m = simplify_path(d.file("cube.ply"), grid(7));
  double diag = std::sqrt(3.0);
  for (int c = 0; c < 8; ++c) {
    double cx = c & 1, cy = (c >> 1) & 1, cz = (c >> 2) & 1;
    double best = 1e9;
    for (std::size_t i = 0; i < m.positions.size(); i += 3)
      best = std::min(best, std::sqrt((m.positions[i] - cx) * (m.positions[i] - cx) +
                                      (m.positions[i + 1] - cy) * (m.positions[i + 1] - cy) +
                                      (m.positions[i + 2] - cz) * (m.positions[i + 2] - cz)));
    INFO("corner " << cx << " " << cy << " " << cz);
    CHECK(best <= 1e-5 * diag);
  }
}

TEST_CASE("output keeps only triangles spanning three cells, each cell triple once", "[uniform]") {
  ScratchDir d;
  write_plane_ply(d.file("plane.ply"), 64, 0, 0, 0);
  SimplifiedMesh m = simplify_path(d.file("plane.ply"), grid(8));
  std::set<std::array<std::uint32_t, 3>> seen;
  for (std::size_t i = 0; i < m.triangles.size(); i += 3) {
    std::array<std::uint32_t, 3> t{m.triangles[i], m.triangles[i + 1], m.triangles[i + 2]};
    CHECK(t[0] != t[1]);
    CHECK(t[1] != t[2]);
    CHECK(t[0] != t[2]);
    std::sort(t.begin(), t.end());
    CHECK(seen.insert(t).second);
    for (auto v : t) CHECK(v < m.positions.size() / 3);
  }
  // An 8x8 grid of cells on a flat square: 9x9 = 81 cell vertices at most, and the
  // surviving triangles cover the square with all normals pointing up (+z), like
  // the input.
  CHECK(m.positions.size() / 3 <= 81);
  double area = 0;
  for (std::size_t i = 0; i < m.triangles.size(); i += 3) {
    const double* a = &m.positions[3 * m.triangles[i]];
    const double* b = &m.positions[3 * m.triangles[i + 1]];
    const double* c = &m.positions[3 * m.triangles[i + 2]];
    double nz = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    CHECK(nz > 0);
    area += nz / 2;
  }
  CHECK(area > 0.7);
  CHECK(area <= 1.0 + 1e-6);
}

TEST_CASE("output is byte-identical for any thread count", "[uniform]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 300000 --shape parts --seed 3 --quiet -o " + d.file("p.ply")).exit_code == 0);
  SimplifiedMesh a = simplify_path(d.file("p.ply"), grid(97), 1);
  SimplifiedMesh b = simplify_path(d.file("p.ply"), grid(97), 2);
  SimplifiedMesh c = simplify_path(d.file("p.ply"), grid(97), 8);
  REQUIRE(a.triangles.size() > 1000);
  CHECK(a.positions == b.positions);
  CHECK(a.triangles == b.triangles);
  CHECK(a.positions == c.positions);
  CHECK(a.triangles == c.triangles);
}

TEST_CASE("ratio sizing lands near the requested fraction", "[uniform]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 400000 --shape sphere --quiet -o " + d.file("s.ply")).exit_code == 0);
  CellSizing s;
  s.ratio = 0.05;
  SimplifyStats st;
  simplify_path(d.file("s.ply"), s, 0, &st);
  double kept = double(st.output_triangles) / double(st.input_triangles);
  CHECK(kept > 0.05 / 2);
  CHECK(kept < 0.05 * 2);
}

TEST_CASE("grid choice validates its options", "[uniform]") {
  ScratchDir d;
  write_plane_ply(d.file("plane.ply"), 4, 0, 0, 0);
  MeshInput in = open_mesh_input(d.file("plane.ply"));
  // Nothing given: the documented default ratio, the same grid as asking for it.
  CellSizing none, tenth;
  tenth.ratio = 0.1;
  GridSpec by_default = choose_grid(in, none, 0), asked = choose_grid(in, tenth, 0);
  CHECK(by_default.cell == asked.cell);
  // A value given is checked, never replaced by a default.
  for (double bad : {-1.0, std::nan(""), HUGE_VAL}) {
    CellSizing cell, ratio;
    cell.cell = bad;
    ratio.ratio = bad;
    CHECK_THROWS_AS(choose_grid(in, cell, 0), UsageError);
    CHECK_THROWS_AS(choose_grid(in, ratio, 0), UsageError);
  }
  CellSizing two;
  two.grid = 4;
  two.cell = 0.1;
  CHECK_THROWS_AS(choose_grid(in, two, 0), UsageError);
  CellSizing tiny;
  tiny.cell = 1e-9;
  CHECK_THROWS_AS(choose_grid(in, tiny, 0), UsageError);
  GridSpec g = choose_grid(in, grid(4), 0);
  CHECK(g.dims[0] == 4);
  CHECK(g.dims[1] == 4);
  CHECK(g.cell == Approx(0.25));
}

namespace {

// The positions of `vertices` of `m`.
std::set<std::array<double, 3>> positions_of(const LoadedMesh& m, const std::vector<std::uint64_t>& vertices) {
  std::set<std::array<double, 3>> out;
  for (std::uint64_t v : vertices) out.insert({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
  return out;
}

// How many vertices of `m` are at one of `wanted`, and whether each is a corner of some
// triangle.
std::size_t count_at(const SimplifiedMesh& m, const std::set<std::array<double, 3>>& wanted, bool* all_used) {
  std::vector<char> used(m.positions.size() / 3, 0);
  for (std::uint32_t v : m.triangles) used[v] = 1;
  std::size_t n = 0;
  *all_used = true;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (wanted.count(std::array<double, 3>{m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]})) {
      ++n;
      *all_used = *all_used && used[i];
    }
  return n;
}

SimplifiedMesh run_locked(const std::string& path, ClusterMethod method, const std::vector<std::uint64_t>& locks,
                          unsigned threads, SimplifyStats* stats = nullptr, double tile = 0) {
  MeshInput in = open_mesh_input(path);
  SimplifyOptions o;
  o.method = method;
  o.sizing = grid(24);
  o.threads = threads;
  o.locked_vertices = locks;
  o.floating.tile_side = tile;
  return simplify(in, o, stats);
}

}  // namespace

TEST_CASE("a locked vertex is a cluster of its own, its output vertex where it is", "[uniform][locks]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --shape parts --tris 20000 -o " + d.file("p.ply")).exit_code == 0);
  REQUIRE(run_cli("generate --quiet --shape terrain --tris 20000 -o " + d.file("t.ply")).exit_code == 0);
  const LoadedMesh parts = load_mesh(d.file("p.ply")), terrain = load_mesh(d.file("t.ply"));
  // Scattered vertices of a closed surface.
  std::vector<std::uint64_t> scattered;
  for (std::uint64_t v = 5; v < parts.vertex_count(); v += 397) scattered.push_back(v);
  // The whole outline of an open one: the edges of one face.
  std::map<std::pair<std::uint64_t, std::uint64_t>, int> edge_faces;
  for (std::size_t t = 0; t < terrain.triangles.size(); t += 3)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint64_t a = terrain.triangles[t + k], b = terrain.triangles[t + (k + 1) % 3];
      ++edge_faces[{std::min(a, b), std::max(a, b)}];
    }
  std::set<std::uint64_t> on_outline;
  for (const auto& e : edge_faces)
    if (e.second == 1) on_outline.insert({e.first.first, e.first.second});
  const std::vector<std::uint64_t> outline(on_outline.begin(), on_outline.end());
  REQUIRE(outline.size() > 100);
  for (ClusterMethod method : {ClusterMethod::uniform, ClusterMethod::curvature, ClusterMethod::floating}) {
    INFO(method_name(method));
    bool used = false;
    // Clustering moves vertices; locked ones stay, each a corner of some triangle, or
    // are left out with a warning where their whole neighbourhood fell in one cell.
    const auto wanted = positions_of(parts, scattered);
    CHECK(count_at(run_locked(d.file("p.ply"), method, {}, 2), wanted, &used) < wanted.size() / 2);
    SimplifyStats st;
    const SimplifiedMesh held = run_locked(d.file("p.ply"), method, scattered, 2, &st);
    const std::size_t kept = count_at(held, wanted, &used);
    CHECK(used);
    CHECK(kept > wanted.size() / 2);
    // The ones left out are counted in a warning (a vertex of the surface that is not
    // locked may happen to stand where a dropped one was: at least the others are kept).
    std::size_t dropped = 0;
    const std::string said = " of " + std::to_string(scattered.size()) + " locked vertices are left out";
    for (const std::string& w : st.warnings)
      if (w.find(said) != std::string::npos) dropped = std::stoul(w);
    CHECK(kept + dropped >= wanted.size());
    CHECK(dropped < wanted.size() / 2);
    const SimplifiedMesh one = run_locked(d.file("p.ply"), method, scattered, 1);
    CHECK(one.positions == held.positions);
    CHECK(one.triangles == held.triangles);
    if (method == ClusterMethod::floating) {  // tiles of 2.5 cells: locks near their borders
      SimplifyStats tiled_stats;
      const SimplifiedMesh tiled = run_locked(d.file("p.ply"), method, scattered, 2, &tiled_stats, 2.5 * st.cell_size);
      CHECK(tiled_stats.floating.tiles > 20);
      CHECK(tiled.positions == held.positions);
      CHECK(tiled.triangles == held.triangles);
    }
    // A locked outline is kept whole: every vertex of it, exactly where it was.
    const auto rim = positions_of(terrain, outline);
    CHECK(count_at(run_locked(d.file("t.ply"), method, outline, 2), rim, &used) == rim.size());
    CHECK(used);
  }
  write_file(d.file("locks.txt"), "5 402\n");
  for (const char* method : {"floating", "uniform"})
    REQUIRE(run_cli("simplify --quiet " + d.file("p.ply") + " -o " + d.file("u.ply") + " --method " + method +
                    " --grid 24 --lock-vertices " + d.file("locks.txt"))
                .exit_code == 0);
}

TEST_CASE("locks hold through a clustering phase 1 and the collapse after it", "[uniform][floating][locks]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --shape sphere --tris 200000 -o " + d.file("f.ply")).exit_code == 0);
  // In double precision, scaled so that no coordinate is a float: one that the grid's
  // origin is taken from and added back to can come back a bit off.
  LoadedMesh sphere = load_mesh(d.file("f.ply"));
  for (double& x : sphere.positions) x = x * 1.1 + 0.3;
  const std::vector<std::uint32_t> triangles(sphere.triangles.begin(), sphere.triangles.end());
  write_mesh(d.file("p.ply"), sphere.positions, triangles, MeshFormat::ply_binary, ScalarType::f64);
  std::vector<std::uint64_t> scattered;
  for (std::uint64_t v = 11; v < sphere.vertex_count(); v += 1999) scattered.push_back(v);
  const auto wanted = positions_of(sphere, scattered);
  for (ClusterMethod method : {ClusterMethod::uniform, ClusterMethod::floating}) {
    INFO(method_name(method));
    MeshInput in = open_mesh_input(d.file("p.ply"));
    SimplifyOptions o;
    o.method = method;
    o.target.triangles = 4000;
    o.target.intermediate_factor = 4;  // a phase 1 of 65536 triangles, the least it hands on
    o.locked_vertices = scattered;
    SimplifyStats st;
    const SimplifiedMesh m = simplify(in, o, &st);
    // Phase 1 clustered (a grid), then the collapse met the target.
    CHECK(st.grid_dims[0] > 0);
    CHECK(st.refine.intermediate_triangles < 200000);
    CHECK(m.triangles.size() / 3 == 4000);
    bool used = false;
    std::size_t dropped = 0;
    for (const std::string& w : st.warnings)
      if (w.find(" locked vertices are left out") != std::string::npos) dropped = std::stoul(w);
    CHECK(count_at(m, wanted, &used) + dropped >= wanted.size());
    CHECK(dropped < wanted.size() / 10);
    CHECK(used);
    // Phase 1 alone keeps every one of them to the last bit.
    MeshInput first = open_mesh_input(d.file("p.ply"));
    SimplifyOptions grid_only;
    grid_only.method = method;
    grid_only.sizing = grid(60);
    grid_only.locked_vertices = scattered;
    SimplifyStats grid_stats;
    const SimplifiedMesh clustered = simplify(first, grid_only, &grid_stats);
    std::size_t left_out = 0;
    for (const std::string& w : grid_stats.warnings)
      if (w.find(" locked vertices are left out") != std::string::npos) left_out = std::stoul(w);
    CHECK(count_at(clustered, wanted, &used) + left_out == wanted.size());
    CHECK(left_out < wanted.size() / 4);
    // Without the locks, the collapse moves most of them.
    MeshInput again = open_mesh_input(d.file("p.ply"));
    o.locked_vertices.clear();
    CHECK(count_at(simplify(again, o, nullptr), wanted, &used) < wanted.size() / 2);
  }
}

TEST_CASE("a lock holds every vertex at its position: the other side of a seam stays with it", "[uniform][locks]") {
  // A closed sphere of 40 x 80 quads whose meridian x > 0, y = 0 has its vertices
  // doubled (one copy for the faces on each side, as a texture seam splits them).
  ScratchDir d;
  const std::uint32_t rings = 40, columns = 80, row = columns + 1;
  std::vector<double> p;
  std::vector<std::uint32_t> t;
  const double pi = 3.14159265358979323846;
  for (std::uint32_t r = 1; r < rings; ++r)
    for (std::uint32_t c = 0; c <= columns; ++c) {
      const double lat = pi * r / rings, lon = 2 * pi * (c % columns) / columns;
      p.insert(p.end(), {std::sin(lat) * std::cos(lon), std::sin(lat) * std::sin(lon), std::cos(lat)});
    }
  const std::uint32_t north = std::uint32_t(p.size() / 3), south = north + 1;
  p.insert(p.end(), {0, 0, 1, 0, 0, -1});
  const auto at = [&](std::uint32_t r, std::uint32_t c) { return (r - 1) * row + c; };
  std::vector<std::uint64_t> side;  // one copy of each doubled vertex
  for (std::uint32_t r = 1; r < rings; ++r) side.push_back(at(r, 0));
  for (std::uint32_t c = 0; c < columns; ++c) {
    t.insert(t.end(), {north, at(1, c), at(1, c + 1), south, at(rings - 1, c + 1), at(rings - 1, c)});
    for (std::uint32_t r = 1; r + 1 < rings; ++r)
      t.insert(t.end(), {at(r, c), at(r + 1, c), at(r + 1, c + 1), at(r, c), at(r + 1, c + 1), at(r, c + 1)});
  }
  write_mesh(d.file("s.ply"), p, t, MeshFormat::ply_binary, ScalarType::f64);
  // Edges of one face once the copies are welded by position: the seam opened there.
  const auto open_edges = [](const SimplifiedMesh& m) {
    std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, int> faces;
    for (std::size_t f = 0; f < m.triangles.size(); f += 3)
      for (std::size_t k = 0; k < 3; ++k) {
        const double* a = &m.positions[3 * std::size_t(m.triangles[f + k])];
        const double* b = &m.positions[3 * std::size_t(m.triangles[f + (k + 1) % 3])];
        std::array<double, 3> x{a[0], a[1], a[2]}, y{b[0], b[1], b[2]};
        if (y < x) std::swap(x, y);
        ++faces[{x, y}];
      }
    std::size_t n = 0;
    for (const auto& e : faces) n += e.second == 1;
    return n;
  };
  const std::size_t free = open_edges(run_locked(d.file("s.ply"), ClusterMethod::uniform, {}, 2));
  CHECK(open_edges(run_locked(d.file("s.ply"), ClusterMethod::uniform, side, 2)) <= free);
}
