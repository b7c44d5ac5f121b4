// Precision: georeferenced input keeps its precision through reading,
// clustering and writing, double input gives double output (--precision auto), and
// float input near the origin still gives float output.
#include <catch2/catch.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "io/text_scan.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/oocsimp.hpp"
#include "api/simplify.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

// A UTM-like offset, as georeferenced scans carry.
constexpr double kShift[3] = {4.5e5, 5.4e6, 200};

// A scan 0.27 units wide: the generator's terrain (unit square) scaled down, each
// coordinate rounded to a multiple of 2^-30. Such a coordinate plus kShift is exactly
// a double (2^23 > 5.4e6, and 23 + 30 bits fit in 53), and so is the difference of two
// of them: shifted and unshifted, the clustering sees the same relative geometry, so
// the two results may differ only by the rounding of their last addition.
LoadedMesh small_scan(const ScratchDir& d) {
  GenerateOptions g;
  g.shape = SyntheticShape::terrain;
  g.triangles = 20000;
  generate_mesh(d.file("terrain.ply"), g);
  LoadedMesh m = load_mesh(d.file("terrain.ply"), d.path());
  for (double& v : m.positions) v = std::ldexp(std::nearbyint(std::ldexp(v * 0.27, 30)), -30);
  return m;
}

std::vector<double> shifted(const std::vector<double>& pos, double sign) {
  std::vector<double> out(pos);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] += sign * kShift[i % 3];
  return out;
}

void write_double_ply(const std::string& path, const std::vector<double>& pos, const std::vector<std::uint64_t>& tri) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(pos.size() / 3) +
                  "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                  std::to_string(tri.size() / 3) + "\nproperty list uchar uint vertex_indices\nend_header\n";
  for (double v : pos) put_le(s, v);
  for (std::size_t i = 0; i < tri.size(); i += 3) {
    s.push_back(3);
    for (int k = 0; k < 3; ++k) put_le(s, std::uint32_t(tri[i + std::size_t(k)]));
  }
  write_file(path, s);
}

// %.17g: every double reads back exactly.
void write_obj(const std::string& path, const std::vector<double>& pos, const std::vector<std::uint64_t>& tri) {
  std::string s;
  char line[128];
  for (std::size_t i = 0; i < pos.size(); i += 3) {
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", pos[i], pos[i + 1], pos[i + 2]);
    s += line;
  }
  for (std::size_t i = 0; i < tri.size(); i += 3)
    s += "f " + std::to_string(tri[i] + 1) + " " + std::to_string(tri[i + 1] + 1) + " " +
         std::to_string(tri[i + 2] + 1) + "\n";
  write_file(path, s);
}

SimplifiedMesh simplify_path(const std::string& path, const ScratchDir& tmp, ClusterMethod method, double cell,
                             double tile = 0, unsigned threads = 0, Precision precision = Precision::automatic) {
  OpenOptions oo;
  oo.temp_dir = tmp.path();
  MeshInput in = open_mesh_input(path, oo);
  SimplifyOptions o;
  o.method = method;
  o.sizing.cell = cell;
  o.floating.tile_side = tile;
  o.threads = threads;
  o.temp_dir = tmp.path();
  o.memory_budget = 64u << 20;
  o.precision = precision;
  return simplify(in, o, nullptr);
}

// `got`, shifted back by kShift, is `want` within `tolerance` per coordinate, with the
// same triangles.
void check_same_after_shift_back(const SimplifiedMesh& got, const SimplifiedMesh& want, double tolerance) {
  REQUIRE(got.triangles == want.triangles);
  REQUIRE(got.positions.size() == want.positions.size());
  std::vector<double> back = shifted(got.positions, -1);
  double worst = 0;
  for (std::size_t i = 0; i < back.size(); ++i) worst = std::max(worst, std::abs(back[i] - want.positions[i]));
  INFO("largest difference " << worst);
  CHECK(worst <= tolerance);
}

}  // namespace

TEST_CASE("a scan shifted to UTM coordinates simplifies to the unshifted result, at double precision", "[precision]") {
  ScratchDir d;
  LoadedMesh scan = small_scan(d);
  write_double_ply(d.file("scan.ply"), scan.positions, scan.triangles);
  write_double_ply(d.file("utm.ply"), shifted(scan.positions, 1), scan.triangles);
  write_obj(d.file("utm.obj"), shifted(scan.positions, 1), scan.triangles);
  double diagonal = 0;
  {
    OpenOptions oo;
    oo.temp_dir = d.path();
    MeshInput in = open_mesh_input(d.file("scan.ply"), oo);
    diagonal = in.info.bounds.diagonal();
    CHECK(diagonal == Approx(0.27 * std::sqrt(2.0)).epsilon(0.3));  // the terrain's height adds a little
  }
  const double cell = 0.27 / 48;
  for (ClusterMethod method : {ClusterMethod::floating, ClusterMethod::uniform}) {
    CAPTURE(method_name(method));
    SimplifiedMesh want = simplify_path(d.file("scan.ply"), d, method, cell);
    CHECK(want.precision == ScalarType::f64);
    REQUIRE(want.triangles.size() / 3 > 500);
    for (const char* input : {"utm.ply", "utm.obj"}) {
      CAPTURE(input);
      SimplifiedMesh got = simplify_path(d.file(input), d, method, cell);
      CHECK(got.precision == ScalarType::f64);
      check_same_after_shift_back(got, want, 1e-6 * diagonal);
    }
    // Forced to float, the same run is off by up to half a float step at 5.4e6 (0.25):
    // the loss that georeferenced input suffers in float.
    SimplifiedMesh as_float = simplify_path(d.file("utm.ply"), d, method, cell, 0, 0, Precision::float32);
    CHECK(as_float.precision == ScalarType::f32);
    REQUIRE(as_float.triangles == want.triangles);
    std::vector<double> back = shifted(as_float.positions, -1);
    double worst = 0;
    for (std::size_t i = 0; i < back.size(); ++i) worst = std::max(worst, std::abs(back[i] - want.positions[i]));
    CHECK(worst > 1e-3 * diagonal);
  }
}

TEST_CASE("at UTM coordinates floating cells stay byte-identical for any tiling and thread count", "[precision]") {
  ScratchDir d;
  LoadedMesh scan = small_scan(d);
  write_obj(d.file("utm.obj"), shifted(scan.positions, 1), scan.triangles);
  const double cell = 0.27 / 48;
  SimplifiedMesh ref = simplify_path(d.file("utm.obj"), d, ClusterMethod::floating, cell, 0, 1);
  for (double tile : {4 * cell, 11 * cell})
    for (unsigned threads : {1u, 2u}) {
      CAPTURE(tile, threads);
      SimplifiedMesh got = simplify_path(d.file("utm.obj"), d, ClusterMethod::floating, cell, tile, threads);
      CHECK(got.triangles == ref.triangles);
      CHECK(got.positions == ref.positions);
    }
}

TEST_CASE("the CLI writes double output for a double input at UTM coordinates", "[precision][cli]") {
  ScratchDir d;
  LoadedMesh scan = small_scan(d);
  write_double_ply(d.file("scan.ply"), scan.positions, scan.triangles);
  write_double_ply(d.file("utm.ply"), shifted(scan.positions, 1), scan.triangles);
  const std::string cell = std::to_string(0.27 / 48);
  for (const char* method : {"floating", "uniform"}) {
    CAPTURE(method);
    for (const char* out : {"a.ply", "b.ply", "a.obj"}) {
      const std::string in = std::string(out) == "a.ply" ? "scan.ply" : "utm.ply";
      CliResult r = run_cli("simplify --quiet " + q(d.file(in)) + " -o " + q(d.file(out)) + " --cell " + cell +
                            " --method " + method + " --tmp " + q(d.path()));
      INFO(r.err);
      REQUIRE(r.exit_code == 0);
    }
    CHECK(read_file(d.file("b.ply")).find("property double x\nproperty double y\nproperty double z\n") !=
          std::string::npos);
    LoadedMesh a = load_mesh(d.file("a.ply"), d.path()), b = load_mesh(d.file("b.ply"), d.path()),
               o = load_mesh(d.file("a.obj"), d.path());
    CHECK(b.info.double_precision);
    CHECK(o.info.double_precision);
    CHECK(o.positions == b.positions);  // the OBJ text holds every digit
    REQUIRE(b.triangles == a.triangles);
    std::vector<double> back = shifted(b.positions, -1);
    for (std::size_t i = 0; i < back.size(); ++i) CHECK(std::abs(back[i] - a.positions[i]) <= 1e-6 * 0.4);
    // --precision float: float output, and the y coordinates fall on the float grid
    // at 5.4e6 (multiples of 0.5), the precision float has there.
    CliResult r = run_cli("simplify --quiet " + q(d.file("utm.ply")) + " -o " + q(d.file("f.ply")) + " --cell " + cell +
                          " --method " + method + " --precision float --tmp " + q(d.path()));
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    LoadedMesh f = load_mesh(d.file("f.ply"), d.path());
    CHECK_FALSE(f.info.double_precision);
    for (std::size_t i = 1; i < f.positions.size(); i += 3) CHECK(std::fmod(f.positions[i], 0.5) == 0);
  }
}

TEST_CASE("a float PLY input near the origin gives float output under auto, double when asked", "[precision][cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  for (const char* method : {"floating", "uniform"}) {
    CAPTURE(method);
    const std::string base =
        "simplify --quiet " + q(d.file("s.ply")) + " --grid 24 --method " + method + " --tmp " + q(d.path()) + " -o ";
    REQUIRE(run_cli(base + q(d.file("auto.ply"))).exit_code == 0);
    REQUIRE(run_cli(base + q(d.file("float.ply")) + " --precision float").exit_code == 0);
    REQUIRE(run_cli(base + q(d.file("double.ply")) + " --precision double").exit_code == 0);
    const std::string a = read_file(d.file("auto.ply"));
    CHECK(a.find("property float x\n") != std::string::npos);
    CHECK(a == read_file(d.file("float.ply")));
    LoadedMesh am = load_mesh(d.file("auto.ply"), d.path()), dm = load_mesh(d.file("double.ply"), d.path());
    CHECK_FALSE(am.info.double_precision);
    CHECK(dm.info.double_precision);
    // The double output is the float one before rounding.
    REQUIRE(dm.triangles == am.triangles);
    for (std::size_t i = 0; i < dm.positions.size(); ++i) CHECK(double(float(dm.positions[i])) == am.positions[i]);
  }
  CliResult bad = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("x.ply")) + " --precision half");
  CHECK(bad.exit_code == 2);
  CHECK_FALSE(file_exists(d.file("x.ply")));
}

TEST_CASE("converted positions keep what the file says: float while it fits, double from the first that does not",
          "[precision][readers]") {
  ScratchDir d;
  SECTION("OBJ text with no more than float precision stays float; more digits make it double") {
    // "1e-3" is no float, but the float nearest it prints back as 1e-3: the text says no more.
    write_file(d.file("m.obj"), "v 0 0.5 -2\nv 1 16777216 0.25\nv 3 1e-3 7\nf 1 2 3\n");
    LoadedMesh m = load_mesh(d.file("m.obj"), d.path());
    CHECK_FALSE(m.info.double_precision);
    CHECK(m.positions == std::vector<double>{0, 0.5, -2, 1, 16777216, 0.25, 3, double(1e-3f), 7});
    // A float written with %.9g reads back as that float.
    write_file(d.file("g.obj"), "v 0.100000001 0.200000003 0.300000012\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    LoadedMesh g = load_mesh(d.file("g.obj"), d.path());
    CHECK_FALSE(g.info.double_precision);
    CHECK(g.positions[0] == double(0.1f));
    // Ten significant digits, and an integer past 2^24: more than a float keeps.
    for (const char* v : {"v 3 0.1234567891 7", "v 3 16777217 7", "v 451234.567 0 0"}) {
      CAPTURE(v);
      write_file(d.file("x.obj"), std::string("v 0 0.5 -2\nv 1 16777216 0.25\n") + v + "\nf 1 2 3\n");
      LoadedMesh x = load_mesh(d.file("x.obj"), d.path());
      CHECK(x.info.double_precision);
      CHECK(x.positions[0] == 0);
      CHECK(x.positions[4] == 16777216);  // the vertices before the switch kept exactly
    }
  }
  SECTION("the switch to double after megabytes of floats keeps every earlier vertex") {
    std::string text;
    std::vector<double> want;
    for (int i = 0; i < 120000; ++i) {  // 1.4 MB of floats, more than the write buffer
      text += "v " + std::to_string(i) + ".25 -" + std::to_string(i) + ".5 " + std::to_string(1000000 + i) + "\n";
      want.insert(want.end(), {i + 0.25, -(i + 0.5), 1e6 + i});  // exact floats
    }
    text += "v 450000.001 5400000.002 200.003\nf 1 2 120001\n";
    want.insert(want.end(), {450000.001, 5400000.002, 200.003});
    write_file(d.file("long.obj"), text);
    LoadedMesh m = load_mesh(d.file("long.obj"), d.path());
    CHECK(m.info.double_precision);
    REQUIRE(m.positions.size() == want.size());
    CHECK(m.positions == want);
    CHECK(m.info.bounds.max.y == 5400000.002);
    CHECK(m.info.bounds.min.y == -119999.5);
    CHECK(m.info.bounds.max.x == 450000.001);
  }
  SECTION("an integer PLY property beyond 2^24 is kept exactly") {
    write_file(d.file("i.ply"),
               "ply\nformat ascii 1.0\nelement vertex 2\nproperty int x\nproperty int y\nproperty int z\n"
               "end_header\n16777217 0 1\n2 3 4\n");
    LoadedMesh m = load_mesh(d.file("i.ply"), d.path());
    CHECK(m.info.double_precision);
    CHECK(m.positions == std::vector<double>{16777217, 0, 1, 2, 3, 4});
  }
  SECTION("a PLY declaring double is double, read in place or converted") {
    const std::vector<double> pos = {0.5, 1, 2, 3, 4, 5, 6, 7, 8};  // exact floats all
    write_double_ply(d.file("d.ply"), pos, {0, 1, 2});
    write_zstd_file(d.file("d.ply.zst"), read_file(d.file("d.ply")));
    LoadedMesh a = load_mesh(d.file("d.ply"), d.path()), z = load_mesh(d.file("d.ply.zst"), d.path());
    CHECK(a.info.positions_in_place);
    CHECK_FALSE(z.info.positions_in_place);
    CHECK(a.info.double_precision);
    CHECK(z.info.double_precision);
    CHECK(a.positions == pos);
    CHECK(z.positions == pos);
  }
  SECTION("a PLY declaring float is float, also in ascii with more digits") {
    write_file(d.file("f.ply"),
               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
               "property float z\nend_header\n450000.123456 0.1 2\n");
    LoadedMesh m = load_mesh(d.file("f.ply"), d.path());
    CHECK_FALSE(m.info.double_precision);
    CHECK(m.positions == std::vector<double>{double(450000.123456f), double(0.1f), 2});
  }
  for (const std::string& e : d.entries()) CHECK(e.find("oocsimp-positions-") == std::string::npos);
}

TEST_CASE("the shortest text of any float carries no more than float precision, more digits do",
          "[precision][readers]") {
  std::mt19937 random(7);
  int checked = 0;
  while (checked < 200000) {
    const std::uint32_t bits = random();
    float f;
    std::memcpy(&f, &bits, sizeof f);
    if (!std::isfinite(f)) continue;
    ++checked;
    char text[64];
    const auto end = std::to_chars(text, text + sizeof text, f).ptr;
    const std::string_view token(text, std::size_t(end - text));
    double v = 0;
    REQUIRE(oocsimp::parse_double(token, &v));
    INFO(token);
    REQUIRE(oocsimp::decimal_fits_float(token, v));
    REQUIRE(float(v) == f);
  }
  // A double's shortest text, where it is no float, says more than a float keeps.
  for (double d : {451234.567, 0.1234567891, 16777217.0, 5400000.002, 1e-3 + 1e-12}) {
    char text[64];
    const auto end = std::to_chars(text, text + sizeof text, d).ptr;
    const std::string_view token(text, std::size_t(end - text));
    INFO(token);
    CHECK_FALSE(oocsimp::decimal_fits_float(token, d));
  }
}
