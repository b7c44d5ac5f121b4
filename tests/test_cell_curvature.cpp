// The cell-scale curvature estimate (cluster/patch_moments.hpp, cluster/cell_moments.hpp):
// the principal curvatures a cell and its 26 neighbours give on surfaces whose
// curvatures are known exactly. A sphere of radius R has k1 = k2 = 1/R, a cylinder 1/R
// and 0, the saddle z = (x^2 - y^2) / 2 has +1 and -1 at the origin; one flat face has
// none; nothing gives NaN.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cluster/cell_moments.hpp"
#include "cluster/patch_moments.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using oocsimp_test::CliResult;
using oocsimp_test::read_file;
using oocsimp_test::run_cli;
using oocsimp_test::ScratchDir;

namespace {

using Triangle = std::array<Vec3d, 3>;

// Each face to the cell its centroid falls in, relative to the cell's corner, as
// sum_cell_moments adds it.
CellMap<PatchMoments> cell_sums(const std::vector<Triangle>& faces, const MomentLattice& lattice) {
  CellMap<PatchMoments> cells;
  for (const Triangle& t : faces) {
    const Vec3d a = t[0] - lattice.origin, b = t[1] - lattice.origin, c = t[2] - lattice.origin;
    const std::uint64_t key = lattice.key_relative((a + b + c) / 3.0);
    const Vec3d corner = lattice.corner(key);
    cells.value(cells.insert(key)).add_triangle(a - corner, b - corner, c - corner);
  }
  return cells;
}

MomentLattice lattice_over(const Vec3d& lo, const Vec3d& hi, double side) {
  MomentLattice l;
  l.origin = lo;
  l.side = side;
  l.dims[0] = std::uint64_t((hi.x - lo.x) / side) + 1;
  l.dims[1] = std::uint64_t((hi.y - lo.y) / side) + 1;
  l.dims[2] = std::uint64_t((hi.z - lo.z) / side) + 1;
  return l;
}

struct IndexedMesh {
  std::vector<Vec3d> v;
  std::vector<std::array<int, 3>> f;
};

// An icosahedron subdivided `levels` times, its vertices on the unit sphere, wound
// counter-clockwise seen from outside.
IndexedMesh unit_icosphere(int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3d> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vec3d& p : v) p = p / length(p);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      const Vec3d m = (v[a] + v[b]) / 2.0;
      v.push_back(m / length(m));
      mid[key] = int(v.size() - 1);
      return int(v.size() - 1);
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& g : f) {
      const int ab = midpoint(g[0], g[1]), bc = midpoint(g[1], g[2]), ca = midpoint(g[2], g[0]);
      next.push_back({g[0], ab, ca});
      next.push_back({g[1], bc, ab});
      next.push_back({g[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = next;
  }
  return {v, f};
}

// The same on the sphere of radius r about `centre`, as triangles.
std::vector<Triangle> icosphere(const Vec3d& centre, double r, int levels) {
  const IndexedMesh m = unit_icosphere(levels);
  std::vector<Triangle> out;
  for (const auto& g : m.f) out.push_back({centre + m.v[g[0]] * r, centre + m.v[g[1]] * r, centre + m.v[g[2]] * r});
  return out;
}

// ... and as a binary PLY.
void write_icosphere(const std::string& path, double r, int levels) {
  const IndexedMesh m = unit_icosphere(levels);
  std::vector<float> xyz;
  for (const Vec3d& p : m.v) xyz.insert(xyz.end(), {float(p.x * r), float(p.y * r), float(p.z * r)});
  std::vector<std::uint32_t> tris;
  for (const auto& g : m.f) tris.insert(tris.end(), {std::uint32_t(g[0]), std::uint32_t(g[1]), std::uint32_t(g[2])});
  oocsimp_test::write_binary_ply(path, xyz, tris);
}

// The k1 and k2 columns of an ascii PLY that `oocsimp curvature --ascii` wrote, after
// checking its header declares them after x, y and z.
std::vector<std::pair<double, double>> read_k(const std::string& path) {
  std::istringstream in(read_file(path));
  std::string line;
  std::vector<std::string> properties;
  std::size_t vertices = 0;
  while (std::getline(in, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) vertices = std::stoul(line.substr(15));
    if (line.rfind("property float ", 0) == 0 && properties.size() < 5) properties.push_back(line.substr(15));
  }
  REQUIRE(properties == std::vector<std::string>{"x", "y", "z", "k1", "k2"});
  std::vector<std::pair<double, double>> k(vertices);
  for (auto& [a, b] : k) {
    std::string x, y, z, k1, k2;
    in >> x >> y >> z >> k1 >> k2;
    a = std::stod(k1);  // "nan" parses as NaN, which the checks below catch
    b = std::stod(k2);
  }
  return k;
}

// The N of "give at least N MiB" in `text`, 0 if absent.
std::uint64_t named_mib(const std::string& text) {
  const std::string key = "give at least ";
  const std::size_t at = text.find(key);
  if (at == std::string::npos) return 0;
  return std::stoull(text.substr(at + key.size()));
}

// A grid of n x m quads over a parametric surface, two triangles each.
template <class Surface>
std::vector<Triangle> grid_surface(int n, int m, Surface s) {
  std::vector<Triangle> out;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      const Vec3d a = s(i, j), b = s(i + 1, j), c = s(i + 1, j + 1), d = s(i, j + 1);
      out.push_back({a, b, c});
      out.push_back({a, c, d});
    }
  return out;
}

}  // namespace

TEST_CASE("a sphere of radius R has k1 = k2 = 1/R in every cell, at cell sides R/20 to R/4", "[curvature][cells]") {
  const double r = 2.0;
  const Vec3d centre{0.123, 0.0456, -0.0789};
  const std::vector<Triangle> faces = icosphere(centre, r, 6);  // mean edge about R/53
  for (const double side : {r / 20, r / 10, r / 4}) {
    const MomentLattice lattice = lattice_over(centre - Vec3d{r, r, r}, centre + Vec3d{r, r, r}, side);
    const CellMap<PatchMoments> cells = cell_sums(faces, lattice);
    double worst = 0;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const PatchCurvature k = neighbourhood_curvature(cells, lattice, cells.key(i));
      REQUIRE(k.fit == PatchFit::slope);
      worst = std::max({worst, std::abs(k.k1 * r - 1), std::abs(k.k2 * r - 1)});
    }
    INFO("side R/" << r / side << ": " << cells.size() << " cells, worst relative error " << worst);
    CHECK(worst < 0.05);
  }
}

TEST_CASE("a sphere wound inside out has k1 = k2 = -1/R", "[curvature][cells]") {
  const double r = 1.0;
  std::vector<Triangle> faces = icosphere({0, 0, 0}, r, 5);
  for (Triangle& t : faces) std::swap(t[1], t[2]);
  const MomentLattice lattice = lattice_over({-1, -1, -1}, {1, 1, 1}, r / 8);
  const CellMap<PatchMoments> cells = cell_sums(faces, lattice);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const PatchCurvature k = neighbourhood_curvature(cells, lattice, cells.key(i));
    CHECK(k.k1 * r == Approx(-1).margin(0.05));
    CHECK(k.k2 * r == Approx(-1).margin(0.05));
  }
}

TEST_CASE("a cylinder of radius R has 1/R and 0", "[curvature][cells]") {
  const double r = 1.5, half = 3.0;
  const int around = 480, along = 320;
  const double pi = std::acos(-1.0);
  const std::vector<Triangle> faces = grid_surface(around, along, [&](int i, int j) {
    const double a = 2 * pi * i / around;
    return Vec3d{r * std::cos(a) + 0.01, r * std::sin(a) - 0.02, -half + 2 * half * j / along};
  });
  for (const double side : {r / 20, r / 10, r / 4}) {
    const MomentLattice lattice = lattice_over({-2 * r, -2 * r, -half - 0.1}, {2 * r, 2 * r, half + 0.1}, side);
    const CellMap<PatchMoments> cells = cell_sums(faces, lattice);
    double worst1 = 0, worst2 = 0;
    std::size_t tested = 0;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const Vec3d mid = lattice.corner(cells.key(i)) + lattice.origin + Vec3d{side, side, side} * 0.5;
      if (std::abs(mid.z) > half - 2 * side) continue;  // away from the open ends
      const PatchCurvature k = neighbourhood_curvature(cells, lattice, cells.key(i));
      REQUIRE(k.fit == PatchFit::slope);
      worst1 = std::max(worst1, std::abs(k.k1 * r - 1));
      worst2 = std::max(worst2, std::abs(k.k2 * r));
      ++tested;
    }
    INFO("side R/" << r / side << ": " << tested << " cells");
    CHECK(tested > 100);
    CHECK(worst1 < 0.05);
    CHECK(worst2 < 0.05);
  }
}

TEST_CASE("the saddle z = (x^2 - y^2) / 2 has +1 and -1 at the origin", "[curvature][cells]") {
  const int n = 400;
  const std::vector<Triangle> faces = grid_surface(n, n, [&](int i, int j) {
    const double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n;
    return Vec3d{x, y, (x * x - y * y) / 2};
  });
  for (const double side : {0.02, 0.05, 0.1}) {
    // The cell centred on the origin.
    const MomentLattice lattice =
        lattice_over({-10.5 / 0.1 * side, -10.5 / 0.1 * side, -10.5 / 0.1 * side}, {1.1, 1.1, 1.1}, side);
    const CellMap<PatchMoments> cells = cell_sums(faces, lattice);
    const PatchCurvature k = neighbourhood_curvature(cells, lattice, lattice.key_relative(-lattice.origin));
    INFO("side " << side << ": " << k.k1 << ", " << k.k2);
    CHECK(k.fit == PatchFit::slope);
    CHECK(k.k1 == Approx(1).margin(0.1));
    CHECK(k.k2 == Approx(-1).margin(0.1));
  }
}

TEST_CASE("a cell holding one flat face has no curvature, and nothing gives NaN", "[curvature][cells]") {
  PatchMoments one;
  one.add_triangle({0.1, 0.2, 0.3}, {0.7, 0.25, 0.3}, {0.3, 0.9, 0.35});
  const PatchCurvature flat = patch_curvature(one);
  CHECK(flat.k1 == 0);
  CHECK(flat.k2 == 0);

  // A plane of many faces: zero, by the slope.
  PatchMoments plane;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const Vec3d a{0.1 * i, 0.1 * j, 0.2 + 0.01 * i}, b{0.1 * (i + 1), 0.1 * j, 0.2 + 0.01 * (i + 1)},
          c{0.1 * i, 0.1 * (j + 1), 0.2 + 0.01 * i};
      plane.add_triangle(a, b, c);
    }
  const PatchCurvature p = patch_curvature(plane);
  CHECK(p.fit == PatchFit::slope);
  CHECK(std::abs(p.k1) < 1e-9);
  CHECK(std::abs(p.k2) < 1e-9);

  // Nothing, zero-area faces, a strip one face wide, the two windings of one face, and
  // non-finite input: 0 and 0, never NaN.
  PatchMoments none;
  CHECK(patch_curvature(none).fit == PatchFit::empty);
  PatchMoments degenerate;
  degenerate.add_triangle({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  degenerate.add_triangle({0, 0, 0}, {0, 0, 0}, {0, 1, 0});
  CHECK(patch_curvature(degenerate).fit == PatchFit::empty);
  PatchMoments strip;
  for (int i = 0; i < 8; ++i)
    strip.add_triangle({0.1 * i, 0, 0.01 * i * i}, {0.1 * i + 0.1, 0, 0.01 * i * i}, {0.1 * i, 0.01, 0.01 * i * i});
  const PatchCurvature s = patch_curvature(strip);
  CHECK(std::isfinite(s.k1));
  CHECK(std::isfinite(s.k2));
  PatchMoments both;
  both.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  both.add_triangle({0, 0, 0}, {0, 1, 0}, {1, 0, 0});
  CHECK(patch_curvature(both).fit == PatchFit::folded);
  CHECK(patch_curvature(both).k1 == 0);
  PatchMoments bad;
  bad.add_face({std::nan(""), 0, 0}, {0, 0, 1});
  const PatchCurvature b = patch_curvature(bad);
  CHECK(b.k1 == 0);
  CHECK(b.k2 == 0);
}

TEST_CASE("a cell's moments shifted to another corner give the same curvature", "[curvature][cells]") {
  // The sums of two halves of a sphere's faces, each relative to its own corner and
  // then added with the shift between the corners, equal the sums taken at once.
  const std::vector<Triangle> faces = icosphere({0.3, 0.2, 0.1}, 1.0, 3);
  PatchMoments whole, left, right;
  const Vec3d shift{0.25, -0.5, 0.125};
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Triangle& t = faces[i];
    if (t[0].z < 0.5) continue;
    whole.add_triangle(t[0], t[1], t[2]);
    if (i % 2)
      left.add_triangle(t[0], t[1], t[2]);
    else
      right.add_triangle(t[0] - shift, t[1] - shift, t[2] - shift);
  }
  PatchMoments joined = left;
  joined.add(right, shift);
  const PatchCurvature a = patch_curvature(whole), b = patch_curvature(joined);
  CHECK(a.k1 == Approx(b.k1).epsilon(1e-9));
  CHECK(a.k2 == Approx(b.k2).epsilon(1e-9));
  CHECK(a.k1 == Approx(1).epsilon(0.02));
}

TEST_CASE("oocsimp curvature --at-scale: a sphere's vertices get k1 = k2 = 1/R, a generated one finite values",
          "[curvature][cells][cli]") {
  ScratchDir d;
  // An icosphere of radius R = 2 (5 subdivisions, mean edge about R/27) at cells of
  // R/8: every vertex interpolates cells whose patches lie on the sphere.
  const double r = 2;
  write_icosphere(d.file("ico.ply"), r, 5);
  const CliResult ok =
      run_cli("curvature " + d.file("ico.ply") + " -o " + d.file("k.ply") + " --ascii --at-scale 0.25");
  INFO(ok.err);
  REQUIRE(ok.exit_code == 0);
  CHECK(ok.out.find("input   10242 vertices, 20480 triangles") != std::string::npos);
  CHECK(ok.out.find("scale   cells of side 0.25") != std::string::npos);
  CHECK(ok.out.find("estimated 10242 from the cells around them, 0 not at all") != std::string::npos);
  CHECK(ok.err.find("warning") == std::string::npos);
  const auto k = read_k(d.file("k.ply"));
  REQUIRE(k.size() == 10242);
  for (const auto& [k1, k2] : k) {
    REQUIRE(std::isfinite(k1));
    REQUIRE(std::isfinite(k2));
    CHECK(k1 * r == Approx(1).margin(0.05));
    CHECK(k2 * r == Approx(1).margin(0.05));
  }
  // The generated sphere is displaced by sinusoids, so its curvature is not 1/R
  // anywhere in particular; what holds is that every vertex gets finite values,
  // k1 >= k2, from cells around it.
  REQUIRE(run_cli("generate --shape sphere --tris 20000 --quiet -o " + d.file("gen.ply")).exit_code == 0);
  const CliResult gen =
      run_cli("curvature " + d.file("gen.ply") + " -o " + d.file("g.ply") + " --ascii --at-scale 0.1");
  REQUIRE(gen.exit_code == 0);
  CHECK(gen.err.find("warning") == std::string::npos);
  const auto g = read_k(d.file("g.ply"));
  REQUIRE(g.size() > 9000);
  for (const auto& [k1, k2] : g) {
    REQUIRE(std::isfinite(k1));
    REQUIRE(std::isfinite(k2));
    CHECK(k1 >= k2);
  }
}

TEST_CASE("the cell-scale estimate's output bytes do not depend on threads or --mem", "[curvature][cells][cli]") {
  ScratchDir d;
  // More faces than one chunk of the moments pass (2^15), so that chunks' tables are
  // merged; parts, whose edges make the octree split.
  REQUIRE(run_cli("generate --shape sphere --tris 100000 --quiet -o " + d.file("s.ply")).exit_code == 0);
  REQUIRE(run_cli("generate --shape parts --tris 100000 --seed 3 --quiet -o " + d.file("p.ply")).exit_code == 0);
  const std::string scale = "curvature " + d.file("s.ply") + " --quiet --at-scale 0.05 -o ";
  REQUIRE(run_cli(scale + d.file("a1.ply") + " --threads 1").exit_code == 0);
  for (const char* more : {"--threads 2", "--threads 3", "--threads 2 --mem 40M"}) {
    INFO(more);
    REQUIRE(run_cli(scale + d.file("a.ply") + " " + more).exit_code == 0);
    CHECK(read_file(d.file("a.ply")) == read_file(d.file("a1.ply")));
  }
  const std::string octree = "simplify " + d.file("p.ply") + " --quiet --method curvature --grid 24 -o ";
  REQUIRE(run_cli(octree + d.file("c1.ply") + " --max-depth 2 --threads 1").exit_code == 0);
  REQUIRE(run_cli(octree + d.file("c0.ply") + " --max-depth 0").exit_code == 0);
  CHECK(read_file(d.file("c1.ply")) != read_file(d.file("c0.ply")));  // the octree split cells
  for (const char* more : {"--threads 2", "--threads 3", "--threads 2 --mem 64M"}) {
    INFO(more);
    REQUIRE(run_cli(octree + d.file("c.ply") + " --max-depth 2 " + more).exit_code == 0);
    CHECK(read_file(d.file("c.ply")) == read_file(d.file("c1.ply")));
  }
}

TEST_CASE("a --mem too small for the cell tables exits 2 before reading a face, naming a budget that works",
          "[curvature][cells][cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --shape sphere --tris 100000 --quiet -o " + d.file("s.ply")).exit_code == 0);
  const std::string in = d.file("s.ply");
  // --at-scale: about 60k cells of side 0.02 on the sphere, some 14 MiB of tables.
  const std::string scale = "curvature " + in + " --quiet --at-scale 0.02 -o ";
  REQUIRE(run_cli(scale + d.file("whole.ply")).exit_code == 0);
  const CliResult small = run_cli(scale + d.file("x.ply") + " --mem 4M");
  INFO(small.err);
  CHECK(small.exit_code == 2);
  CHECK(small.err.find("--mem 4 MiB cannot hold about") != std::string::npos);
  CHECK(small.err.find("estimated") != std::string::npos);
  const std::uint64_t named = named_mib(small.err);
  REQUIRE(named > 4);
  const CliResult enough = run_cli(scale + d.file("enough.ply") + " --mem " + std::to_string(named) + "M");
  INFO(enough.err);
  CHECK(enough.exit_code == 0);
  CHECK(read_file(d.file("enough.ply")) == read_file(d.file("whole.ply")));
  // In the library: refused before the pass over the faces begins.
  std::vector<std::string> phases;
  CurvatureOptions o;
  o.at_scale = 0.02;
  o.memory_budget = 4 << 20;
  o.progress = [&](const Progress& p) {
    if (p.event == Progress::Event::begin) phases.push_back(p.phase);
    return true;
  };
  CHECK_THROWS_AS(curvature_file(in, d.file("y.ply"), o, nullptr), UsageError);
  CHECK(std::find(phases.begin(), phases.end(), std::string("cell moments")) == phases.end());
  // The octree of --method curvature: its first depth's moments (cells of side 1/400
  // of the box, about one a face), estimated up front. 32 MiB is the least budget a
  // simplification takes.
  const std::string octree = "simplify " + in + " --quiet --method curvature --grid 200 --max-depth 1 -o ";
  REQUIRE(run_cli(octree + d.file("c.ply")).exit_code == 0);
  const CliResult tight = run_cli(octree + d.file("x.ply") + " --mem 32M");
  INFO(tight.err);
  CHECK(tight.exit_code == 2);
  CHECK(tight.err.find("cells of curvature moments at depth 1, estimated") != std::string::npos);
  const std::uint64_t octree_named = named_mib(tight.err);
  REQUIRE(octree_named > 32);
  const CliResult roomy = run_cli(octree + d.file("c-enough.ply") + " --mem " + std::to_string(octree_named) + "M");
  INFO(roomy.err);
  CHECK(roomy.exit_code == 0);
  CHECK(read_file(d.file("c-enough.ply")) == read_file(d.file("c.ply")));
  SimplifyOptions s;
  s.method = ClusterMethod::curvature;
  s.sizing.grid = 200;
  s.curvature.max_depth = 1;
  s.memory_budget = 32 << 20;
  s.temp_dir = d.path();
  phases.clear();
  s.progress = o.progress;
  CHECK_THROWS_AS(simplify_file(in, d.file("z.ply"), s, nullptr), UsageError);
  CHECK(std::find(phases.begin(), phases.end(), std::string("curvature moments")) == phases.end());
  CHECK(d.entries() == std::vector<std::string>{"c-enough.ply", "c.ply", "enough.ply", "s.ply", "whole.ply"});
}
