#include <catch2/catch.hpp>

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <tbb/global_control.h>

#include "cluster/kept_tiles.hpp"
#include "cluster/vertex_grading.hpp"
#include "floating_cells_reference.hpp"
#include "oocsimp/generate.hpp"
#include "api/simplify.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

// What the sequential algorithm gives on the whole mesh in memory, with the centre
// vertex as representative (so the output is exact and comparable bit for bit):
// the referenced vertices, graded; the reference clustering; the triangles over
// three clusters, first occurrence in file order; vertices numbered by first use.
SimplifiedMesh expected_mesh(const std::string& path, double cell, CellShape shape, AssignRule rule) {
  LoadedMesh m = load_mesh(path);
  MeshInput in = open_mesh_input(path);
  std::vector<std::uint64_t> used(m.triangles.begin(), m.triangles.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  std::vector<GradedVertex> graded = grade_vertices(used, m.triangles.data(), m.triangle_count(), in.positions);
  ReferenceClustering ref = reference_floating_cells(graded, cell, shape, rule);
  std::map<std::uint64_t, std::uint64_t> cluster;  // vertex -> centre
  std::map<std::uint64_t, Vec3d> where;
  for (std::size_t i = 0; i < graded.size(); ++i) {
    cluster[graded[i].index] = ref.cluster[i];
    where[graded[i].index] = graded[i].p;
  }
  std::set<std::array<std::uint64_t, 3>> seen;
  std::map<std::uint64_t, std::uint32_t> number;
  SimplifiedMesh out;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    std::array<std::uint64_t, 3> c = {cluster[m.triangles[3 * t]], cluster[m.triangles[3 * t + 1]],
                                      cluster[m.triangles[3 * t + 2]]};
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    std::array<std::uint64_t, 3> key = c;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) continue;
    for (std::uint64_t x : c) {
      auto it = number.emplace(x, std::uint32_t(number.size())).first;
      if (it->second == number.size() - 1 && out.positions.size() / 3 < number.size()) {
        const Vec3d& p = where[x];
        out.positions.insert(out.positions.end(), {float(p.x), float(p.y), float(p.z)});
      }
      out.triangles.push_back(it->second);
    }
  }
  return out;
}

SimplifiedMesh run_floating(const std::string& path, double cell, CellShape shape, AssignRule rule,
                            RepresentativeRule rep, double tile, unsigned threads, SimplifyStats* st = nullptr) {
  MeshInput in = open_mesh_input(path);
  SimplifyOptions o;
  o.method = ClusterMethod::floating;
  o.sizing.cell = cell;
  o.floating.cell_shape = shape;
  o.floating.assign = rule;
  o.floating.representative = rep;
  o.floating.tile_side = tile;
  o.threads = threads;
  return simplify(in, o, st);
}

// A noisy plane with coincident weights (a regular grid: all interior vertices
// have the same weight) and duplicated points, as an ascii PLY.
void write_grid_with_duplicates(const std::string& path, int n) {
  std::string v, f;
  int count = 0;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i, ++count) v += std::to_string(i * 0.1) + " " + std::to_string(j * 0.1) + " 0\n";
  int nv = count;
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i;
      tris.push_back({a, a + 1, a + n + 2});
      tris.push_back({a, a + n + 2, a + n + 1});
    }
  // A second copy of the first row's vertices (duplicate points) used by a strip.
  for (int i = 0; i <= n; ++i) v += std::to_string(i * 0.1) + " 0 0\n";
  for (int i = 0; i < n; ++i) tris.push_back({nv + i, nv + i + 1, (n + 1) + i});
  nv += n + 1;
  for (auto& t : tris)
    f += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  write_file(path, "ply\nformat ascii 1.0\nelement vertex " + std::to_string(nv) +
                       "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                       std::to_string(tris.size()) + "\nproperty list uchar int vertex_indices\nend_header\n" + v + f);
}

// A soup of random triangles (boundaries everywhere, many tiny and long ones).
void write_random_soup(const std::string& path, int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::string v, f;
  for (int i = 0; i < 3 * n; ++i)
    v += std::to_string(u(rng)) + " " + std::to_string(u(rng)) + " " + std::to_string(0.2 * u(rng)) + "\n";
  std::uniform_int_distribution<int> pick(0, 3 * n - 1);
  for (int i = 0; i < n; ++i) {
    int a = pick(rng), b = pick(rng), c = pick(rng);
    // Mostly local triangles: pick neighbours by index.
    if (i % 4) {
      b = (a + 1) % (3 * n);
      c = (a + 2) % (3 * n);
    }
    f += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
  }
  write_file(path, "ply\nformat ascii 1.0\nelement vertex " + std::to_string(3 * n) +
                       "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(n) +
                       "\nproperty list uchar int vertex_indices\nend_header\n" + v + f);
}

}  // namespace

TEST_CASE("floating cells out of core equal the sequential algorithm in memory", "[floating][clusterer]") {
  ScratchDir d;
  struct Case {
    std::string name;
    double cell;
  };
  std::vector<Case> cases;
  GenerateOptions g;
  g.triangles = 20000;
  g.shape = SyntheticShape::sphere;
  generate_mesh(d.file("sphere.ply"), g);
  cases.push_back({"sphere.ply", 0.09});
  g.shape = SyntheticShape::parts;
  g.triangles = 30000;
  g.seed = 4;
  generate_mesh(d.file("parts.ply"), g);
  cases.push_back({"parts.ply", 0.04});
  g.shape = SyntheticShape::terrain;
  g.triangles = 8000;
  generate_mesh(d.file("terrain.ply"), g);
  cases.push_back({"terrain.ply", 0.07});
  write_grid_with_duplicates(d.file("grid.ply"), 40);
  cases.push_back({"grid.ply", 0.35});
  write_random_soup(d.file("soup.ply"), 3000, 9);
  cases.push_back({"soup.ply", 0.08});

  for (const Case& c : cases) {
    for (CellShape shape : {CellShape::cube, CellShape::sphere}) {
      for (AssignRule rule : {AssignRule::nearest, AssignRule::heaviest}) {
        SimplifiedMesh want = expected_mesh(d.file(c.name), c.cell, shape, rule);
        REQUIRE(want.triangles.size() > 30);
        for (double tile : {0.0, c.cell * 1.0, c.cell * 2.7}) {
          for (unsigned threads : {1u, 2u}) {
            SimplifyStats st;
            SimplifiedMesh got =
                run_floating(d.file(c.name), c.cell, shape, rule, RepresentativeRule::centre, tile, threads, &st);
            INFO(c.name << " shape " << int(shape) << " rule " << int(rule) << " tile " << tile << " threads "
                        << threads << " tiles " << st.floating.tiles << " rounds " << st.floating.rounds);
            CHECK(got.triangles == want.triangles);
            CHECK(got.positions == want.positions);
          }
        }
      }
    }
  }
}

TEST_CASE("floating output is byte-identical for any tile size and thread count", "[floating][clusterer]") {
  ScratchDir d;
  GenerateOptions g;
  g.triangles = 30000;
  g.shape = SyntheticShape::parts;
  generate_mesh(d.file("parts.ply"), g);
  // The sphere's coordinates make floating-point sums sensitive to their order,
  // which the axis-aligned parts are not.
  g.shape = SyntheticShape::sphere;
  g.triangles = 20000;
  generate_mesh(d.file("sphere.ply"), g);
  for (const char* name : {"parts.ply", "sphere.ply"})
    for (RepresentativeRule rep : {RepresentativeRule::quadric, RepresentativeRule::mean}) {
      double cell = std::string(name) == "parts.ply" ? 0.02 : 0.06;
      SimplifiedMesh ref = run_floating(d.file(name), cell, CellShape::cube, AssignRule::nearest, rep, 0, 1);
      REQUIRE(ref.triangles.size() > 1000);
      for (double tile : {cell, 2.5 * cell, 6.5 * cell}) {
        for (unsigned threads : {1u, 2u, 4u}) {
          SimplifyStats st;
          SimplifiedMesh got =
              run_floating(d.file(name), cell, CellShape::cube, AssignRule::nearest, rep, tile, threads, &st);
          INFO(name << " rep " << int(rep) << " tile " << tile << " threads " << threads << " tiles "
                    << st.floating.tiles);
          CHECK(st.floating.tiles > 1);
          CHECK(got.positions == ref.positions);
          CHECK(got.triangles == ref.triangles);
        }
      }
    }
}

TEST_CASE("the triangle spill is zstd-compressed or not as asked, with the same output", "[floating][clusterer]") {
  // 200k triangles at the smallest budget (32 MiB): most of the spill goes to the
  // disk, where compression applies.
  ScratchDir d;
  GenerateOptions g;
  g.triangles = 200000;
  g.shape = SyntheticShape::sphere;
  generate_mesh(d.file("sphere.ply"), g);
  auto run = [&](SpillCompression c, SimplifyStats* st) {
    MeshInput in = open_mesh_input(d.file("sphere.ply"));
    SimplifyOptions o;
    o.sizing.cell = 0.06;
    o.floating.tile_side = 0.3;
    o.memory_budget = 32u << 20;
    o.floating.spill_compression = c;
    return simplify(in, o, st);
  };
  SimplifyStats none, zstd, automatic;
  SimplifiedMesh a = run(SpillCompression::none, &none);
  SimplifiedMesh b = run(SpillCompression::zstd, &zstd);
  SimplifiedMesh c = run(SpillCompression::automatic, &automatic);
  REQUIRE(a.triangles.size() > 1000);
  CHECK(b.positions == a.positions);
  CHECK(b.triangles == a.triangles);
  CHECK(c.positions == a.positions);
  CHECK(c.triangles == a.triangles);
  // The same records on disk either way; zstd stores the triangle and stitch
  // records in well under what they take raw (the vertex blocks are never
  // compressed).
  CHECK(none.floating.spill_raw_bytes > 0);
  CHECK(zstd.floating.spill_raw_bytes == none.floating.spill_raw_bytes);
  CHECK(zstd.floating.spill_bytes_in_memory == none.floating.spill_bytes_in_memory);
  CHECK(none.floating.spill_bytes >= none.floating.spill_raw_bytes);  // block headers on top
  CHECK(double(none.floating.spill_bytes) < 1.01 * double(none.floating.spill_raw_bytes));
  CHECK(double(zstd.floating.spill_bytes) < 0.8 * double(none.floating.spill_bytes));
  // A few MiB of spill fit in any machine's page cache: automatic leaves it raw.
  CHECK(automatic.floating.spill_bytes == none.floating.spill_bytes);
}

TEST_CASE("quadric representatives stay in their floating cell and sharpen corners", "[floating][clusterer]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 40);
  double cell = 0.15;
  SimplifiedMesh q =
      run_floating(d.file("cube.ply"), cell, CellShape::cube, AssignRule::nearest, RepresentativeRule::quadric, 0, 0);
  SimplifiedMesh c =
      run_floating(d.file("cube.ply"), cell, CellShape::cube, AssignRule::nearest, RepresentativeRule::centre, 0, 0);
  // Same clusters, same connectivity: only positions differ.
  REQUIRE(q.triangles == c.triangles);
  for (std::size_t i = 0; i < q.positions.size(); ++i)
    CHECK(std::abs(q.positions[i] - c.positions[i]) <= 0.5 * cell + 1e-6);
  // Every cube corner is reproduced exactly by some quadric representative.
  for (int k = 0; k < 8; ++k) {
    double best = 1e9;
    for (std::size_t i = 0; i < q.positions.size(); i += 3)
      best = std::min<double>(best, std::abs(q.positions[i] - (k & 1)) + std::abs(q.positions[i + 1] - ((k >> 1) & 1)) +
                                        std::abs(q.positions[i + 2] - ((k >> 2) & 1)));
    CHECK(best < 1e-5);
  }
}

namespace {

void write_mesh_ply(const std::string& path, const std::vector<double>& pos, const std::vector<std::uint64_t>& tri) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(pos.size() / 3) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(tri.size() / 3) + "\nproperty list uchar uint vertex_indices\nend_header\n";
  for (double v : pos) put_le(s, float(v));
  for (std::size_t i = 0; i < tri.size(); i += 3) {
    s.push_back(3);
    for (int k = 0; k < 3; ++k) put_le(s, std::uint32_t(tri[i + std::size_t(k)]));
  }
  write_file(path, s);
}

SimplifiedMesh simplify_with(const std::string& path, ClusterMethod method, double cell) {
  MeshInput in = open_mesh_input(path);
  SimplifyOptions o;
  o.method = method;
  o.sizing.cell = cell;
  return simplify(in, o, nullptr);
}

}  // namespace

TEST_CASE("consistency (Low & Tan 3.2.2, Plate 5): a distant object leaves A's floating cells alone",
          "[floating][clusterer]") {
  ScratchDir d;
  GenerateOptions g;
  g.triangles = 40000;
  g.shape = SyntheticShape::parts;
  generate_mesh(d.file("a.ply"), g);
  LoadedMesh a = load_mesh(d.file("a.ply"));
  // B: a cube far from A that moves the bounding box; its vertices follow A's.
  write_cube_ply(d.file("b.ply"), 20);
  LoadedMesh b = load_mesh(d.file("b.ply"));
  std::vector<double> pos = a.positions;
  for (std::size_t i = 0; i < b.positions.size(); i += 3)
    pos.insert(pos.end(), {b.positions[i] - 7.3, b.positions[i + 1] + 3.1, b.positions[i + 2] - 5.9});
  std::vector<std::uint64_t> tri = a.triangles;
  for (std::uint64_t v : b.triangles) tri.push_back(v + a.vertex_count());
  write_mesh_ply(d.file("ab.ply"), pos, tri);

  const double cell = 0.013;
  SimplifiedMesh fa = simplify_with(d.file("a.ply"), ClusterMethod::floating, cell);
  SimplifiedMesh fab = simplify_with(d.file("ab.ply"), ClusterMethod::floating, cell);
  // A's triangles come first in the input, so A's part of the output is a prefix:
  // the same triangles, the same vertex numbers, the same positions.
  REQUIRE(fab.triangles.size() > fa.triangles.size());
  CHECK(std::equal(fa.triangles.begin(), fa.triangles.end(), fab.triangles.begin()));
  CHECK(std::equal(fa.positions.begin(), fa.positions.end(), fab.positions.begin()));

  // The uniform grid follows the bounding box, so A's part moves with B (this is
  // what Plate 5(a) shows); record that it indeed differs.
  SimplifiedMesh ua = simplify_with(d.file("a.ply"), ClusterMethod::uniform, cell);
  SimplifiedMesh uab = simplify_with(d.file("ab.ply"), ClusterMethod::uniform, cell);
  bool same_prefix = uab.positions.size() >= ua.positions.size() &&
                     std::equal(ua.positions.begin(), ua.positions.end(), uab.positions.begin());
  CHECK_FALSE(same_prefix);
}

TEST_CASE("keep-tmp keeps the binned tiles and a later run with other options reuses them", "[floating][clusterer]") {
  ScratchDir d;
  GenerateOptions g;
  g.triangles = 20000;
  g.shape = SyntheticShape::parts;
  generate_mesh(d.file("p.ply"), g);
  std::string kept = d.file("kept"), fresh = d.file("fresh");
  REQUIRE(system(("mkdir '" + kept + "' '" + fresh + "'").c_str()) == 0);
  auto run = [&](double cell, RepresentativeRule rep, const std::string& tmp, bool keep, SimplifyStats* st) {
    MeshInput in = open_mesh_input(d.file("p.ply"));
    SimplifyOptions o;
    o.method = ClusterMethod::floating;
    o.sizing.cell = cell;
    o.floating.representative = rep;
    o.floating.tile_side = 0.1;
    o.temp_dir = tmp;
    o.floating.keep_temp = keep;
    return simplify(in, o, st);
  };
  SimplifyStats first, second;
  run(0.02, RepresentativeRule::quadric, kept, true, &first);
  CHECK_FALSE(first.floating.resumed);
  SimplifiedMesh resumed = run(0.03, RepresentativeRule::mean, kept, true, &second);
  CHECK(second.floating.resumed);
  CHECK(second.input_triangles == first.input_triangles);
  SimplifyStats third;
  SimplifiedMesh plain = run(0.03, RepresentativeRule::mean, fresh, false, &third);
  CHECK_FALSE(third.floating.resumed);
  CHECK(resumed.triangles == plain.triangles);
  CHECK(resumed.positions == plain.positions);
  // The kept files stay (tiles, vertices, manifest); a run without --keep-tmp leaves nothing.
  CHECK(system(("test $(ls '" + kept + "' | grep -c '^oocsimp-kept-') -eq 3").c_str()) == 0);
  CHECK(system(("test -z \"$(ls -A '" + fresh + "')\"").c_str()) == 0);
  // A cell wider than the kept tiles cannot reuse them: they are rebuilt.
  SimplifyStats wide;
  run(0.2, RepresentativeRule::quadric, kept, true, &wide);
  CHECK_FALSE(wide.floating.resumed);
}

namespace {

// --keep-tmp runs of one input into one kept folder, against fresh runs elsewhere.
struct KeptFolder {
  ScratchDir d;
  std::string input = d.file("in.ply"), kept = d.file("kept"), fresh = d.file("fresh");
  KeptFolder() { REQUIRE(system(("mkdir '" + kept + "' '" + fresh + "'").c_str()) == 0); }

  SimplifiedMesh run(const std::string& path, const std::string& tmp, bool keep, SimplifyStats* st) const {
    MeshInput in = open_mesh_input(path);
    SimplifyOptions o;
    o.method = ClusterMethod::floating;
    o.sizing.cell = 0.05;
    o.floating.tile_side = 0.25;
    o.temp_dir = tmp;
    o.floating.keep_temp = keep;
    return simplify(in, o, st);
  }
  SimplifiedMesh kept_run(SimplifyStats* st) const { return run(input, kept, true, st); }
  // What a run without kept tiles gives on `path` (in its own folder).
  SimplifiedMesh fresh_run(const std::string& path) const {
    SimplifyStats st;
    SimplifiedMesh m = run(path, fresh, false, &st);
    REQUIRE_FALSE(st.floating.resumed);
    return m;
  }
  // The kept file with this extension (there is one set: one input).
  std::string kept_file(const std::string& ext) const {
    for (const std::string& name : ScratchDirNames(kept))
      if (name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0)
        return kept + "/" + name;
    FAIL("no kept ." << ext << " file");
    return "";
  }
  static std::vector<std::string> ScratchDirNames(const std::string& dir) {
    std::vector<std::string> names;
    if (DIR* dp = opendir(dir.c_str())) {
      while (dirent* e = readdir(dp))
        if (e->d_name[0] != '.') names.push_back(e->d_name);
      closedir(dp);
    }
    return names;
  }
};

// A sphere of radius about 1; seeds give files of one size and different content.
void generate_sphere(const std::string& path, std::uint64_t seed) {
  GenerateOptions g;
  g.triangles = 20000;
  g.seed = seed;
  generate_mesh(path, g);
}

bool same_mesh(const SimplifiedMesh& a, const SimplifiedMesh& b) {
  return a.triangles == b.triangles && a.positions == b.positions;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const std::string& l : lines) s += l + "\n";
  return s;
}

}  // namespace

TEST_CASE("keep-tmp does not resume from an input replaced by another of the same size and times",
          "[floating][clusterer][kept]") {
  KeptFolder k;
  generate_sphere(k.input, 1);
  generate_sphere(k.d.file("other.ply"), 2);
  const std::string other = read_file(k.d.file("other.ply"));
  REQUIRE(other.size() == read_file(k.input).size());
  REQUIRE(other != read_file(k.input));
  SimplifyStats first;
  k.kept_run(&first);
  REQUIRE_FALSE(first.floating.resumed);
  struct stat before;
  REQUIRE(stat(k.input.c_str(), &before) == 0);

  SECTION("overwritten in place, the modification time set back") {
    write_file(k.input, other);
    const timespec times[2] = {before.st_atim, before.st_mtim};
    REQUIRE(utimensat(AT_FDCWD, k.input.c_str(), times, 0) == 0);
    struct stat after;
    REQUIRE(stat(k.input.c_str(), &after) == 0);
    REQUIRE(after.st_size == before.st_size);
    REQUIRE(after.st_mtim.tv_sec == before.st_mtim.tv_sec);
    REQUIRE(after.st_mtim.tv_nsec == before.st_mtim.tv_nsec);
    SimplifyStats second;
    SimplifiedMesh m = k.kept_run(&second);
    CHECK_FALSE(second.floating.resumed);
    CHECK(same_mesh(m, k.fresh_run(k.d.file("other.ply"))));
    INFO(joined(second.warnings));
    CHECK_THAT(joined(second.warnings), Catch::Contains(k.input + ": changed since its tiles were kept"));
  }
  SECTION("the same identity, other content: the content checksum tells") {
    // stat cannot be fooled without privileges; the manifest can be made to name the
    // replaced file's identity (with a valid checksum of its own), as a file system
    // restored from a backup, or a clock set back, would.
    write_file(k.input, other);
    FileIdentity now;
    REQUIRE(regular_file_identity(k.input, &now));
    KeptManifest m;
    REQUIRE(parse_kept_manifest(read_file(k.kept_file(".manifest")), &m));
    m.input = now;
    write_file(k.kept_file(".manifest"), format_kept_manifest(m));
    SimplifyStats second;
    SimplifiedMesh out = k.kept_run(&second);
    CHECK_FALSE(second.floating.resumed);
    CHECK(same_mesh(out, k.fresh_run(k.d.file("other.ply"))));
    INFO(joined(second.warnings));
    CHECK_THAT(joined(second.warnings), Catch::Contains(k.input + ": content differs"));
  }
}

TEST_CASE("damaged or missing kept files are recomputed with a warning, giving a fresh run's output",
          "[floating][clusterer][kept]") {
  KeptFolder k;
  generate_sphere(k.input, 1);
  const SimplifiedMesh fresh = k.fresh_run(k.input);
  SimplifyStats first;
  CHECK(same_mesh(k.kept_run(&first), fresh));
  REQUIRE_FALSE(first.floating.resumed);
  CHECK(first.warnings.empty());
  const std::string tiles = k.kept_file(".tiles"), vertices = k.kept_file(".vertices"),
                    manifest = k.kept_file(".manifest");
  std::string damaged;  // the file the warning must name
  SECTION("a zero-filled .tiles (a crash before the page cache was written)") {
    write_file(tiles, std::string(read_file(tiles).size(), '\0'));
    damaged = tiles;
  }
  SECTION("a truncated .tiles") {
    REQUIRE(truncate(tiles.c_str(), off_t(read_file(tiles).size() / 2)) == 0);
    damaged = tiles;
  }
  SECTION("a .vertices deleted") {
    REQUIRE(unlink(vertices.c_str()) == 0);
    damaged = vertices;
  }
  SECTION("a garbled manifest") {
    std::string m = read_file(manifest);
    REQUIRE(m.size() > 200);
    for (std::size_t i = 100; i < 110; ++i) m[i] = '7';
    write_file(manifest, m);
    damaged = manifest;
  }
  SECTION("a manifest deleted, the kept files left") {
    REQUIRE(unlink(manifest.c_str()) == 0);
    damaged = manifest;
  }
  SimplifyStats second;
  SimplifiedMesh again = k.kept_run(&second);
  CHECK_FALSE(second.floating.resumed);
  CHECK(same_mesh(again, fresh));
  REQUIRE(second.warnings.size() == 1);
  CHECK_THAT(second.warnings[0], Catch::StartsWith(damaged + ": "));
  CHECK_THAT(second.warnings[0], Catch::EndsWith("binning again"));
  // The recomputed tiles were kept in their place: the next run resumes from them.
  SimplifyStats third;
  CHECK(same_mesh(k.kept_run(&third), fresh));
  CHECK(third.floating.resumed);
  CHECK(third.warnings.empty());
}

namespace {
std::string q(const std::string& s) { return "'" + s + "'"; }
// The number after "key": in a stats file (the first occurrence), or -1.
double json_number(const std::string& js, const std::string& key) {
  std::size_t at = js.find("\"" + key + "\":");
  return at == std::string::npos ? -1 : std::stod(js.substr(at + key.size() + 3));
}
}  // namespace

TEST_CASE("a --tile whose tiles' buffers exceed --mem is refused up front, one that fits stays in the budget",
          "[floating][clusterer][memory]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 200000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  REQUIRE(system(("mkdir " + q(d.file("tmp"))).c_str()) == 0);
  const std::string run = "simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --tmp " +
                          q(d.file("tmp")) + " --grid 256 --threads 2 --stats " + q(d.file("st.json"));
  // e481674: a tile per occupied cell, 8 KiB of buffers each (tens of thousands of
  // tiles here, 256,037 and 2.19 GB on a 2M sphere).
  for (const char* tile : {"1e-30", "0.05"}) {
    CAPTURE(tile);
    CliResult r = run_cli(run + " --mem 32M --tile " + tile);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_THAT(r.err, Catch::Contains("--tile " + std::string(tile)));
    CHECK_THAT(r.err, Catch::Contains("--mem 32 MiB"));
    CHECK_FALSE(file_exists(d.file("o.ply")));
    CHECK(KeptFolder::ScratchDirNames(d.file("tmp")).empty());
  }
  // A sphere of radius about 1 in tiles of 0.25: a few hundred tiles.
  REQUIRE(run_cli(run + " --mem 32M --tile 0.25").exit_code == 0);
  std::string js = read_file(d.file("st.json"));
  INFO(js);
  CHECK(json_number(js, "count") > 100);  // tiles
#if !OOCSIMP_TEST_UNDER_ASAN
  // (AddressSanitizer's shadow memory is anonymous memory too.)
  CHECK(json_number(js, "peak_anon_bytes") < double(32u << 20));
#endif
}

TEST_CASE("the CLI prints a recomputed kept file as one warning line, exit 0, the same output bytes",
          "[floating][clusterer][kept]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  REQUIRE(system(("mkdir " + q(d.file("kept")) + " " + q(d.file("fresh"))).c_str()) == 0);
  auto simplify = [&](const std::string& out, const std::string& tmp, const std::string& keep) {
    return run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file(out)) + " --grid 64 --tmp " +
                   q(d.file(tmp)) + keep);
  };
  REQUIRE(simplify("fresh.ply", "fresh", "").exit_code == 0);
  REQUIRE(simplify("first.ply", "kept", " --keep-tmp").exit_code == 0);
  std::vector<std::string> kept = KeptFolder::ScratchDirNames(d.file("kept"));
  auto vertices = std::find_if(kept.begin(), kept.end(), [](const std::string& n) {
    return n.size() > 9 && n.compare(n.size() - 9, 9, ".vertices") == 0;
  });
  REQUIRE(vertices != kept.end());
  const std::string path = d.file("kept/" + *vertices);
  REQUIRE(unlink(path.c_str()) == 0);
  CliResult r = simplify("again.ply", "kept", " --keep-tmp");
  CHECK(r.exit_code == 0);
  CHECK(r.err == "oocsimp: warning: " + path + ": kept file missing; binning again\n");
  CHECK(read_file(d.file("again.ply")) == read_file(d.file("fresh.ply")));
  CHECK(read_file(d.file("first.ply")) == read_file(d.file("fresh.ply")));
}

namespace {

using PositionPair = std::array<double, 6>;

// The edges of a mesh as position pairs (each pair in ascending order), with the
// number of faces on each: comparable between meshes numbered differently.
std::map<PositionPair, int> edge_faces(const std::vector<double>& positions, const std::vector<std::uint64_t>& tris) {
  std::map<PositionPair, int> out;
  for (std::size_t t = 0; t < tris.size(); t += 3)
    for (std::size_t k = 0; k < 3; ++k) {
      const double* a = &positions[3 * tris[t + k]];
      const double* b = &positions[3 * tris[t + (k + 1) % 3]];
      std::array<double, 3> p{a[0], a[1], a[2]}, q{b[0], b[1], b[2]};
      if (q < p) std::swap(p, q);
      ++out[{p[0], p[1], p[2], q[0], q[1], q[2]}];
    }
  return out;
}

std::map<PositionPair, int> edge_faces(const SimplifiedMesh& m) {
  return edge_faces(m.positions, std::vector<std::uint64_t>(m.triangles.begin(), m.triangles.end()));
}

}  // namespace

TEST_CASE("floating cells with a locked boundary keep every boundary vertex and edge, for any tiling",
          "[floating][locks]") {
  ScratchDir d;
  GenerateOptions g;
  g.shape = SyntheticShape::terrain;
  g.triangles = 100000;
  generate_mesh(d.file("t.ply"), g);
  const LoadedMesh input = load_mesh(d.file("t.ply"));
  std::vector<PositionPair> outline;
  for (const auto& [edge, faces] : edge_faces(input.positions, input.triangles))
    if (faces == 1) outline.push_back(edge);
  REQUIRE(outline.size() > 500);
  const auto run = [&](double tile, unsigned threads, std::uint64_t target, SimplifyStats* st) {
    MeshInput in = open_mesh_input(d.file("t.ply"));
    SimplifyOptions o;
    o.method = ClusterMethod::floating;
    if (target) {
      o.target.triangles = target;
    } else {
      o.sizing.grid = 48;
    }
    o.floating.tile_side = tile;
    o.threads = threads;
    o.lock_boundary = true;
    return simplify(in, o, st);
  };
  SimplifyStats st;
  const SimplifiedMesh whole = run(0, 2, 0, &st);
  // Each boundary edge's triangle keeps its two locked ends and a third cluster: the
  // edge stays, with its one face, and the rest is simplified.
  const auto kept = edge_faces(whole);
  std::size_t found = 0;
  for (const PositionPair& e : outline) {
    const auto at = kept.find(e);
    found += at != kept.end() && at->second == 1;
  }
  CHECK(found == outline.size());
  CHECK(whole.triangles.size() / 3 < input.triangle_count() / 4);
  for (const std::string& w : st.warnings) CHECK(w.find("locked vertices are left out") == std::string::npos);
  // The same bytes for tiles of 2.5 cells (the outline crosses many) and one thread.
  SimplifyStats tiled_stats;
  const SimplifiedMesh tiled = run(2.5 * st.cell_size, 1, 0, &tiled_stats);
  CHECK(tiled_stats.floating.tiles > 20);
  CHECK(tiled.positions == whole.positions);
  CHECK(tiled.triangles == whole.triangles);
  // With a target, the edge collapse holds the boundary; a floating phase 1 would
  // leave tears that the collapse would hold too: refused.
  SimplifyStats target_stats;
  CHECK_THROWS_WITH(run(0, 2, 3000, &target_stats), Catch::Contains("not by a floating phase 1"));
  // Without the lock the outline is simplified too.
  MeshInput in = open_mesh_input(d.file("t.ply"));
  SimplifyOptions free_outline;
  free_outline.method = ClusterMethod::floating;
  free_outline.sizing.grid = 48;
  const auto free_edges = edge_faces(simplify(in, free_outline, nullptr));
  found = 0;
  for (const PositionPair& e : outline) found += free_edges.count(e);
  CHECK(found < outline.size() / 2);
  // With listed locked vertices too (the two locks applied one after the other): the
  // outline and every listed vertex stay.
  MeshInput both = open_mesh_input(d.file("t.ply"));
  SimplifyOptions both_locks;
  both_locks.method = ClusterMethod::floating;
  both_locks.sizing.grid = 48;
  both_locks.lock_boundary = true;
  std::set<std::array<double, 3>> listed;
  for (std::uint64_t v = 3; v < input.vertex_count(); v += 499) {
    both_locks.locked_vertices.push_back(v);
    listed.insert({input.positions[3 * v], input.positions[3 * v + 1], input.positions[3 * v + 2]});
  }
  SimplifyStats both_stats;
  const SimplifiedMesh held = simplify(both, both_locks, &both_stats);
  const auto held_edges = edge_faces(held);
  found = 0;
  for (const PositionPair& e : outline) found += held_edges.count(e);
  CHECK(found == outline.size());
  std::size_t left_out = 0, at_listed = 0;
  for (const std::string& w : both_stats.warnings)
    if (w.find(" locked vertices are left out") != std::string::npos) left_out = std::stoul(w);
  for (std::size_t v = 0; v < held.positions.size() / 3; ++v)
    at_listed += listed.count({held.positions[3 * v], held.positions[3 * v + 1], held.positions[3 * v + 2]});
  CHECK(at_listed + left_out >= listed.size());
  CHECK(left_out < listed.size() / 4);
  // The uniform grid and curvature cells cannot find the boundary: refused, naming
  // the option.
  for (ClusterMethod method : {ClusterMethod::uniform, ClusterMethod::curvature}) {
    MeshInput again = open_mesh_input(d.file("t.ply"));
    free_outline.method = method;
    free_outline.lock_boundary = true;
    CHECK_THROWS_WITH(simplify(again, free_outline, nullptr), Catch::Contains("options.lock_boundary"));
  }
}
