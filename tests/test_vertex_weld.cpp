// Vertex welding (src/io/vertex_weld.*): STL corners, and PLY/OBJ with --weld, become
// one vertex per distinct position. The expected meshes come from a reference weld
// written here with a std::map over the float positions.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "io/vertex_weld.hpp"
#include "test_support.hpp"

using namespace oocsimp_test;
using Catch::Matchers::Contains;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

struct IndexedMesh {
  std::vector<float> positions;
  std::vector<std::uint32_t> triangles;
};

// The reference weld: one vertex per distinct finite position in order of first
// occurrence (float comparison, so -0 == +0), a vertex of its own for every non-finite
// corner. Triangles keep their order and corners.
IndexedMesh reference_weld(const IndexedMesh& in) {
  IndexedMesh out;
  std::map<std::array<float, 3>, std::uint32_t> first;
  std::vector<std::uint32_t> to(in.positions.size() / 3);
  for (std::size_t i = 0; i < to.size(); ++i) {
    std::array<float, 3> p = {in.positions[3 * i], in.positions[3 * i + 1], in.positions[3 * i + 2]};
    std::uint32_t next = std::uint32_t(out.positions.size() / 3);
    bool finite = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
    if (finite) {
      auto it = first.emplace(p, next).first;
      to[i] = it->second;
    } else {
      to[i] = next;
    }
    if (to[i] == next) out.positions.insert(out.positions.end(), p.begin(), p.end());
  }
  for (std::uint32_t v : in.triangles) out.triangles.push_back(to[v]);
  return out;
}

// Every triangle with its own three corners, as STL stores it.
IndexedMesh corners_of(const IndexedMesh& in) {
  IndexedMesh out;
  for (std::uint32_t v : in.triangles) {
    out.triangles.push_back(std::uint32_t(out.positions.size() / 3));
    out.positions.insert(out.positions.end(), in.positions.begin() + 3 * v, in.positions.begin() + 3 * v + 3);
  }
  return out;
}

// An n x n grid on the unit square, its triangles in a shuffled order so that the
// corners of one position are spread over the whole file.
IndexedMesh shuffled_grid(int n, unsigned seed) {
  IndexedMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.positions.insert(m.positions.end(), {float(i) / float(n), float(j) / float(n), 0.0f});
  std::vector<std::array<std::uint32_t, 3>> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      std::uint32_t a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1), d = c + 1;
      tris.push_back({a, b, d});
      tris.push_back({a, d, c});
    }
  std::mt19937 rng(seed);
  std::shuffle(tris.begin(), tris.end(), rng);
  for (const auto& t : tris) m.triangles.insert(m.triangles.end(), t.begin(), t.end());
  return m;
}

IndexedMesh load_indexed(const std::string& path) {
  LoadedMesh l = load_mesh(path);
  IndexedMesh m;
  for (double c : l.positions) m.positions.push_back(float(c));
  for (std::uint64_t v : l.triangles) m.triangles.push_back(std::uint32_t(v));
  return m;
}

struct Opened {
  std::vector<double> positions;
  std::vector<std::uint64_t> triangles;
  oocsimp::MeshInfo info;
  oocsimp::PositionArray array;
  oocsimp::SkippedFaces skipped;
};

Opened read_all(oocsimp::MeshInput& in) {
  Opened r;
  r.info = in.info;
  r.array = in.positions;
  for (std::uint64_t i = 0; i < in.positions.count; ++i) {
    oocsimp::Vec3d p = in.positions.get(i);
    r.positions.insert(r.positions.end(), {p.x, p.y, p.z});
  }
  std::vector<std::uint64_t> buf(3 * 100);
  while (std::size_t n = in.triangles->read(buf.data(), 100))
    r.triangles.insert(r.triangles.end(), buf.begin(), buf.begin() + 3 * n);
  r.skipped = in.triangles->skipped();
  return r;
}

Opened open_welded(const std::string& path, const std::string& temp_dir, std::uint64_t budget, bool weld = true) {
  oocsimp::OpenOptions o;
  o.temp_dir = temp_dir;
  o.weld = weld;
  o.memory_budget = budget;
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
  return read_all(in);
}

std::vector<double> as_doubles(const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); }
std::vector<std::uint64_t> as_u64(const std::vector<std::uint32_t>& v) {
  return std::vector<std::uint64_t>(v.begin(), v.end());
}

void write_obj(const std::string& path, const IndexedMesh& m) {
  std::string s;
  char line[128];
  for (std::size_t i = 0; i < m.positions.size(); i += 3) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", double(m.positions[i]), double(m.positions[i + 1]),
                  double(m.positions[i + 2]));
    s += line;
  }
  for (std::size_t i = 0; i < m.triangles.size(); i += 3)
    s += "f " + std::to_string(m.triangles[i] + 1) + " " + std::to_string(m.triangles[i + 1] + 1) + " " +
         std::to_string(m.triangles[i + 2] + 1) + "\n";
  write_file(path, s);
}

// Simplifies `in` to `out` with `args`; requires success.
void simplify(const std::string& in, const std::string& out, const std::string& args, const std::string& tmp) {
  CliResult r = run_cli("simplify --quiet " + q(in) + " -o " + q(out) + " --tmp " + q(tmp) + " " + args);
  INFO(in << ": " << r.err);
  REQUIRE(r.exit_code == 0);
}

}  // namespace

TEST_CASE("Welding gives one vertex per distinct position, numbered by first occurrence, for any budget", "[weld]") {
  ScratchDir d;
  IndexedMesh grid = shuffled_grid(60, 7);  // 21600 corners, 3721 positions
  write_binary_stl(d.file("grid.stl"), grid.positions, grid.triangles);
  IndexedMesh expected = reference_weld(corners_of(grid));
  REQUIRE(expected.positions.size() / 3 == 61 * 61);
  // 512 bytes: runs of 64 corners and merges of 6 runs, so three merge passes.
  std::uint64_t budget = GENERATE(std::uint64_t(512), std::uint64_t(4096), std::uint64_t(1) << 30);
  CAPTURE(budget);
  std::string tmp = d.file("tmp");
  REQUIRE(std::system(("mkdir " + q(tmp)).c_str()) == 0);
  {
    Opened m = open_welded(d.file("grid.stl"), tmp, budget);
    CHECK(m.info.vertex_count == 61 * 61);
    CHECK(m.info.unwelded_vertex_count == grid.triangles.size());
    CHECK(m.positions == as_doubles(expected.positions));
    CHECK(m.triangles == as_u64(expected.triangles));
    CHECK(m.skipped.total() == 0);
  }
  // The weld's files went with the input: the folder is empty.
  CHECK(std::system(("rmdir " + q(tmp)).c_str()) == 0);
}

TEST_CASE("Welding with 8-byte vertex numbers, as beyond 2^32 vertices, gives the same mesh", "[weld]") {
  ScratchDir d;
  IndexedMesh grid = shuffled_grid(30, 11);
  IndexedMesh expected = reference_weld(corners_of(grid));
  // Opened unwelded (as a PLY without --weld would be), then welded with the wide map.
  std::uint64_t budget = GENERATE(std::uint64_t(512), std::uint64_t(1) << 30);
  CAPTURE(budget);
  oocsimp::OpenOptions o;
  o.temp_dir = d.path();
  IndexedMesh corners = corners_of(grid);
  write_binary_ply(d.file("corners.ply"), corners.positions, corners.triangles);
  oocsimp::MeshInput in = oocsimp::open_mesh_input(d.file("corners.ply"), o);
  oocsimp::weld_vertices(in, d.path(), budget, true);
  in.restart_triangles();
  Opened m = read_all(in);
  CHECK(m.positions == as_doubles(expected.positions));
  CHECK(m.triangles == as_u64(expected.triangles));
}

TEST_CASE("Welding treats -0 as +0 and never welds a NaN or infinite vertex", "[weld]") {
  ScratchDir d;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  IndexedMesh corners;
  corners.positions = {0,     0, 0,     1, 0, 0, 0,   1, 0,   // triangle 0
                       -0.0f, 0, -0.0f, 0, 1, 0, 1,   0, 0,   // triangle 1: the same corners, one at -0
                       nan,   0, 0,     1, 0, 0, 0,   0, 1,   // triangle 2: a NaN corner
                       nan,   0, 0,     0, 0, 1, inf, 0, 0};  // triangle 3: the same NaN, and an infinity
  for (std::uint32_t i = 0; i < 12; ++i) corners.triangles.push_back(i);
  write_binary_stl(d.file("m.stl"), corners.positions, corners.triangles);
  Opened m = open_welded(d.file("m.stl"), d.path(), 1 << 20);
  // (0,0,0) (1,0,0) (0,1,0) NaN (0,0,1) NaN inf: the NaN vertices stay two.
  CHECK(m.info.vertex_count == 7);
  CHECK(m.info.unwelded_vertex_count == 12);
  CHECK(m.info.non_finite_vertices == 3);
  CHECK(m.info.first_non_finite_vertex == 3);  // the welded number: corner 6 of the file is vertex 3 now
  REQUIRE(m.positions.size() == 21);
  CHECK(std::signbit(m.positions[0]) == false);  // the first occurrence's coordinate
  CHECK(std::isnan(m.positions[9]));
  CHECK(std::isnan(m.positions[15]));
  CHECK(std::isinf(m.positions[18]));
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 0, 2, 1});
  CHECK(m.skipped.non_finite == 2);
  CHECK(m.skipped.repeated_index == 0);
}

TEST_CASE("A triangle whose corners weld together is dropped and counted", "[weld]") {
  ScratchDir d;
  IndexedMesh corners;
  corners.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1};
  corners.triangles = {0, 1, 2, 3, 4, 5};
  write_ascii_stl(d.file("m.stl"), corners.positions, corners.triangles);
  Opened m = open_welded(d.file("m.stl"), d.path(), 1 << 20);
  CHECK(m.info.vertex_count == 4);
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2});
  CHECK(m.skipped.repeated_index == 1);
  CliResult r =
      run_cli("simplify " + q(d.file("m.stl")) + " -o " + q(d.file("o.ply")) + " --grid 4 --tmp " + q(d.path()));
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.err, Contains("1 triangle with two corners at one position"));
}

TEST_CASE("Welding keeps double PLY positions at full precision, big-endian too", "[weld]") {
  ScratchDir d;
  const double v[] = {0.1, 0.2, 0.3, 1.0 / 3, 0, 0, 0, 2.0 / 3, 0, 0.1, 0.2, 0.3, 0, 0, 1e-300};
  std::string s =
      "ply\nformat binary_big_endian 1.0\nelement vertex 5\nproperty double x\nproperty double y\nproperty double z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (double c : v) put_be(s, c);
  const std::int32_t tris[2][3] = {{0, 1, 2}, {3, 2, 4}};
  for (const auto& t : tris) {
    s.push_back(3);
    for (std::int32_t i : t) put_be(s, i);
  }
  write_file(d.file("m.ply"), s);
  Opened m = open_welded(d.file("m.ply"), d.path(), 1 << 20);
  CHECK(m.array.type == oocsimp::ScalarType::f64);
  CHECK(m.info.vertex_count == 4);
  CHECK(m.positions == std::vector<double>{0.1, 0.2, 0.3, 1.0 / 3, 0, 0, 0, 2.0 / 3, 0, 0, 0, 1e-300});
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 0, 2, 3});
  // Without --weld nothing changes.
  Opened plain = open_welded(d.file("m.ply"), d.path(), 1 << 20, false);
  CHECK(plain.info.vertex_count == 5);
  CHECK(plain.info.unwelded_vertex_count == 0);
  CHECK(plain.triangles == std::vector<std::uint64_t>{0, 1, 2, 3, 2, 4});
}

TEST_CASE("One mesh as binary STL, ascii STL and PLY simplifies to byte-identical output", "[weld][cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("g.ply"))).exit_code == 0);
  IndexedMesh mesh = load_indexed(d.file("g.ply"));
  IndexedMesh corners = corners_of(mesh);
  IndexedMesh welded = reference_weld(corners);  // PLY vertices in first-occurrence order
  write_binary_ply(d.file("m.ply"), welded.positions, welded.triangles);
  write_binary_stl(d.file("b.stl"), mesh.positions, mesh.triangles);
  write_ascii_stl(d.file("a.stl"), mesh.positions, mesh.triangles);
  for (const char* method : {"floating", "uniform"}) {
    CAPTURE(method);
    std::string args = std::string("--grid 24 --method ") + method;
    simplify(d.file("m.ply"), d.file("m.out.ply"), args, d.path());
    simplify(d.file("b.stl"), d.file("b.out.ply"), args, d.path());
    simplify(d.file("a.stl"), d.file("a.out.ply"), args, d.path());
    std::string ply = read_file(d.file("m.out.ply"));
    CHECK(ply.size() > 1000);
    CHECK(read_file(d.file("b.out.ply")) == ply);
    CHECK(read_file(d.file("a.out.ply")) == ply);
  }
  // No temporary file was left behind.
  CHECK(d.entries() ==
        std::vector<std::string>{"a.out.ply", "a.stl", "b.out.ply", "b.stl", "g.ply", "m.out.ply", "m.ply"});
}

TEST_CASE("The same --ratio on STL keeps what it keeps on the same mesh as PLY", "[weld][cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 40000 --quiet -o " + q(d.file("g.ply"))).exit_code == 0);
  IndexedMesh mesh = load_indexed(d.file("g.ply"));
  write_binary_stl(d.file("m.stl"), mesh.positions, mesh.triangles);
  for (const char* ratio : {"0.02", "0.1", "0.3"}) {
    CAPTURE(ratio);
    simplify(d.file("g.ply"), d.file("p.ply"), std::string("--ratio ") + ratio, d.path());
    simplify(d.file("m.stl"), d.file("s.ply"), std::string("--ratio ") + ratio, d.path());
    std::size_t from_ply = load_mesh(d.file("p.ply")).triangle_count();
    std::size_t from_stl = load_mesh(d.file("s.ply")).triangle_count();
    CHECK(from_ply > 0);
    CHECK(double(from_stl) >= 0.9 * double(from_ply));
    CHECK(double(from_stl) <= 1.1 * double(from_ply));
  }
}

TEST_CASE("PLY and OBJ with duplicated vertices simplified with --weld equal the deduplicated PLY", "[weld][cli]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 12);  // each face has its own vertices along the edges
  IndexedMesh cube = load_indexed(d.file("cube.ply"));
  IndexedMesh dedup = reference_weld(cube);
  REQUIRE(dedup.positions.size() < cube.positions.size());
  write_binary_ply(d.file("dedup.ply"), dedup.positions, dedup.triangles);
  write_obj(d.file("cube.obj"), cube);
  for (const char* method : {"floating", "uniform"}) {
    CAPTURE(method);
    std::string args = std::string("--grid 5 --method ") + method;
    simplify(d.file("dedup.ply"), d.file("expected.ply"), args, d.path());
    simplify(d.file("cube.ply"), d.file("ply.ply"), args + " --weld", d.path());
    simplify(d.file("cube.obj"), d.file("obj.ply"), args + " --weld", d.path());
    std::string expected = read_file(d.file("expected.ply"));
    CHECK(expected.size() > 200);
    CHECK(read_file(d.file("ply.ply")) == expected);
    CHECK(read_file(d.file("obj.ply")) == expected);
  }
}

TEST_CASE("info reports the welded vertex count of an STL", "[weld][cli]") {
  ScratchDir d;
  IndexedMesh grid = shuffled_grid(4, 1);
  write_binary_stl(d.file("g.stl"), grid.positions, grid.triangles);
  CliResult r = run_cli("info " + q(d.file("g.stl")) + " --tmp " + q(d.path()));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.out, Contains("vertices  25 (welded from 96 stored)"));
  CHECK_THAT(r.out, Contains("faces     32"));
}

TEST_CASE("A --keep-tmp run does not resume the unwelded input's tiles for a --weld run", "[weld][cli]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 12);
  std::string tmp = d.file("tmp");
  REQUIRE(std::system(("mkdir " + q(tmp)).c_str()) == 0);
  simplify(d.file("cube.ply"), d.file("fresh.ply"), "--grid 5 --weld", tmp);
  simplify(d.file("cube.ply"), d.file("a.ply"), "--grid 5 --keep-tmp", tmp);
  CliResult r = run_cli("simplify " + q(d.file("cube.ply")) + " -o " + q(d.file("b.ply")) +
                        " --grid 5 --weld --keep-tmp --stats " + q(d.file("s.json")) + " --tmp " + q(tmp));
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(read_file(d.file("s.json")), Contains("\"resumed\": false"));
  CHECK(read_file(d.file("b.ply")) == read_file(d.file("fresh.ply")));
}

TEST_CASE("A --tmp that fills up while welding exits 4 naming the folder, nothing left behind", "[weld][cli]") {
  // A triangle soup: no two corners weld, so the sorted runs (20 bytes a corner) outgrow
  // the position array (12 bytes a corner), which the file-size limit still lets through.
  ScratchDir d;
  IndexedMesh soup;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coord(0, 1);
  for (std::uint32_t i = 0; i < 60000; ++i) {
    soup.positions.insert(soup.positions.end(), {coord(rng), coord(rng), coord(rng)});
    soup.triangles.push_back(i);
  }
  write_binary_stl(d.file("soup.stl"), soup.positions, soup.triangles);
  std::string tmp = d.file("tmp");
  REQUIRE(std::system(("mkdir " + q(tmp)).c_str()) == 0);
  CliResult r =
      run_cli("simplify --quiet " + q(d.file("soup.stl")) + " -o " + q(d.file("o.ply")) + " --grid 16 --tmp " + q(tmp),
              "ulimit -f 1800");  // 921 KB: the positions (720 KB) fit, the runs (1.2 MB) do not
  INFO(r.err);
  CHECK(r.exit_code == 4);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_THAT(r.err, Contains(tmp + ": cannot write the sorted runs for welding the vertices of " + d.file("soup.stl")));
  CHECK_THAT(r.err, Contains("File too large"));
  CHECK_FALSE(file_exists(d.file("o.ply")));
  CHECK(std::system(("rmdir " + q(tmp)).c_str()) == 0);  // empty
}
