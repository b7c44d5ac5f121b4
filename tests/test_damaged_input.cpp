// End-to-end tests of damaged and unusual geometry through the CLI, with both
// clustering methods: NaN and infinite coordinates, repeated indices, short faces,
// zero-area and duplicate faces, a non-manifold fan, a point-sized bounding box, a
// single triangle and empty meshes. Each gives a correct result (exit 0, and what is
// left out counted in --stats and in one warning line) or a one-line exit-3 error.
#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "oocsimp/error.hpp"
#include "test_support.hpp"

using namespace oocsimp_test;
using Catch::Matchers::Contains;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

const char* const kMethods[] = {"uniform", "floating"};

// Binary little-endian PLY with polygons of any size (0, 1, 2 corners included).
void write_polygon_ply(const std::string& path, const std::vector<float>& v,
                       const std::vector<std::vector<int>>& faces) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(v.size() / 3) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(faces.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (float f : v) put_le(s, f);
  for (const auto& f : faces) {
    s.push_back(char(f.size()));
    for (int i : f) put_le(s, std::int32_t(i));
  }
  write_file(path, s);
}

// An n x n grid of quads (two triangles each) on the unit square, slightly bent so
// that quadrics have some curvature to work with.
struct Grid {
  std::vector<float> v;
  std::vector<std::vector<int>> faces;
};
Grid grid_mesh(int n) {
  Grid g;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = double(i) / n, y = double(j) / n;
      g.v.insert(g.v.end(), {float(x), float(y), float(0.2 * x * x - 0.1 * y)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      g.faces.push_back({a, b, d});
      g.faces.push_back({a, d, c});
    }
  return g;
}

struct Run {
  CliResult cli;
  std::string stats;  // the --stats JSON
  LoadedMesh output;
};

Run simplify(const ScratchDir& d, const std::string& input, const std::string& method, const std::string& args) {
  Run r;
  std::string out = d.file("out-" + method + ".ply"), stats = d.file("stats-" + method + ".json");
  std::remove(out.c_str());
  r.cli = run_cli("simplify --quiet " + q(input) + " -o " + q(out) + " --method " + method + " " + args + " --tmp " +
                  q(d.path()) + " --stats " + q(stats));
  if (r.cli.exit_code == 0) {
    r.stats = read_file(stats);
    r.output = load_mesh(out);
  }
  return r;
}

std::size_t lines(const std::string& s) { return std::size_t(std::count(s.begin(), s.end(), '\n')); }

std::string field(const char* name, std::uint64_t value) {
  return std::string("\"") + name + "\": " + std::to_string(value);
}

// What every output must be: indices in range, three distinct vertices per triangle,
// each unordered triple once, finite positions.
void check_valid_output(const LoadedMesh& m) {
  std::set<std::array<std::uint64_t, 3>> seen;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    std::array<std::uint64_t, 3> k = {m.triangles[3 * t], m.triangles[3 * t + 1], m.triangles[3 * t + 2]};
    for (std::uint64_t i : k) REQUIRE(i < m.vertex_count());
    CHECK(k[0] != k[1]);
    CHECK(k[1] != k[2]);
    CHECK(k[0] != k[2]);
    std::sort(k.begin(), k.end());
    CHECK(seen.insert(k).second);
  }
  for (double c : m.positions) CHECK(std::isfinite(c));
}

}  // namespace

TEST_CASE(
    "damaged faces are skipped, counted in --stats and in one warning line, the rest simplifies as if they were absent",
    "[cli][damaged]") {
  ScratchDir d;
  Grid clean = grid_mesh(24);
  write_polygon_ply(d.file("clean.ply"), clean.v, clean.faces);

  // The same mesh plus two vertices with a NaN and an infinite coordinate and faces
  // that no clusterer can use.
  Grid damaged = clean;
  const int nan_vertex = int(damaged.v.size() / 3);
  damaged.v.insert(damaged.v.end(), {std::numeric_limits<float>::quiet_NaN(), 0.5f, 0.5f, 0.5f,
                                     std::numeric_limits<float>::infinity(), 0.5f});
  const int inf_vertex = nan_vertex + 1;
  damaged.faces.insert(damaged.faces.begin() + 5, std::vector<int>{0, nan_vertex, 1});  // a NaN corner
  damaged.faces.push_back({2, 3, inf_vertex, 30});  // a quad: both fan triangles have the infinite corner
  damaged.faces.push_back({4, 4, 30});              // a repeated index
  damaged.faces.push_back({5, 6, 6, 6});            // both fan triangles repeat vertex 6
  damaged.faces.push_back({7, 8});                  // faces with fewer than 3 corners
  damaged.faces.push_back({9});
  damaged.faces.push_back({});
  write_polygon_ply(d.file("damaged.ply"), damaged.v, damaged.faces);
  // A converted (ascii) copy of the damaged file: the same policy applies there.
  std::string ascii = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(damaged.v.size() / 3) +
                      "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                      std::to_string(damaged.faces.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < damaged.v.size(); i += 3) {
    char line[128];
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", double(damaged.v[i]), double(damaged.v[i + 1]),
                  double(damaged.v[i + 2]));
    ascii += line;
  }
  for (const auto& f : damaged.faces) {
    ascii += std::to_string(f.size());
    for (int i : f) ascii += " " + std::to_string(i);
    ascii += "\n";
  }
  write_file(d.file("damaged-ascii.ply"), ascii);
  // Vertex nan_vertex starts at this byte in the binary file and on this line in the ascii one.
  const std::size_t header = read_file(d.file("damaged.ply")).find("end_header\n") + 11;
  const std::string binary_position = "byte " + std::to_string(header + 12 * std::size_t(nan_vertex));
  const std::string ascii_position = "line " + std::to_string(10 + nan_vertex);

  for (const char* method : kMethods) {
    for (const char* args : {"--grid 12", "--cell 0.09"}) {
      CAPTURE(method, args);
      Run ref = simplify(d, d.file("clean.ply"), method, args);
      REQUIRE(ref.cli.exit_code == 0);
      CHECK(ref.cli.err.empty());
      CHECK(ref.output.triangle_count() > 50);
      std::string ref_bytes = read_file(d.file(std::string("out-") + method + ".ply"));
      for (const auto& input : {std::make_pair(d.file("damaged.ply"), binary_position),
                                std::make_pair(d.file("damaged-ascii.ply"), ascii_position)}) {
        CAPTURE(input.first);
        Run r = simplify(d, input.first, method, args);
        INFO(r.cli.err);
        REQUIRE(r.cli.exit_code == 0);
        // The dropped faces never reach the clusterer, the NaN vertices never reach
        // the box or the grid: the output is the clean mesh's, byte for byte.
        CHECK(read_file(d.file(std::string("out-") + method + ".ply")) == ref_bytes);
        CHECK_THAT(r.stats, Contains(field("faces", 9)));
        CHECK_THAT(r.stats, Contains(field("non_finite_triangles", 3)));
        CHECK_THAT(r.stats, Contains(field("repeated_index_triangles", 3)));
        CHECK_THAT(r.stats, Contains(field("short_faces", 3)));
        CHECK_THAT(r.stats, Contains(field("non_finite_vertices", 2)));
        CHECK_THAT(r.stats, Contains(field("triangles", clean.faces.size())));
        // One warning line (not silenced by --quiet) with every count and the first
        // non-finite vertex and where it is.
        CHECK(lines(r.cli.err) == 1);
        CHECK_THAT(r.cli.err, Contains("warning"));
        CHECK_THAT(r.cli.err, Contains(input.first));
        CHECK_THAT(r.cli.err, Contains("skipped 9 faces"));
        CHECK_THAT(r.cli.err, Contains("3 triangles with a NaN or infinite corner"));
        CHECK_THAT(r.cli.err, Contains("3 triangles naming one vertex twice"));
        CHECK_THAT(r.cli.err, Contains("3 faces with fewer than 3 corners"));
        CHECK_THAT(r.cli.err, Contains("ignored 2 vertices"));
        CHECK_THAT(r.cli.err, Contains("vertex " + std::to_string(nan_vertex) + " at " + input.second));
      }
    }
  }
}

TEST_CASE("floating --keep-tmp: a run on kept tiles reports the same skipped counts", "[cli][damaged]") {
  // The resumed run does not read the faces again: the counts come from the manifest.
  ScratchDir d;
  Grid g = grid_mesh(16);
  g.v.insert(g.v.end(), {0.5f, std::numeric_limits<float>::quiet_NaN(), 0.5f});
  const int nan_vertex = int(g.v.size() / 3) - 1;
  g.faces.push_back({0, 1, nan_vertex});
  g.faces.push_back({3, 3, 4});
  g.faces.push_back({5, 6});
  write_polygon_ply(d.file("damaged.ply"), g.v, g.faces);
  std::string skipped =
      "\"skipped\": {\"faces\": 3, \"short_faces\": 1, \"non_finite_triangles\": 1, "
      "\"repeated_index_triangles\": 1, \"non_finite_vertices\": 1}";
  for (const char* cell : {"0.1", "0.2"}) {  // the second run reuses the first one's tiles
    CAPTURE(cell);
    Run r = simplify(d, d.file("damaged.ply"), "floating", std::string("--keep-tmp --cell ") + cell);
    INFO(r.cli.err);
    REQUIRE(r.cli.exit_code == 0);
    CHECK_THAT(r.stats, Contains(skipped));
    CHECK_THAT(r.cli.err, Contains("skipped 3 faces"));
    CHECK_THAT(r.stats, Contains(std::string("\"resumed\": ") + (std::string(cell) == "0.1" ? "false" : "true")));
  }
}

TEST_CASE("a file whose every vertex is NaN gives an empty output and the warning", "[cli][damaged]") {
  ScratchDir d;
  write_file(d.file("nan.obj"), "v nan 0 0\nv 0 nan 0\nv 0 0 nan\nf 1 2 3\n");
  for (const char* method : kMethods) {
    CAPTURE(method);
    Run r = simplify(d, d.file("nan.obj"), method, "--grid 8");
    INFO(r.cli.err);
    REQUIRE(r.cli.exit_code == 0);
    CHECK(r.output.triangle_count() == 0);
    CHECK(r.output.vertex_count() == 0);
    CHECK_THAT(r.stats, Contains(field("non_finite_triangles", 1)));
    CHECK(lines(r.cli.err) == 1);
    CHECK_THAT(r.cli.err, Contains("vertex 0 at line 1"));
  }
}

TEST_CASE("duplicate faces (either orientation) give the same simplification as the faces once", "[cli][damaged]") {
  ScratchDir d;
  Grid once = grid_mesh(20);
  Grid twice = once;
  for (const auto& f : once.faces) twice.faces.push_back({f[2], f[1], f[0]});
  for (const auto& f : once.faces) twice.faces.push_back(f);
  write_polygon_ply(d.file("once.ply"), once.v, once.faces);
  write_polygon_ply(d.file("twice.ply"), twice.v, twice.faces);
  for (const char* method : kMethods) {
    CAPTURE(method);
    Run a = simplify(d, d.file("once.ply"), method, "--grid 10");
    Run b = simplify(d, d.file("twice.ply"), method, "--grid 10");
    REQUIRE(a.cli.exit_code == 0);
    REQUIRE(b.cli.exit_code == 0);
    CHECK(b.cli.err.empty());  // duplicates are not damage: nothing is skipped
    check_valid_output(b.output);
    // Each cell triple once: the same triangles (up to orientation, which follows
    // the first occurrence in file order), nearly the same positions (the quadrics
    // are summed in another order).
    REQUIRE(b.output.triangle_count() == a.output.triangle_count());
    REQUIRE(b.output.vertex_count() == a.output.vertex_count());
    for (std::size_t i = 0; i < a.output.positions.size(); ++i)
      CHECK(b.output.positions[i] == Approx(a.output.positions[i]).margin(1e-5));
  }
}

TEST_CASE("a non-manifold fan (pages sharing one edge, a bow tie) simplifies to a valid mesh", "[cli][damaged]") {
  ScratchDir d;
  // Three pages around the z axis share the spine vertices 0..n; two more fans meet
  // the first page at its far corner only.
  const int n = 16;
  std::vector<float> v;
  std::vector<std::vector<int>> faces;
  for (int k = 0; k <= n; ++k) v.insert(v.end(), {0.0f, 0.0f, float(k) / n});
  for (int page = 0; page < 3; ++page) {
    double a = 2.0943951023931953 * page;  // 120 degrees apart
    int base = int(v.size() / 3);
    for (int j = 1; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        double r = double(j) / n;
        v.insert(v.end(), {float(r * std::cos(a)), float(r * std::sin(a)), float(k) / n});
      }
    auto id = [&](int j, int k) { return j == 0 ? k : base + (j - 1) * (n + 1) + k; };
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        faces.push_back({id(j, k), id(j + 1, k), id(j + 1, k + 1)});
        faces.push_back({id(j, k), id(j + 1, k + 1), id(j, k + 1)});
      }
  }
  write_polygon_ply(d.file("book.ply"), v, faces);
  for (const char* method : kMethods) {
    CAPTURE(method);
    Run r = simplify(d, d.file("book.ply"), method, "--grid 8");
    INFO(r.cli.err);
    REQUIRE(r.cli.exit_code == 0);
    check_valid_output(r.output);
    CHECK(r.output.triangle_count() >= 3 * 8);  // every page keeps a strip of triangles at least
    // Representatives stay within a cell of the input.
    double cell = 2.0 / 8;
    for (std::size_t i = 0; i < r.output.positions.size(); i += 3) {
      CHECK(std::hypot(r.output.positions[i], r.output.positions[i + 1]) <= 1 + cell);
      CHECK(r.output.positions[i + 2] >= -cell);
      CHECK(r.output.positions[i + 2] <= 1 + cell);
    }
  }
}

TEST_CASE("all vertices at one point (a bounding box of size zero) give an empty output", "[cli][damaged]") {
  ScratchDir d;
  Grid g = grid_mesh(6);
  for (std::size_t i = 0; i < g.v.size(); i += 3) {
    g.v[i] = 1.0f;
    g.v[i + 1] = 2.0f;
    g.v[i + 2] = 3.0f;
  }
  write_polygon_ply(d.file("point.ply"), g.v, g.faces);
  for (const char* method : kMethods)
    for (const char* args : {"--grid 64", "--cell 0.5", "--ratio 0.5"}) {
      CAPTURE(method, args);
      Run r = simplify(d, d.file("point.ply"), method, args);
      INFO(r.cli.err);
      REQUIRE(r.cli.exit_code == 0);
      CHECK(r.cli.err.empty());  // the faces are zero-area, not damaged: nothing skipped
      CHECK(r.output.triangle_count() == 0);
      CHECK_THAT(r.stats, Contains(field("triangles", g.faces.size())));
    }
}

TEST_CASE("a single triangle comes out as itself", "[cli][damaged]") {
  ScratchDir d;
  const std::vector<float> v = {0.25f, -1.0f, 3.0f, 2.0f, 0.5f, 3.5f, -0.75f, 1.25f, 2.0f};
  write_polygon_ply(d.file("one.ply"), v, {{0, 1, 2}});
  for (const char* method : kMethods) {
    CAPTURE(method);
    Run r = simplify(d, d.file("one.ply"), method, "--grid 16");
    INFO(r.cli.err);
    REQUIRE(r.cli.exit_code == 0);
    REQUIRE(r.output.triangle_count() == 1);
    REQUIRE(r.output.vertex_count() == 3);
    CHECK(r.output.triangles == std::vector<std::uint64_t>{0, 1, 2});  // orientation kept
    for (std::size_t i = 0; i < v.size(); ++i) CHECK(r.output.positions[i] == Approx(v[i]).margin(1e-5));
  }
}

TEST_CASE("empty meshes give an empty output, a file too short to have a header or not OBJ at all exits 3",
          "[cli][damaged]") {
  ScratchDir d;
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 0\nproperty list uchar int vertex_indices\n";
  write_file(d.file("nothing.ply"), "ply\nformat ascii 1.0\nelement vertex 0\n" + xyz + face + "end_header\n");
  write_file(d.file("no-faces.ply"),
             "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + face + "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  write_file(d.file("no-face-element.ply"), "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz + "end_header\n0 0 0\n");
  write_file(d.file("no-faces.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  write_file(d.file("empty.stl"), "solid empty\nendsolid empty\n");
  write_file(d.file("nothing.off"), "OFF\n0 0 0\n");
  for (const char* name :
       {"nothing.ply", "no-faces.ply", "no-face-element.ply", "no-faces.obj", "empty.stl", "nothing.off"})
    for (const char* method : kMethods) {
      CAPTURE(name, method);
      Run r = simplify(d, d.file(name), method, "--grid 8");
      INFO(r.cli.err);
      REQUIRE(r.cli.exit_code == 0);
      CHECK(r.output.triangle_count() == 0);
      CHECK(r.output.vertex_count() == 0);
      CHECK_THAT(r.stats, Contains("\"output\": {\"vertices\": 0, \"triangles\": 0, \"edges\": 0, \"points\": 0}"));
    }
  // Text that is not OBJ at all, or an OBJ with nothing in it, is no empty mesh: exit
  // 3 naming the line. (PLY, STL and OFF that declare no vertices are empty meshes.)
  write_file(d.file("text.obj"), "hello\n");
  write_file(d.file("zero-bytes.obj"), "");
  write_file(d.file("names-only.obj"), "# exported\nmtllib a.mtl\no empty\n");
  for (const auto& [name, message] : {std::pair<const char*, const char*>{"text.obj", ": line 1: not an OBJ file"},
                                      {"zero-bytes.obj", ": line 0: no vertices or faces found"},
                                      {"names-only.obj", ": line 3: no vertices or faces found"}})
    for (const char* method : kMethods) {
      CAPTURE(name, method);
      Run r = simplify(d, d.file(name), method, "--grid 8");
      CHECK(r.cli.exit_code == 3);
      CHECK(lines(r.cli.err) == 1);
      CHECK_THAT(r.cli.err, Contains(d.file(name) + message));
      CHECK_FALSE(file_exists(d.file(std::string("out-") + method + ".ply")));
    }
  for (const char* name : {"zero-bytes.ply", "zero-bytes.stl"}) {
    CAPTURE(name);
    write_file(d.file(name), "");
    for (const char* method : kMethods) {
      Run r = simplify(d, d.file(name), method, "--grid 8");
      CHECK(r.cli.exit_code == 3);
      CHECK(lines(r.cli.err) == 1);
      CHECK_THAT(r.cli.err, Contains(d.file(name)));
      CHECK_FALSE(file_exists(d.file(std::string("out-") + method + ".ply")));
    }
  }
}

// ---------------------------------------------------------------------------------
// Hostile text and streams (damaged or malicious input must fail fast, with bounded
// memory and a readable message, and streams must read like files)

namespace {

// Runs `before` + the CLI with `args` + `after` in the shell (for pipes and redirected
// standard input, which run_cli does not offer).
CliResult run_cli_in_shell(const std::string& before, const std::string& args, const std::string& after) {
  ScratchDir d;
  std::string cmd = before + std::string(OOCSIMP_CLI) + " " + args + " " + after + " >'" + d.file("out") + "' 2>'" +
                    d.file("err") + "'";
  int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = read_file(d.file("out"));
  r.err = read_file(d.file("err"));
  return r;
}

// A virtual-memory cap for runs whose memory must stay bounded: far below what the
// unbounded line buffer reached, far above what a run needs. AddressSanitizer
// reserves terabytes of address space, so there the cap is left out.
std::string memory_cap() {
#if OOCSIMP_TEST_UNDER_ASAN
  return "true";
#else
  return "ulimit -v 400000";
#endif
}

// 1 GiB of zero bytes as a zstd file of 1024 frames of 1 MiB each, a few tens of KB.
void write_zero_bomb(const ScratchDir& d, const std::string& path) {
  write_zstd_file(d.file("frame.zst"), std::string(1 << 20, '\0'));
  std::string frame = read_file(d.file("frame.zst")), all;
  for (int i = 0; i < 1024; ++i) all += frame;
  write_file(path, all);
}

}  // namespace

TEST_CASE("a zstd bomb without newlines, a huge header comment and /dev/zero exit 3 fast with bounded memory",
          "[cli][damaged][text]") {
  ScratchDir d;
  std::string bomb = d.file("bomb.obj.zst");
  write_zero_bomb(d, bomb);
  CliResult r =
      run_cli("simplify --quiet " + q(bomb) + " -o " + q(d.file("out.ply")) + " --tmp " + q(d.path()), memory_cap());
  CHECK(r.exit_code == 3);
  CHECK(lines(r.err) == 1);
  CHECK_THAT(r.err, Contains(bomb + ": line 1: line longer than 64 KiB"));

  // A PLY header comment that decompresses to 1 GiB.
  write_zstd_file(d.file("head.zst"), "ply\nformat ascii 1.0\ncomment ");
  std::string header = read_file(d.file("head.zst"));
  write_zero_bomb(d, d.file("rest.zst"));
  write_file(d.file("comment.ply.zst"), header + read_file(d.file("rest.zst")));
  r = run_cli("info --quiet " + q(d.file("comment.ply.zst")), memory_cap());
  CHECK(r.exit_code == 3);
  CHECK(lines(r.err) == 1);
  CHECK_THAT(r.err, Contains(d.file("comment.ply.zst") + ": line 3: PLY header longer than 1 MiB"));

  // /dev/zero under an OBJ name, and as it is.
  REQUIRE(::symlink("/dev/zero", d.file("zero.obj").c_str()) == 0);
  r = run_cli("simplify --quiet " + q(d.file("zero.obj")) + " -o " + q(d.file("out.ply")) + " --tmp " + q(d.path()),
              memory_cap());
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Contains(d.file("zero.obj") + ": line 1: line longer than 64 KiB"));
  r = run_cli("info --quiet /dev/zero", memory_cap());
  CHECK(r.exit_code == 3);
  CHECK(lines(r.err) == 1);
  CHECK_FALSE(file_exists(d.file("out.ply")));
  for (const std::string& e : d.entries()) CHECK(e.rfind("oocsimp-", 0) != 0);  // no temporary file left
}

TEST_CASE("a NUL byte in a token is shown as \\x00 in the one-line message, which goes on past it", "[cli][damaged]") {
  ScratchDir d;
  write_file(d.file("nul.obj"), std::string("v 0 0 0\nv 1 0\0junk 0\n", 22));
  CliResult r = run_cli("info " + q(d.file("nul.obj")));
  CHECK(r.exit_code == 3);
  CHECK(lines(r.err) == 1);
  CHECK_THAT(r.err, Contains(d.file("nul.obj") + ": line 2: malformed vertex coordinate \"0\\x00junk\""));
}

TEST_CASE("'-' reads standard input, redirected from a file or piped, like the file itself", "[cli][damaged][stdin]") {
  ScratchDir d;
  Grid g = grid_mesh(24);
  write_polygon_ply(d.file("in.ply"), g.v, g.faces);
  std::string obj;
  for (std::size_t i = 0; i < g.v.size(); i += 3)
    obj += "v " + std::to_string(g.v[i]) + " " + std::to_string(g.v[i + 1]) + " " + std::to_string(g.v[i + 2]) + "\n";
  for (const auto& f : g.faces)
    obj += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "\n";
  write_file(d.file("in.obj"), obj);
  write_zstd_file(d.file("in.ply.zst"), read_file(d.file("in.ply")));
  for (const char* name : {"in.ply", "in.obj", "in.ply.zst"})
    for (const char* method : kMethods) {
      CAPTURE(name, method);
      std::string in = d.file(name),
                  tail = std::string(" --method ") + method + " --grid 8 --quiet --tmp " + q(d.path());
      REQUIRE(run_cli("simplify " + q(in) + " -o " + q(d.file("file.ply")) + tail).exit_code == 0);
      std::string expected = read_file(d.file("file.ply"));
      CliResult redirected = run_cli_in_shell("", "simplify - -o " + q(d.file("redirected.ply")) + tail, "<" + q(in));
      INFO(redirected.err);
      REQUIRE(redirected.exit_code == 0);
      CHECK(read_file(d.file("redirected.ply")) == expected);
      CliResult piped = run_cli_in_shell("cat " + q(in) + " | ", "simplify - -o " + q(d.file("piped.ply")) + tail, "");
      INFO(piped.err);
      REQUIRE(piped.exit_code == 0);
      CHECK(read_file(d.file("piped.ply")) == expected);
      for (const std::string& e : d.entries()) CHECK(e.rfind("oocsimp-input-", 0) != 0);
    }
  // A damaged stream names standard input.
  CliResult r =
      run_cli_in_shell("printf 'ply\\nformat ascii 1.0\\nelement vertex 1\\nproperty float q\\n' | ", "info -", "");
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Contains("stdin"));
}

TEST_CASE("a FIFO input is read once through a copy in --tmp: the face pass does not hang", "[cli][damaged][fifo]") {
  ScratchDir d;
  Grid g = grid_mesh(24);
  write_polygon_ply(d.file("in.ply"), g.v, g.faces);
  std::string ascii = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(g.v.size() / 3) +
                      "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                      std::to_string(g.faces.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < g.v.size(); i += 3)
    ascii += std::to_string(g.v[i]) + " " + std::to_string(g.v[i + 1]) + " " + std::to_string(g.v[i + 2]) + "\n";
  for (const auto& f : g.faces)
    ascii += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  write_file(d.file("ascii.ply"), ascii);
  for (const char* name : {"in.ply", "ascii.ply"})
    for (const char* method : kMethods) {
      CAPTURE(name, method);
      std::string tail = std::string(" --method ") + method + " --grid 8 --quiet --tmp " + q(d.path());
      REQUIRE(run_cli("simplify " + q(d.file(name)) + " -o " + q(d.file("file.ply")) + tail).exit_code == 0);
      std::string fifo = d.file(std::string("fifo-") + name);
      std::remove(fifo.c_str());
      REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
      CliResult r = run_cli_in_shell("cat " + q(d.file(name)) + " > " + q(fifo) + " & ",
                                     "simplify " + q(fifo) + " -o " + q(d.file("fifo.ply")) + tail, "");
      INFO(r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(read_file(d.file("fifo.ply")) == read_file(d.file("file.ply")));
    }
}
