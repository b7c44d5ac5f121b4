// --method curvature (Hua et al.): flat cells stay whole, cells across a sharp edge
// split, two sheets through one cell stay two clusters, the vertex representative is
// an input vertex, and the output does not depend on threads or tiles. The expected
// values come from the shapes (a plane has no curvature, a cube's edges have) and
// from the uniform method where the two must agree.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

SimplifyOptions clustering(ClusterMethod method, std::uint32_t grid, const ScratchDir& tmp) {
  SimplifyOptions o;
  o.method = method;
  o.sizing.grid = grid;
  o.temp_dir = tmp.path();
  o.weld = true;
  return o;
}

SimplifiedMesh run(const std::string& path, const SimplifyOptions& o, SimplifyStats* stats = nullptr) {
  return simplify_file_to_mesh(path, o, stats);
}

// Two parallel planes z = 0.5 and z = 0.5 + gap over the unit square, each an n x n
// grid of quads, wound the same way.
void write_two_sheets(const std::string& path, int n, double gap) {
  std::vector<float> v;
  std::vector<std::uint32_t> t;
  for (int sheet = 0; sheet < 2; ++sheet) {
    const std::uint32_t base = std::uint32_t(v.size() / 3);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) v.insert(v.end(), {float(i) / n, float(j) / n, float(0.5 + sheet * gap)});
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::uint32_t a = base + std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1),
                            d = c + 1;
        t.insert(t.end(), {a, b, d, a, d, c});
      }
  }
  write_binary_ply(path, v, t);
}

std::set<std::tuple<float, float, float>> position_set(const std::vector<double>& p) {
  std::set<std::tuple<float, float, float>> s;
  for (std::size_t i = 0; i + 2 < p.size(); i += 3) s.insert({float(p[i]), float(p[i + 1]), float(p[i + 2])});
  return s;
}

}  // namespace

TEST_CASE("on a plane no cell splits: the clusters are the uniform cells", "[curvature][method]") {
  ScratchDir d, tmp;
  write_plane_ply(d.file("plane.ply"), 100, 0.3, -0.2, 0.1);
  SimplifyOptions u = clustering(ClusterMethod::uniform, 8, tmp);
  SimplifyOptions c = clustering(ClusterMethod::curvature, 8, tmp);
  // The default representative, quadric: uniform's solve, in the same (unsplit) cell.
  const SimplifiedMesh a = run(d.file("plane.ply"), u), b = run(d.file("plane.ply"), c);
  REQUIRE(a.triangles.size() > 0);
  CHECK(b.triangles == a.triangles);
  CHECK(b.positions == a.positions);
}

TEST_CASE("cells split where a cube's faces meet, and only there", "[curvature][method]") {
  ScratchDir d, tmp;
  write_cube_ply(d.file("cube.ply"), 40);
  const std::string cube = d.file("cube.ply");
  SimplifyOptions c = clustering(ClusterMethod::curvature, 4, tmp);
  SimplifyStats unsplit, split, uniform, fine;
  c.curvature.max_depth = 0;
  run(cube, c, &unsplit);
  c.curvature.max_depth = 2;
  run(cube, c, &split);
  run(cube, clustering(ClusterMethod::uniform, 4, tmp), &uniform);
  run(cube, clustering(ClusterMethod::uniform, 16, tmp), &fine);
  // Without splits each cell holds one connected part of the surface: the uniform
  // cells. With them the cells along the edges are finer, the faces' are not: more
  // clusters than the grid's, fewer than a grid 2^2 times finer everywhere.
  CHECK(unsplit.output_vertices == uniform.output_vertices);
  // With quadric representatives no vertex's own curvature is read: the octree reads
  // the cells' moments, and the ball estimate does not run.
  auto estimated = [](const SimplifyStats& s) {
    return std::any_of(s.phases.begin(), s.phases.end(), [](const PhaseTime& p) { return p.name == "curvatures"; });
  };
  CHECK_FALSE(estimated(unsplit));
  CHECK_FALSE(estimated(split));
  CHECK(split.output_vertices > uniform.output_vertices);
  CHECK(split.output_vertices < fine.output_vertices / 2);
}

TEST_CASE("the vertex representative is an input vertex of its cluster", "[curvature][method]") {
  ScratchDir d, tmp;
  write_cube_ply(d.file("cube.ply"), 30);
  SimplifyOptions o = clustering(ClusterMethod::curvature, 5, tmp);
  o.curvature.representative = RepresentativeRule::vertex;
  const SimplifiedMesh m = run(d.file("cube.ply"), o);
  const LoadedMesh in = load_mesh(d.file("cube.ply"));
  const auto inputs = position_set(in.positions);
  REQUIRE(m.positions.size() > 0);
  for (const auto& p : position_set(m.positions)) CHECK(inputs.count(p) == 1);
}

TEST_CASE("two sheets through one cell stay two clusters", "[curvature][method]") {
  ScratchDir d, tmp;
  // 0.01 apart, cells of 1/8: uniform merges the sheets, curvature keeps each.
  write_two_sheets(d.file("sheets.ply"), 60, 0.01);
  write_plane_ply(d.file("one.ply"), 60, 0, 0, 0.5);
  SimplifyStats one, uniform, curvature;
  run(d.file("one.ply"), clustering(ClusterMethod::curvature, 8, tmp), &one);
  run(d.file("sheets.ply"), clustering(ClusterMethod::uniform, 8, tmp), &uniform);
  const SimplifiedMesh m = run(d.file("sheets.ply"), clustering(ClusterMethod::curvature, 8, tmp), &curvature);
  CHECK(uniform.output_vertices == one.output_vertices);
  CHECK(curvature.output_vertices == 2 * one.output_vertices);
  CHECK(curvature.output_triangles == 2 * one.output_triangles);
  // No triangle joins the sheets.
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    int upper = 0;
    for (int k = 0; k < 3; ++k) upper += m.positions[3 * m.triangles[t + k] + 2] > 0.505;
    CHECK((upper == 0 || upper == 3));
  }
}

TEST_CASE("curvature clustering gives the same bytes for any thread count and curvature tiles",
          "[curvature][method][determinism]") {
  ScratchDir d, tmp;
  write_cube_ply(d.file("cube.ply"), 30);
  for (RepresentativeRule rep : {RepresentativeRule::quadric, RepresentativeRule::vertex}) {
    std::string first;
    for (unsigned threads : {1u, 2u, 3u})
      for (double tile : {0.0, 0.3}) {
        INFO(representative_name(rep) << ", threads " << threads << ", curvature tiles " << tile);
        SimplifyOptions o = clustering(ClusterMethod::curvature, 6, tmp);
        o.curvature.representative = rep;
        o.threads = threads;
        o.curvature.tile_side = tile;
        simplify_file(d.file("cube.ply"), d.file("out.ply"), o, nullptr);
        const std::string bytes = read_file(d.file("out.ply"));
        if (first.empty()) first = bytes;
        CHECK(bytes == first);
      }
  }
}

TEST_CASE("curvature clustering as phase 1 reaches an exact target", "[curvature][method][target]") {
  ScratchDir d, tmp;
  // Large enough for a phase 1 (smaller inputs collapse whole).
  write_plane_ply(d.file("plane.ply"), 230, 0.1, 0.2, 0.3);
  SimplifyOptions o = clustering(ClusterMethod::curvature, 0, tmp);
  o.sizing = CellSizing();
  o.target.triangles = 600;
  SimplifyStats st;
  const SimplifiedMesh m = run(d.file("plane.ply"), o, &st);
  CHECK(m.triangles.size() == 3 * 600);
  CHECK(st.refine.intermediate_triangles > 600);  // phase 1 clustered, phase 2 collapsed
  CHECK(std::any_of(st.phases.begin(), st.phases.end(), [](const PhaseTime& p) { return p.name == "octree"; }));
}

TEST_CASE("curvature clustering keeps thin parts as thick edges, and its levels share one estimate",
          "[curvature][method]") {
  ScratchDir d, tmp;
  REQUIRE(run_cli("generate --shape branches --tris 20000 --quiet -o " + d.file("tree.ply")).exit_code == 0);
  SimplifyOptions o = clustering(ClusterMethod::curvature, 24, tmp);
  o.thick_edges = true;
  SimplifyStats st;
  run(d.file("tree.ply"), o, &st);
  CHECK(st.output_edges > 0);
  // Levels share one estimate of the vertices' curvatures (which the vertex
  // representatives read): the first equals a run of its own at its grid, and only
  // the first level's phases hold the estimate.
  const std::string common = " --method curvature --rep vertex --quiet --tmp " + tmp.path();
  const CliResult r =
      run_cli("simplify " + d.file("tree.ply") + " -o " + d.file("l.ply") + " --grid 24 --lods 2" + common);
  CHECK(r.exit_code == 0);
  REQUIRE(file_exists(d.file("l.lod1.ply")));
  REQUIRE(run_cli("simplify " + d.file("tree.ply") + " -o " + d.file("one.ply") + " --grid 24" + common).exit_code ==
          0);
  CHECK(read_file(d.file("l.lod0.ply")) == read_file(d.file("one.ply")));
  const std::string json = read_file(d.file("l.lods.json"));
  const std::size_t first = json.find("\"curvatures\"");
  CHECK(first != std::string::npos);
  CHECK(json.find("\"curvatures\"", first + 1) == std::string::npos);
}

TEST_CASE("curvature's options are checked and named", "[curvature][method][cli]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 10);
  const std::string run = "simplify " + d.file("cube.ply") + " -o " + d.file("out.ply") + " --quiet ";
  struct Case {
    const char* args;
    const char* names;
  };
  const Case cases[] = {
      {"--method curvature --radius -1", "--radius"},
      {"--method curvature --radius 100", "--radius"},
      {"--method curvature --max-depth 7", "--max-depth"},
      {"--method curvature --curvature-tolerance 0", "--curvature-tolerance"},
      {"--method curvature --rep centre", "--rep"},
      {"--method uniform --curvature-tolerance 0.5", "--curvature-tolerance"},
      {"--method floating --rep vertex", "--rep"},
      {"--method uniform --rep quadric", "--rep"},
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const CliResult r = run_cli(run + c.args);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.names) != std::string::npos);
    CHECK_FALSE(file_exists(d.file("out.ply")));
  }
  const CliResult ok = run_cli("simplify " + d.file("cube.ply") + " -o " + d.file("out.ply") +
                               " --method curvature --grid 4 --rep quadric --max-depth 1 --weld");
  CHECK(ok.exit_code == 0);
  CHECK(ok.out.find("(curvature, grid") != std::string::npos);
}

TEST_CASE("curvature clustering carries colours as the area-weighted mean of a cluster's vertices",
          "[curvature][method][attributes]") {
  ScratchDir d, tmp;
  // red, green, blue = 255 (p - lo) / (hi - lo) over the bounding box, rounded.
  REQUIRE(run_cli("generate --shape sphere --tris 20000 --attributes --quiet -o " + d.file("s.ply")).exit_code == 0);
  const LoadedMesh in = load_mesh(d.file("s.ply"));
  SimplifyStats st;
  const SimplifiedMesh m = run(d.file("s.ply"), clustering(ClusterMethod::curvature, 12, tmp), &st);
  const std::vector<VertexAttribute>& a = m.attributes.attributes;
  const std::size_t width = a.size();
  REQUIRE(m.positions.size() > 3 * 100);
  const char* names[3] = {"red", "green", "blue"};
  const double lo[3] = {in.info.bounds.min.x, in.info.bounds.min.y, in.info.bounds.min.z};
  const double hi[3] = {in.info.bounds.max.x, in.info.bounds.max.y, in.info.bounds.max.z};
  for (int c = 0; c < 3; ++c) {
    INFO(names[c]);
    std::size_t k = 0;
    while (k < width && a[k].name != names[c]) ++k;
    REQUIRE(k < width);
    // A cluster's vertices and its representative share a leaf no larger than the
    // grid's cell: the mean lies within the function's change across its diagonal,
    // plus the rounding to whole units.
    const double bound = 1.0 + 255 * st.cell_size * std::sqrt(3.0) / (hi[c] - lo[c]);
    double worst = 0;
    for (std::size_t v = 0; v < m.positions.size() / 3; ++v) {
      const double expected = 255 * (m.positions[3 * v + std::size_t(c)] - lo[c]) / (hi[c] - lo[c]);
      worst = std::max(worst, std::fabs(m.attributes.values[width * v + k] - expected));
    }
    CHECK(worst <= bound);
  }
}
