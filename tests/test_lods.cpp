// simplify --lods (Low & Tan 1997 §3.2.2 and §4): every level equals its own run byte
// for byte, the description lists what the files hold, and bad requests exit 2 before
// anything is written.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "oocsimp/generate.hpp"
#include "oocsimp/lod.hpp"
#include "oocsimp/measure.hpp"
#include "api/simplify.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

// The cell as text that reads back as the same double.
std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Runs `simplify --quiet IN -o OUT ARGS`, which must succeed, and gives the triangle
// count of each level its description lists.
std::vector<std::uint64_t> level_triangles(const std::string& in, const std::string& out, const std::string& args) {
  REQUIRE(run_cli("simplify --quiet " + q(in) + " -o " + q(out) + " " + args).exit_code == 0);
  std::vector<std::uint64_t> counts;
  for (const LodLevel& l : read_lod_levels(lod_description_path(out))) counts.push_back(l.triangles);
  return counts;
}

}  // namespace

TEST_CASE("level names and the description's name", "[lods]") {
  CHECK(lod_level_path("out.ply", 0) == "out.lod0.ply");
  CHECK(lod_level_path("a/b.obj.zst", 3) == "a/b.lod3.obj.zst");
  CHECK(lod_level_path("a.b/c", 1) == "a.b/c.lod1");
  CHECK(lod_description_path("a/out.ply.zst") == "a/out.lods.json");
  CHECK(lod_description_path("out.stl") == "out.lods.json");
}

TEST_CASE("every level of simplify --lods equals its separate run byte for byte", "[lods][determinism]") {
  ScratchDir d;
  GenerateOptions g;
  g.triangles = OOCSIMP_TEST_UNDER_ASAN ? 20000 : 100000;
  generate_mesh(d.file("sphere.ply"), g);
  for (const char* method : {"floating", "uniform"})
    for (const char* threads : {"1", "2"}) {
      INFO(method << " threads " << threads);
      const std::string common = std::string(" --quiet --method ") + method + " --threads " + threads;
      const CliResult r = run_cli("simplify " + q(d.file("sphere.ply")) + " -o " + q(d.file("l.ply")) +
                                  " --grid 100 --lods 3 --lod-factor 2" + common);
      REQUIRE(r.exit_code == 0);
      const std::vector<LodLevel> levels = read_lod_levels(d.file("l.lods.json"));
      REQUIRE(levels.size() == 3);
      for (std::uint32_t k = 0; k < 3; ++k) {
        INFO("level " << k);
        CHECK(levels[k].file == "l.lod" + std::to_string(k) + ".ply");
        CHECK(levels[k].cell == levels[0].cell * std::pow(2.0, double(k)));
        // Level 0 is the run with the options given; the others the runs at their cell.
        const std::string sizing = k == 0 ? " --grid 100" : " --cell " + exact(levels[k].cell);
        REQUIRE(run_cli("simplify " + q(d.file("sphere.ply")) + " -o " + q(d.file("one.ply")) + sizing + common)
                    .exit_code == 0);
        CHECK(read_file(d.file("one.ply")) == read_file(d.file(levels[k].file)));
        // The description counts what the file holds.
        const LoadedMesh m = load_mesh(d.file(levels[k].file));
        CHECK(levels[k].vertices == m.vertex_count());
        CHECK(levels[k].triangles == m.triangle_count());
      }
      CHECK(levels[1].triangles < levels[0].triangles);
      CHECK(levels[2].triangles < levels[1].triangles);
      // lod-select reads the description: with FOV 90 over 1000 pixels a pixel spans
      // R = 2 D / 1000; at D = 150 C the level of cell 2C is too coarse for 5 R = 1.5 C,
      // the level of cell C (level 1) is not.
      const CliResult pick = run_cli("lod-select " + q(d.file("l.lods.json")) + " --distance " +
                                     exact(150 * levels[1].cell) + " --fov 90 --height 1000 --json");
      REQUIRE(pick.exit_code == 0);
      CHECK_THAT(pick.out, Catch::Contains("\"level\":1,"));
      CHECK_THAT(pick.out, Catch::Contains("\"file\":\"l.lod1.ply\""));
    }
}

TEST_CASE("levels of detail with thick edges, a target and --measure", "[lods]") {
  ScratchDir d;
  GenerateOptions g;
  g.shape = SyntheticShape::branches;
  g.triangles = 50000;
  generate_mesh(d.file("tree.ply"), g);
  REQUIRE(run_cli("simplify --quiet " + q(d.file("tree.ply")) + " -o " + q(d.file("t.ply")) +
                  " --cell 0.02 --lods 2 --thick-edges --measure")
              .exit_code == 0);
  const std::vector<LodLevel> levels = read_lod_levels(d.file("t.lods.json"));
  REQUIRE(levels.size() == 2);
  for (const LodLevel& l : levels) {
    const LoadedMesh m = load_mesh(d.file(l.file));
    CHECK(l.edges == m.edges.size());
    CHECK(l.points == m.points.size());
    CHECK(l.edges > 0);
  }
  // Measured into the description.
  const std::string json = read_file(d.file("t.lods.json"));
  CHECK(json.find("\"rms\"") != std::string::npos);
  CHECK(json.find("\"hausdorff\"") != std::string::npos);

  // With a target, each level halves it; the collapse meets it exactly.
  GenerateOptions sphere;
  sphere.triangles = 100000;
  generate_mesh(d.file("sphere.ply"), sphere);
  CHECK(level_triangles(d.file("sphere.ply"), d.file("s.ply"), "--target-tris 8000 --lods 3 --measure") ==
        std::vector<std::uint64_t>{8000, 4000, 2000});
}

TEST_CASE("levels to a target go on from the finer level's collapse, as good as their own runs", "[lods][target]") {
  ScratchDir d;
  GenerateOptions g;
  g.triangles = OOCSIMP_TEST_UNDER_ASAN ? 20000 : 100000;
  generate_mesh(d.file("sphere.ply"), g);
  const std::string in = q(d.file("sphere.ply"));
  for (const char* threads : {"1", "2"})
    REQUIRE(run_cli("simplify --quiet " + in + " -o " + q(d.file(std::string("t") + threads + ".ply")) +
                    " --method qem --target-tris 4000 --lods 3 --threads " + threads)
                .exit_code == 0);
  MeasureOptions mo;
  mo.samples = 100000;
  for (std::uint32_t k = 0; k < 3; ++k) {
    INFO("level " << k);
    const std::string level = d.file("t1.lod" + std::to_string(k) + ".ply");
    CHECK(read_file(level) == read_file(d.file("t2.lod" + std::to_string(k) + ".ply")));
    const LoadedMesh m = load_mesh(level);
    const std::uint64_t target = 4000 >> k;
    CHECK(m.triangles.size() / 3 == target);
    const Topology t = topology(m.positions, std::vector<std::uint32_t>(m.triangles.begin(), m.triangles.end()));
    CHECK(t.manifold);
    CHECK(t.boundary_edges == 0);
    CHECK(t.euler() == 2);
    // Against the run to the level's count on its own: level 0 is that run; the
    // others come within a tenth of its RMS distance to the input.
    const std::string own = d.file("own" + std::to_string(k) + ".ply");
    REQUIRE(
        run_cli("simplify --quiet " + in + " -o " + q(own) + " --target-tris " + std::to_string(target)).exit_code ==
        0);
    if (k == 0) CHECK(read_file(level) == read_file(own));
    const double chained = measure_surface_distance(d.file("sphere.ply"), level, mo).symmetric.rms;
    const double alone = measure_surface_distance(d.file("sphere.ply"), own, mo).symmetric.rms;
    CHECK(chained <= 1.1 * alone);
  }
}

TEST_CASE("levels to a target: ratios of fanned polygons, and a level a floating phase 1 leaves short",
          "[lods][target]") {
  ScratchDir d;
  // 60 x 80 quads: 9600 triangles once fanned. Each level's ratio counts those.
  std::string obj;
  for (int y = 0; y <= 80; ++y)
    for (int x = 0; x <= 60; ++x) obj += "v " + std::to_string(x) + " " + std::to_string(y) + " 0\n";
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 60; ++x) {
      const int a = y * 61 + x + 1;
      obj += "f " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + 62) + " " +
             std::to_string(a + 61) + "\n";
    }
  write_file(d.file("quads.obj"), obj);
  CHECK(level_triangles(d.file("quads.obj"), d.file("r.ply"), "--target-ratio 0.25 --lods 3") ==
        std::vector<std::uint64_t>{2400, 1200, 600});

  // Floating cells at a cell for the first target leave the coarser parts' levels
  // stuck short of their counts; those levels run on their own and meet them.
  GenerateOptions g;
  g.shape = SyntheticShape::parts;
  g.triangles = 100000;
  generate_mesh(d.file("parts.ply"), g);
  const CliResult run = run_cli("simplify " + q(d.file("parts.ply")) + " -o " + q(d.file("p.ply")) +
                                " --method floating --target-tris 6400 --lods 4");
  REQUIRE(run.exit_code == 0);
  const std::vector<LodLevel> p = read_lod_levels(d.file("p.lods.json"));
  REQUIRE(p.size() == 4);
  for (std::size_t k = 0; k < 4; ++k) CHECK(p[k].triangles == std::uint64_t(6400 >> k));
  CHECK(run.err.find("was not met") == std::string::npos);
}

TEST_CASE("bad simplify --lods requests exit 2 before writing anything", "[lods][cli]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 8);
  const std::string in = q(d.file("cube.ply"));
  for (const std::string& args : std::vector<std::string>{
           " -o " + q(d.file("o.ply")) + " --lods 0", " -o " + q(d.file("o.ply")) + " --lods 17",
           " -o " + q(d.file("o.ply")) + " --lods 2 --lod-factor 1", " -o " + q(d.file("o.ply")) + " --lod-factor 2",
           " -o " + q(d.file("o.ply")) + " --measure", " -o - --lods 2",
           " -o " + q(d.file("o.ply")) + " --lods 2 --stats " + q(d.file("s.json")),
           " -o " + q(d.file("o.ply")) + " --lods 2 --method qem",
           " -o " + q(d.file("o.ply")) + " --lods 4 --target-tris 20",
           " -o " + q(d.file("o.ply")) + " --lods 2 --max-error 0.01"}) {
    INFO(args);
    const CliResult r = run_cli("simplify " + in + args);
    CHECK(r.exit_code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  }
  CHECK(d.entries() == std::vector<std::string>{"cube.ply"});
  // A missing folder fails before the work, with nothing left behind.
  const CliResult missing = run_cli("simplify " + in + " -o " + q(d.file("none/o.ply")) + " --lods 2");
  CHECK(missing.exit_code == 4);
  CHECK(d.entries() == std::vector<std::string>{"cube.ply"});
}
