// The out-of-core passes of the quadric edge collapse (methods/qem_passes,
// refine/pass_tile), on small meshes cut into many small tiles: the surface stays
// closed and manifold across the tiles' borders, the geometry stays on the shape, the
// attributes follow the positions, and the result is the same for any thread count
// and budget.
#include <catch2/catch.hpp>
#include <fcntl.h>
#include <sys/wait.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <thread>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "api/simplify.hpp"
#include "common/vec3_math.hpp"
#include "io/mesh_input.hpp"
#include "methods/qem_passes.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/generate.hpp"
#include "refine/edge_collapse.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

// Tiles of about 2000 faces: a mesh of tens of thousands of faces has dozens.
PassSizes small_tiles() {
  PassSizes s;
  s.tile_faces = 2000;
  s.from_faces = 0;
  return s;
}

std::string generated(const ScratchDir& d, SyntheticShape shape, std::uint64_t triangles, bool attributes) {
  GenerateOptions g;
  g.shape = shape;
  g.triangles = triangles;
  g.attributes = attributes;
  const std::string path = d.file("in.ply");
  generate_mesh(path, g);
  return path;
}

struct Reduced {
  QuadricMesh mesh;  // the exact count, positions in model units
  SimplifyStats stats;
};

// The passes, then the last collapse to `target` exactly, as --method qem runs them.
Reduced reduce(const std::string& path, std::uint64_t target, std::uint64_t budget = 0, bool attributes = false,
               std::uint64_t part_above = 0) {
  OpenOptions open;
  if (!attributes) open.attributes.mode = AttributeSelection::Mode::none;
  MeshInput input = open_mesh_input(path, open);
  SimplifyOptions options;
  options.memory_budget = budget;
  const Vec3d origin = input.info.bounds.min;
  Reduced r;
  PassSizes sizes = small_tiles();
  sizes.part_above = part_above;
  QuadricMesh rest = reduce_in_passes(input, plan_run(input, options), origin, target, &r.stats, sizes);
  CollapseSettings last;
  last.target_triangles = target;
  last.boundary_weight = 0;  // in the quadrics already
  r.mesh = collapse_edges(std::move(rest), last, nullptr);
  for (Vec3d& p : r.mesh.positions) p = p + origin;
  return r;
}

struct EdgeCounts {
  std::uint64_t edges = 0, boundary = 0, non_manifold = 0;
};
EdgeCounts count_edges(const QuadricMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> faces;
  for (std::size_t f = 0; f < m.triangles.size() / 3; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = m.triangles[3 * f + std::size_t(k)], w = m.triangles[3 * f + std::size_t(k + 1) % 3];
      ++faces[{std::min(u, w), std::max(u, w)}];
    }
  EdgeCounts c;
  c.edges = faces.size();
  for (const auto& e : faces) {
    c.boundary += e.second == 1;
    c.non_manifold += e.second > 2;
  }
  return c;
}

}  // namespace

TEST_CASE("the passes keep a closed sphere closed, manifold and of genus 0, on the sphere", "[qem_passes]") {
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::sphere, 60000, false);
  for (std::uint64_t target : {6000u, 1000u}) {
    const Reduced r = reduce(in, target);
    CHECK(r.stats.refine.passes >= 1);
    const QuadricMesh& m = r.mesh;
    REQUIRE(m.triangles.size() / 3 == target);
    const EdgeCounts e = count_edges(m);
    CHECK(e.boundary == 0);
    CHECK(e.non_manifold == 0);
    // Euler's formula for a closed surface of genus 0: V - E + F = 2.
    CHECK(std::int64_t(m.positions.size()) - std::int64_t(e.edges) + std::int64_t(target) == 2);
    // The generated sphere is the unit sphere displaced by eight sinusoids of
    // amplitudes 0.04 / (1 + i) (generator.cpp), less than 0.11 in all: every vertex
    // stays near that shell.
    for (const Vec3d& p : m.positions) {
      const double r2 = length(p);
      REQUIRE(r2 > 0.85);
      REQUIRE(r2 < 1.15);
    }
  }
}

TEST_CASE("the passes keep the parts' and the terrain's topology: no edge of three faces, the same Euler number",
          "[qem_passes]") {
  ScratchDir d;
  for (SyntheticShape shape : {SyntheticShape::parts, SyntheticShape::terrain}) {
    INFO(name_of(synthetic_shape_names(), shape));
    const std::string in = generated(d, shape, 40000, false);
    const LoadedMesh input = load_mesh(in);
    QuadricMesh before;
    before.positions.resize(input.vertex_count());
    for (std::uint64_t t : input.triangles) before.triangles.push_back(std::uint32_t(t));
    const EdgeCounts e0 = count_edges(before);
    REQUIRE(e0.non_manifold == 0);
    std::vector<char> used(input.vertex_count(), 0);
    for (std::uint64_t t : input.triangles) used[t] = 1;
    const std::int64_t v0 = std::count(used.begin(), used.end(), 1);
    const std::int64_t euler = v0 - std::int64_t(e0.edges) + std::int64_t(input.triangle_count());
    for (std::uint64_t target : {8000u, 3000u}) {
      INFO(target);
      const Reduced r = reduce(in, target);
      REQUIRE(r.mesh.triangles.size() / 3 == target);
      const EdgeCounts e = count_edges(r.mesh);
      CHECK(e.non_manifold == 0);
      CHECK(e.boundary <= e0.boundary);
      CHECK(std::int64_t(r.mesh.positions.size()) - std::int64_t(e.edges) + std::int64_t(target) == euler);
    }
  }
}

TEST_CASE("tiles worked on in parts keep the sphere closed and give the same mesh on any thread count",
          "[qem_passes]") {
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::sphere, 60000, false);
  Reduced one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = reduce(in, 3000, 0, false, 300);  // every tile in 8 or 64 parts
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = reduce(in, 3000, 0, false, 300);
  }
  const QuadricMesh& m = one.mesh;
  REQUIRE(m.triangles.size() / 3 == 3000);
  const EdgeCounts e = count_edges(m);
  CHECK(e.boundary == 0);
  CHECK(e.non_manifold == 0);
  CHECK(std::int64_t(m.positions.size()) - std::int64_t(e.edges) + 3000 == 2);
  CHECK(one.mesh.triangles == two.mesh.triangles);
  REQUIRE(one.mesh.positions.size() == two.mesh.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const Vec3d &a = one.mesh.positions[i], &b = two.mesh.positions[i];
    REQUIRE((a.x == b.x && a.y == b.y && a.z == b.z));
  }
}

TEST_CASE("the passes give the same mesh for any thread count and budget", "[qem_passes]") {
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::parts, 40000, false);
  Reduced one, two, small;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = reduce(in, 3000, std::uint64_t(1) << 30);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = reduce(in, 3000, std::uint64_t(1) << 30);
    small = reduce(in, 3000, std::uint64_t(48) << 20);
  }
  REQUIRE(one.mesh.triangles.size() / 3 == 3000);
  CHECK(one.mesh.triangles == two.mesh.triangles);
  CHECK(one.mesh.triangles == small.mesh.triangles);
  REQUIRE(one.mesh.positions.size() == two.mesh.positions.size());
  REQUIRE(one.mesh.positions.size() == small.mesh.positions.size());
  for (std::size_t i = 0; i < one.mesh.positions.size(); ++i) {
    const Vec3d &a = one.mesh.positions[i], &b = two.mesh.positions[i], &c = small.mesh.positions[i];
    REQUIRE((a.x == b.x && a.y == b.y && a.z == b.z));
    REQUIRE((a.x == c.x && a.y == c.y && a.z == c.z));
  }
}

TEST_CASE("the passes carry the attributes along the collapses", "[qem_passes]") {
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::sphere, 40000, true);
  const Reduced r = reduce(in, 4000, 0, true);
  const QuadricMesh& m = r.mesh;
  REQUIRE(m.attribute_count >= 3);
  // The generator's red is 255 (x - lo) / (hi - lo) over the input's box: linear in
  // position, so interpolating it along an edge keeps it near the function of the
  // vertex's new position (placements lie near the edge they collapse).
  const LoadedMesh input = load_mesh(in);
  const double lo = input.info.bounds.min.x, hi = input.info.bounds.max.x;
  double worst = 0;
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    const double red = m.attributes[v * m.attribute_count];
    worst = std::max(worst, std::fabs(red - 255 * (m.positions[v].x - lo) / (hi - lo)));
  }
  CHECK(worst < 12);
}

TEST_CASE("a budget that cannot hold a tile of the passes is refused up front, naming the one that can",
          "[qem_passes]") {
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::sphere, 20000, false);
  OpenOptions open;
  open.attributes.mode = AttributeSelection::Mode::none;
  MeshInput input = open_mesh_input(in, open);
  SimplifyOptions options;
  // The default pieces: 1.5 x 65536 face records at 448 bytes each, two of which the
  // tiles' half of the budget must hold: 2 x 1.5 x 65536 x 448 bytes = 84 MiB.
  options.memory_budget = std::uint64_t(80) << 20;
  SimplifyStats stats;
  try {
    reduce_in_passes(input, plan_run(input, options), input.info.bounds.min, 2000, &stats);
    FAIL("an 80 MiB budget was accepted");
  } catch (const UsageError& e) {
    const std::string message = e.what();
    CHECK(message.find("cannot hold a tile of the collapse in passes") != std::string::npos);
    CHECK(message.find("give options.memory_budget 84 MiB or more") != std::string::npos);
  }
  CHECK(stats.input_triangles == 0);  // refused before the input was binned
  options.memory_budget = std::uint64_t(84) << 20;
  MeshInput again = open_mesh_input(in, open);
  CHECK(reduce_in_passes(again, plan_run(again, options), again.info.bounds.min, 2000, &stats).triangles.size() > 0);
}

namespace {

// The boundary of a mesh (its edges of one face) as position pairs, each pair in
// ascending order, sorted: comparable between meshes numbered differently.
std::vector<std::array<double, 6>> boundary_edges(const LoadedMesh& m) {
  std::map<std::pair<std::uint64_t, std::uint64_t>, int> faces;
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = m.triangles[3 * t + std::size_t(k)], b = m.triangles[3 * t + std::size_t((k + 1) % 3)];
      ++faces[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<std::array<double, 6>> out;
  for (const auto& [edge, count] : faces) {
    if (count != 1) continue;
    std::array<double, 3> p, q;
    for (int k = 0; k < 3; ++k) {
      p[std::size_t(k)] = m.positions[3 * edge.first + std::size_t(k)];
      q[std::size_t(k)] = m.positions[3 * edge.second + std::size_t(k)];
    }
    if (q < p) std::swap(p, q);
    out.push_back({p[0], p[1], p[2], q[0], q[1], q[2]});
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("a locked boundary keeps its every vertex and edge, and locked vertices stay, whole and in passes",
          "[qem][locks]") {
  ScratchDir d;
  // 600k triangles collapse whole; 2M at --mem 128M in out-of-core passes (the whole
  // would not fit) before the last collapse.
  struct Case {
    std::uint64_t triangles;
    const char* mem;
    bool passes;
  };
  std::vector<Case> cases = {{600000, "1G", false}};
  if (!OOCSIMP_TEST_UNDER_ASAN) cases.push_back({2000000, "128M", true});
  for (const Case& c : cases) {
    CAPTURE(c.triangles);
    const std::string in = d.file("terrain-" + std::to_string(c.triangles) + ".ply");
    REQUIRE(run_cli("generate --quiet --shape terrain --tris " + std::to_string(c.triangles) + " -o '" + in + "'")
                .exit_code == 0);
    const auto before = boundary_edges(load_mesh(in));
    REQUIRE(before.size() > 1000);
    const std::string out = d.file("locked.ply"), stats = d.file("st.json");
    REQUIRE(run_cli("simplify --quiet '" + in + "' -o '" + out + "' --target-tris 6000 --lock-boundary --mem " + c.mem +
                    " --stats '" + stats + "'")
                .exit_code == 0);
    const LoadedMesh m = load_mesh(out);
    CHECK(m.triangle_count() == 6000);
    CHECK(boundary_edges(m) == before);
    CHECK((read_file(stats).find("\"passes\": 0,") == std::string::npos) == c.passes);
    // Chosen vertices, spread over the input, stay where they are too.
    const LoadedMesh input = load_mesh(in);
    std::string list = "# every 997th vertex\n";
    std::vector<std::array<double, 3>> pinned;
    for (std::size_t v = 5; v < input.vertex_count(); v += 997) {
      list += std::to_string(v) + (pinned.size() % 10 == 9 ? "\n" : " ");
      pinned.push_back({input.positions[3 * v], input.positions[3 * v + 1], input.positions[3 * v + 2]});
    }
    write_file(d.file("locks.txt"), list);
    REQUIRE(run_cli("simplify --quiet '" + in + "' -o '" + out + "' --target-tris 6000 --lock-vertices '" +
                    d.file("locks.txt") + "' --mem " + c.mem)
                .exit_code == 0);
    const LoadedMesh held = load_mesh(out);
    CHECK(held.triangle_count() == 6000);
    std::vector<std::array<double, 3>> kept;
    for (std::size_t v = 0; v < held.vertex_count(); ++v)
      kept.push_back({held.positions[3 * v], held.positions[3 * v + 1], held.positions[3 * v + 2]});
    std::sort(kept.begin(), kept.end());
    std::size_t found = 0;
    for (const auto& p : pinned) found += std::binary_search(kept.begin(), kept.end(), p);
    CHECK(found == pinned.size());
    if (c.passes) continue;
    // An index past the vertices, or a word that is none, is refused.
    write_file(d.file("bad.txt"), "1 2 " + std::to_string(input.vertex_count()) + "\n");
    CliResult bad = run_cli("simplify --quiet '" + in + "' -o '" + d.file("x.ply") +
                            "' --target-tris 6000 --lock-vertices '" + d.file("bad.txt") + "'");
    CHECK(bad.exit_code == 2);
    CHECK(bad.err.find("--lock-vertices names vertex") != std::string::npos);
    write_file(d.file("word.txt"), "1 2\n3 x4\n");
    bad = run_cli("simplify --quiet '" + in + "' -o '" + d.file("x.ply") + "' --target-tris 6000 --lock-vertices '" +
                  d.file("word.txt") + "'");
    CHECK(bad.exit_code == 3);
    CHECK(bad.err.find("word.txt: line 2: \"x4\"") != std::string::npos);
    // Without the lock the outline is simplified too.
    REQUIRE(run_cli("simplify --quiet '" + in + "' -o '" + d.file("free.ply") + "' --target-tris 6000").exit_code == 0);
    CHECK(boundary_edges(load_mesh(d.file("free.ply"))).size() < before.size());
    // The uniform grid cannot find the boundary: refused, naming the flag and the method.
    const CliResult r = run_cli("simplify --quiet '" + in + "' -o '" + d.file("x.ply") +
                                "' --method uniform --grid 32 --lock-boundary");
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("--lock-boundary") != std::string::npos);
    CHECK(r.err.find("not in uniform") != std::string::npos);
  }
}

namespace {

// An open cylinder of radius 1 around z, nu columns around by nz rows up, cut along
// x > 0, y = 0 into one texture chart: the seam's column is doubled, u = 0 on one
// side and u = 1 on the other, v = z. Binary PLY with float u and v.
void write_seam_cylinder(const std::string& path, std::uint32_t nu, std::uint32_t nz) {
  std::string body;
  const std::uint32_t row = nu + 1;
  for (std::uint32_t j = 0; j <= nz; ++j)
    for (std::uint32_t i = 0; i <= nu; ++i) {
      const double a = 2 * 3.14159265358979323846 * (i % nu) / nu;
      const float p[5] = {float(std::cos(a)), float(std::sin(a)), float(double(j) / nz), float(double(i) / nu),
                          float(double(j) / nz)};
      body.append(reinterpret_cast<const char*>(p), sizeof p);
    }
  for (std::uint32_t j = 0; j < nz; ++j)
    for (std::uint32_t i = 0; i < nu; ++i) {
      const std::uint32_t a = j * row + i, b = a + 1, c = a + row, e = c + 1;
      for (const std::array<std::uint32_t, 3>& t :
           {std::array<std::uint32_t, 3>{a, b, e}, std::array<std::uint32_t, 3>{a, e, c}}) {
        body.push_back(3);
        body.append(reinterpret_cast<const char*>(t.data()), 12);
      }
    }
  write_file(path, "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(row * (nz + 1)) +
                       "\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\n"
                       "element face " +
                       std::to_string(2 * nu * nz) + "\nproperty list uchar uint vertex_indices\nend_header\n" + body);
}

// The vertices of an ascii PLY with x y z u v, and its faces.
void read_ascii_xyzuv(const std::string& path, std::vector<std::array<double, 5>>* vertices,
                      std::vector<std::array<std::uint32_t, 3>>* faces) {
  std::istringstream in(read_file(path));
  std::string line;
  std::size_t nv = 0, nf = 0;
  while (std::getline(in, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) nv = std::stoul(line.substr(15));
    if (line.rfind("element face ", 0) == 0) nf = std::stoul(line.substr(13));
  }
  vertices->resize(nv);
  for (auto& v : *vertices)
    for (double& x : v) in >> x;
  faces->resize(nf);
  for (auto& f : *faces) {
    int n = 0;
    in >> n;
    REQUIRE(n == 3);
    for (auto& k : f) in >> k;
  }
}

// The same cylinder as write_seam_cylinder, in OBJ as exporters write it: each
// position once (nu a row), the texture coordinates apart (nu + 1 a row), and the faces
// naming both, so the reader has to split the seam's positions itself.
void write_seam_cylinder_obj(const std::string& path, std::uint32_t nu, std::uint32_t nz) {
  std::string s;
  char line[128];
  for (std::uint32_t j = 0; j <= nz; ++j)
    for (std::uint32_t i = 0; i < nu; ++i) {
      const double a = 2 * 3.14159265358979323846 * i / nu;
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", double(float(std::cos(a))), double(float(std::sin(a))),
                    double(float(double(j) / nz)));
      s += line;
    }
  for (std::uint32_t j = 0; j <= nz; ++j)
    for (std::uint32_t i = 0; i <= nu; ++i) {
      std::snprintf(line, sizeof line, "vt %.9g %.9g\n", double(float(double(i) / nu)), double(float(double(j) / nz)));
      s += line;
    }
  // 1-based "position/texture" of column i (0..nu) of row j.
  const auto corner = [&](std::uint32_t i, std::uint32_t j) {
    return std::to_string(j * nu + i % nu + 1) + "/" + std::to_string(j * (nu + 1) + i + 1);
  };
  for (std::uint32_t j = 0; j < nz; ++j)
    for (std::uint32_t i = 0; i < nu; ++i) {
      s += "f " + corner(i, j) + " " + corner(i + 1, j) + " " + corner(i + 1, j + 1) + "\n";
      s += "f " + corner(i, j) + " " + corner(i + 1, j + 1) + " " + corner(i, j + 1) + "\n";
    }
  write_file(path, s);
}

// Checks the ascii PLY (x y z u v) simplified from a seam cylinder of nz rows: the
// seam is whole on both sides, no face spans it, and u and v stay near the cylinder's
// own parametrisation.
void check_seam_cylinder_output(const std::string& out, std::uint32_t nz) {
  std::vector<std::array<double, 5>> v;
  std::vector<std::array<std::uint32_t, 3>> f;
  read_ascii_xyzuv(out, &v, &f);
  CHECK(f.size() == 4000);
  // No face blends the two sides of the seam: its u span is that of a face, not ~1.
  for (const auto& t : f) {
    const double lo = std::min({v[t[0]][3], v[t[1]][3], v[t[2]][3]}),
                 hi = std::max({v[t[0]][3], v[t[1]][3], v[t[2]][3]});
    CHECK(hi - lo < 0.5);
  }
  // u follows the angle and v the height: interpolated along the collapses, they stay
  // near the cylinder's own parametrisation (the face's chart decides 0 or 1 at the seam).
  double worst = 0;
  for (const auto& p : v) {
    double u = std::atan2(p[1], p[0]) / (2 * 3.14159265358979323846);
    if (u < 0) u += 1;
    if (p[3] > 0.75 && u < 0.25) u += 1;
    if (p[3] < 0.25 && u > 0.75) u -= 1;
    worst = std::max({worst, std::fabs(u - p[3]), std::fabs(p[2] - p[4])});
  }
  CHECK(worst < 0.02);
  // The seam simplifies, its two sides together: the vertices at u = 0 and at u = 1 are
  // at the same positions, the rims' ends among them.
  std::set<std::array<double, 3>> side0, side1;
  for (const auto& p : v)
    if (p[1] == 0.0 && (p[3] == 0.0 || p[3] == 1.0)) (p[3] == 0.0 ? side0 : side1).insert({p[0], p[1], p[2]});
  CHECK(side0 == side1);
  CHECK(side0.size() >= 2);
  CHECK(side0.size() < std::size_t(nz + 1));
  // Welded by position, the surface is closed but for its two rims: the seam did not open.
  std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, int> edge_faces;
  for (const auto& t : f)
    for (int k = 0; k < 3; ++k) {
      const auto& p = v[t[std::size_t(k)]];
      const auto& q = v[t[std::size_t((k + 1) % 3)]];
      std::array<double, 3> a{p[0], p[1], p[2]}, b{q[0], q[1], q[2]};
      if (b < a) std::swap(a, b);
      ++edge_faces[{a, b}];
    }
  std::size_t open_inside = 0, more_than_two = 0;
  for (const auto& e : edge_faces) {
    const bool rim =
        (e.first.first[2] == 0.0 && e.first.second[2] == 0.0) || (e.first.first[2] == 1.0 && e.first.second[2] == 1.0);
    open_inside += e.second == 1 && !rim;
    more_than_two += e.second > 2;
  }
  CHECK(open_inside == 0);
  CHECK(more_than_two == 0);
}

}  // namespace

TEST_CASE("texture coordinates follow the edge collapse, and a seam stays where it is, whole and in passes",
          "[qem][uv]") {
  ScratchDir d;
  struct Case {
    std::uint32_t nu, nz;
    const char* mem;
  };
  std::vector<Case> cases = {{200, 150, "1G"}};
  if (!OOCSIMP_TEST_UNDER_ASAN) cases.push_back({1000, 1000, "128M"});
  for (const Case& c : cases) {
    CAPTURE(c.nu, c.nz);
    const std::string in = d.file("cylinder.ply"), out = d.file("out.ply");
    write_seam_cylinder(in, c.nu, c.nz);
    const CliResult r = run_cli("simplify '" + in + "' -o '" + out + "' --ascii --target-tris 4000 --mem " + c.mem);
    REQUIRE(r.exit_code == 0);
    CHECK(r.err.find("texture coordinates") == std::string::npos);  // carried, not dropped
    check_seam_cylinder_output(out, c.nz);
  }
  // OBJ keeps texture coordinates on face corners: the reader splits the seam.
  {
    const std::string in = d.file("cylinder.obj"), out = d.file("out-obj.ply");
    write_seam_cylinder_obj(in, 200, 150);
    OpenOptions open;
    open.attributes.texture_coordinates = true;
    const MeshInput mesh = open_mesh_input(in, open);
    CHECK(mesh.info.vertex_count == 200 * 151 + 151);
    const CliResult r = run_cli("simplify '" + in + "' -o '" + out + "' --ascii --target-tris 4000");
    REQUIRE(r.exit_code == 0);
    CHECK(r.err.find("texture coordinates") == std::string::npos);
    check_seam_cylinder_output(out, 150);
  }
  // Clustering cannot keep them: dropped with the warning that says why.
  write_seam_cylinder(d.file("small.ply"), 60, 40);
  const CliResult r = run_cli("simplify '" + d.file("small.ply") + "' -o '" + d.file("c.ply") + "' --grid 10");
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("texture coordinates (u, v) are dropped: clustering merges vertices across texture seams") !=
        std::string::npos);
}

TEST_CASE("the first pass spread over parts leaves one process's remainder, for 1 to 5 parts", "[qem_passes]") {
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::parts, 40000, true);
  PassSizes sizes = small_tiles();
  sizes.part_above = 3000;  // dense tiles are worked on in parts too
  const SimplifyOptions options;
  const std::uint64_t target = 3000;
  MeshInput whole = open_mesh_input(in, OpenOptions());
  SimplifyStats one;
  const QuadricMesh expected =
      reduce_in_passes(whole, plan_run(whole, options), whole.info.bounds.min, target, &one, sizes);
  REQUIRE(one.refine.passes >= 2);
  for (std::uint32_t parts = 1; parts <= 5; ++parts) {
    // Each part's tiles, as a part file would keep them.
    std::vector<TileOutput> tiles;
    FirstPassParts spread;
    std::uint64_t collapses = 0;
    for (std::uint32_t part = 0; part < parts; ++part) {
      MeshInput input = open_mesh_input(in, OpenOptions());
      const FirstPassPlan plan = first_pass_part(
          input, plan_run(input, options), input.info.bounds.min, target, part, parts,
          [&](const TileOutput& t) { tiles.push_back(t); }, sizes);
      collapses += plan.collapses;
      if (part == 0) spread.plan = plan;
      CHECK(plan.threshold == spread.plan.threshold);
      CHECK(plan.tiles == spread.plan.tiles);
    }
    spread.plan.collapses = collapses;
    std::reverse(tiles.begin(), tiles.end());  // any order
    spread.tiles = [&](const TileOutputSink& sink) {
      for (const TileOutput& t : tiles) sink(t);
    };
    MeshInput input = open_mesh_input(in, OpenOptions());
    SimplifyStats merged;
    const QuadricMesh rest = reduce_after_first_pass(input, plan_run(input, options), input.info.bounds.min, target,
                                                     spread.plan, spread.tiles, &merged, sizes);
    INFO(parts << " parts");
    CHECK(merged.refine.pass_triangles == one.refine.pass_triangles);
    CHECK(merged.refine.collapses == one.refine.collapses);
    CHECK(merged.input_triangles == one.input_triangles);
    REQUIRE(rest.triangles == expected.triangles);
    REQUIRE(rest.positions.size() == expected.positions.size());
    for (std::size_t i = 0; i < rest.positions.size(); ++i) {
      const Vec3d &a = rest.positions[i], &b = expected.positions[i];
      REQUIRE((a.x == b.x && a.y == b.y && a.z == b.z));
    }
    CHECK(rest.attributes == expected.attributes);
    REQUIRE(rest.quadrics.size() == expected.quadrics.size());
    CHECK(std::memcmp(rest.quadrics.data(), expected.quadrics.data(), rest.quadrics.size() * sizeof(Quadric)) == 0);
  }
}

namespace {

// A number of the stats JSON, by its key (-1 when absent).
double json_number(const std::string& js, const std::string& key) {
  const std::size_t at = js.find("\"" + key + "\":");
  return at == std::string::npos ? -1 : std::stod(js.substr(at + key.size() + 3));
}

// The CLI run with `args`, its stderr into `err`, its RssAnon read from /proc every
// 10 ms while it runs: a figure independent of the one the program reports.
struct PolledRun {
  int exit_code = -1;
  std::uint64_t peak_anon = 0;
};
PolledRun run_polled(const std::vector<std::string>& args, const std::string& err) {
  std::vector<char*> argv{const_cast<char*>(OOCSIMP_CLI)};
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(fd, 2);
    ::dup2(null, 1);
    ::dup2(null, 0);
    ::execv(OOCSIMP_CLI, argv.data());
    ::_exit(127);
  }
  PolledRun r;
  const std::string status = "/proc/" + std::to_string(pid) + "/status";
  for (;;) {
    int st = 0;
    if (::waitpid(pid, &st, WNOHANG) == pid) {
      r.exit_code = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
      return r;
    }
    std::ifstream in(status);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("RssAnon:", 0) == 0)
        r.peak_anon = std::max<std::uint64_t>(r.peak_anon, std::stoull(line.substr(8)) * 1024);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// The lines of `text` that end with `suffix` after "oocsimp: ", without either.
std::vector<std::string> phase_lines(const std::string& text, const std::string& suffix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("oocsimp: ", 0) != 0) continue;
    const std::size_t at = line.find(suffix);
    if (at != std::string::npos) out.push_back(line.substr(9, at - 9));
  }
  return out;
}

}  // namespace

TEST_CASE("a run through the passes stays within --mem in every phase, by its own figures and by /proc",
          "[qem_passes][memory]") {
#if OOCSIMP_TEST_UNDER_ASAN
  // AddressSanitizer's shadow memory and quarantine are anonymous memory too: the
  // bound is the normal build's to check.
  skip_test("AddressSanitizer build: the bound is the normal build's to check");
  return;
#endif
  // 20M triangles go through three passes; at --mem 112M the sphere's poles make
  // tiles worked on in parts whose slabs hold up to 2.3x their average, one piece at a
  // time fits next to the spill held in memory, and the budget is within a fifth of
  // the least the run accepts (docs/benchmarks.md, "Memory of the passes").
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::sphere, 20000000, false);
  const std::uint64_t budget = std::uint64_t(112) << 20;
  const PolledRun r = run_polled({"simplify", in, "-o", d.file("out.ply"), "--target-tris", "100000", "--mem", "112M",
                                  "--threads", "2", "--stats", d.file("s.json"), "--tmp", d.path()},
                                 d.file("err"));
  const std::string err = read_file(d.file("err"));
  INFO(err);
  REQUIRE(r.exit_code == 0);
  const std::string js = read_file(d.file("s.json"));
  CHECK(json_number(js, "passes") >= 2);
  CHECK(json_number(js, "phase1_peak_anon_bytes") > 0);
  CHECK(json_number(js, "phase1_peak_anon_bytes") <= double(budget));
  CHECK(json_number(js, "phase2_peak_anon_bytes") <= double(budget));
  CHECK(json_number(js, "peak_anon_bytes") <= double(budget));
  CHECK(r.peak_anon > 0);
  CHECK(r.peak_anon <= budget);
  CHECK(err.find("went past") == std::string::npos);
}

TEST_CASE("a log of the passes has a started and a done line for each phase, and each pass's counts",
          "[qem_passes][progress]") {
  ScratchDir d;
  const std::string in = generated(d, SyntheticShape::sphere, 2000000, false);
  // stderr is a file here: the log's plain lines, not the terminal's bar.
  const CliResult r = run_cli("simplify '" + in + "' -o '" + d.file("out.ply") +
                              "' --target-tris 20000 --mem 128M --threads 2 --stats '" + d.file("s.json") +
                              "' --tmp '" + d.path() + "'");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const std::vector<std::string> started = phase_lines(r.err, " started"), done = phase_lines(r.err, " done in ");
  // Every phase started is done, in the same order (the phases do not nest).
  std::vector<std::string> started_names;
  for (const std::string& s : started) started_names.push_back(s.substr(0, s.find(" started")));
  CHECK(started_names == done);
  CHECK(std::find(done.begin(), done.end(), "bin tiles") != done.end());
  CHECK(std::find(done.begin(), done.end(), "collapse") != done.end());
  // Each pass: its number, the triangles it starts from, and at its end those it
  // leaves, as the summary counts them.
  const std::string js = read_file(d.file("s.json"));
  const int passes = int(json_number(js, "passes"));
  REQUIRE(passes >= 1);
  std::string counts = r.out.substr(r.out.find("passes  "));
  counts = counts.substr(counts.find(": ") + 2);
  counts = counts.substr(0, counts.find(" triangles"));
  std::vector<std::string> n;  // the triangles before and after each pass
  for (std::size_t at = 0; at != std::string::npos;) {
    const std::size_t arrow = counts.find(" -> ", at);
    n.push_back(counts.substr(at, arrow == std::string::npos ? std::string::npos : arrow - at));
    at = arrow == std::string::npos ? arrow : arrow + 4;
  }
  REQUIRE(n.size() == std::size_t(passes) + 1);
  for (int p = 1; p <= passes; ++p) {
    const std::string name = "collapse pass " + std::to_string(p);
    INFO(name);
    CHECK(r.err.find("oocsimp: " + name + " started: " + n[std::size_t(p - 1)] + " triangles in\n") !=
          std::string::npos);
    const std::size_t end = r.err.find("oocsimp: " + name + " done in ");
    REQUIRE(end != std::string::npos);
    const std::string line = r.err.substr(end, r.err.find('\n', end) - end);
    CHECK(line.find(": " + n[std::size_t(p - 1)] + " -> " + n[std::size_t(p)] + " triangles") != std::string::npos);
  }
  CHECK(r.err.find("collapse passes") == std::string::npos);
}
