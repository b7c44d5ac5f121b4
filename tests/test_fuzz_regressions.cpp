// Inputs found by the fuzz targets (tests/fuzz/, scripts/fuzz.sh), kept byte for byte,
// each with the clean outcome it must now have.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <initializer_list>
#include <set>
#include <string>

#include "oocsimp/error.hpp"
#include "oocsimp/hierarchy.hpp"
#include "io/mesh_input.hpp"
#include "api/simplify.hpp"
#include "test_support.hpp"

using namespace oocsimp_test;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

std::string bytes(const char* s, std::size_t n) { return std::string(s, n); }

// fuzz_simplify: a binary PLY with double coordinates, vertex 1 at x = 1e300 (read in
// place at full precision). Simplifying it wrote a mesh with an infinite coordinate
// (the output is float), which no reader accepts back.
const char kDoubleBeyondFloat[] =
    "ply\n"
    "format binary_little_endian 1.0\n"
    "element vertex 3\n"
    "property double x\n"
    "property double y\n"
    "property double z\n"
    "element face 1\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x9c\x75\x00\x88\x3c\xe4\x37\x7e"
    "\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x9c\x75\x00\x88\x3c\xe4\x37\x7e"
    "\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x03"
    "\x00\x00\x00\x00"
    "\x01\x00\x00\x00"
    "\x02\x00\x00\x00";

// A binary PLY whose element "junk" (after the vertices, before the faces) declares
// 2^64 - 13 one-byte records, none of them present, and whose face data is missing
// too. Skipping "junk" computed its end as offset + size, which wrapped around 2^64 to
// 13 bytes back, so the face was read from the bytes of element "pad" and the file
// was accepted as a valid one-triangle mesh.
const char kSkipWraps[] =
    "ply\n"
    "format binary_little_endian 1.0\n"
    "element vertex 3\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "element pad 1\n"
    "property uchar a\n"
    "property int b\n"
    "property int c\n"
    "property int d\n"
    "element junk 18446744073709551603\n"
    "property uchar j\n"
    "element face 1\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00\x00\x00"
    "\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00"
    "\x03\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00";

// fuzz_hierarchy_build: a binary PLY with a vertex property named "re", 18 bytes
// 0xff and "d". It reads, and a hierarchy built from it kept the attribute under
// that name, which the .4k reader refuses: the file did not read back.
const char kAttributeNameBytes[] =
    "ply\n"
    "format binary_little_endian 1.0\n"
    "element vertex 4\n"
    "property double x\n"
    "property double y\n"
    "property double z\n"
    "property uchar re\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff"
    "\xff\xff\xff\xff"
    "d\n"
    "element face 4\n"
    "property list ushort uint vertex_indices\n"
    "end_header\n"
    "\x00\x00\x00\x00\x00\x00\n"
    "property double x\n"
    "property double y\n"
    "property double z\n"
    "p\x00\x00\xf0\x3f\x00\x00\x00\x00\x00\x00\x00\x00\x07\x00\x00\x00\x00\x00"
    "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\xf0"
    "\x3f\x07\x03\x00\x00\x00\x00\x00\x02\x00\x00\x00\x01\x00\x00\x00\x03\x00"
    "\x00\x00\x00\x00\x01\x00\x00\x00\x03\x00\x00\x00\x03\x00\x00\x00\x00\x00"
    "\x03\x00\x00\x00\x02\x00\x00\x00\x03\x00\x01\x00\x00\x00\x02\x00\x00\x00"
    "\x03\x00\x00\x00";
// fuzz_hierarchy_build (selector 0x05: OBJ, three sets a level): an open mesh of three
// pieces, with vertices split where fans met. The coarsest level with the middle
// quarter of the bounding box kept at the finest cut a piece in two: a boundary ear's
// removal was applied where its vertex still had faces that records the region held
// back would have taken first, so the ear's face went and left them hanging.
const char kEarOfAHeldBackVertex[] =
    "# oocsimp\n"
    "v 0.060325094 0.039231937 -0.04293877\n"
    "v 0.20635045 0.0391483 -0.062710054\n"
    "v 0.19824857 0.19723375 -0.120181136\n"
    "v 0.05663203 0.1476162 -0.08019341\n"
    "v 0.3490808 0.057044994 -0.085852526\n"
    "v 0.32028174 0.134268945 -0.02037757\n"
    "v 0.81967235 0.3880128 -0.022378359\n"
    "v 0.11740889 0.46492884 -0\n"
    "v 0.95533293 0.08142108 -0.15049906\n"
    "v 0.63688934 0.3593264 -0.069202475\n"
    "v 0.055853393 0.31939507 -0.12054578\n"
    "v 0.28492656 0.3687118 -0.13390948\n"
    "v 0.43084738 0.34268945 -0.02037757\n"
    "v 0.81967235 0.3880128 -0.022378359\n"
    "v 0.11740889 0.46492884 -0.094043165\n"
    "v 0.9362739 0.40034547 -0.05525742\n"
    "v 0.4229291 0.5031131 -0.018571021\n"
    "v 0.67614514 0.56460637 -0.060290333\n"
    "v 0.08638613 0.6113399 -0.047337282\n"
    "v 0.8130114 0.5871232 0.07153838\n"
    "v 0.5458155 0.67766297 -0.038512766\n"
    "v 0.9584374 0.56534326 0.047816068\n"
    "v 0.13006572 0.6748262 0.029871972\n"
    "v 0.9379628 0.7556733 0.11513137\n"
    "v 0.30129015 0.78387237 0.020430563\n"
    "v 0.639051 0.8271022 0.0068730074\n"
    "v 0.79099035 0.81859773 0.14878982\n"
    "v 0.12875067 0.8420211 0.13444892\n"
    "v 0.4604161 0.9134446 0.002649577\n"
    "v 0.25671223 0.9546937 0.04691508\n"
    "v 0.6287576 0.9706085 0.012915257\n"
    "v 0.9619451 0.95521593 0.11934523\n"
    "v 0.7975367 0.965895 0.12529927\n"
    "v 0.09165898 0.9544195 0.17421909\n"
    "f 1 2 3\n"
    "f 1 3 4\n"
    "f 2 5 6\n"
    "f 2 6 3\n"
    "f 7 8 9\n"
    "v 0.7373013 0.19844747 -0.075292654\n"
    "v 0.48387012 0.042744324 0.029411089\n"
    "v 0.46753702 0.18804482 -0.007967313\n"
    "v 0.9351043 0.2278945 -0.12595114\n"
    "v 0.95533293 0.08284216 -0.15049906\n"
    "v 0.63688934 0.3593264 -0.069202475\n"
    "v 0.055853393 0.31939507 -0.12054578\n"
    "v 0.28492656 0.3687118 -0.13390948\n"
    "v9\n"
    "f 14 9 18\n"
    "f 18 12 20\n"
    "f 16 17 21\n"
    "f 17 14 21\n"
    "f 14 18 22\n"
    "f 19 16 23\n"
    "f 16 21 23\n"
    "f 21 14 22\n"
    "f 18 24 22\n"
    "f 21 22 25\n"
    "f 18 20 24\n"
    "f 20 26 24\n"
    "f 19 23 27\n"
    "f 21 25 23\n"
    "f 24 26 28\n"
    "f 23 25 29\n"
    "f 27 23 29\n"
    "f 25 22 30\n"
    "f 22 24 31\n"
    "f 22 31 30\n"
    "f 24 28 31\n"
    "f 32 27 29\n"
    "c\x00\x00\x00\x00\x00\x00\x00"
    "f 29 25 33\n"
    "f 25 30 33\n"
    "f 32 29 34\n"
    "f 29 33 34\n"
    "f 33 30 35\n"
    "f 31 28 36\n"
    "f 31 36 37\n"
    "\\ 30 31 37\n"
    "f 30 37 35\n"
    "f 32 34 38\n";

}  // namespace

TEST_CASE("fuzz: a hierarchy is not built with an attribute name its file cannot hold", "[fuzz][hierarchy]") {
  ScratchDir d;
  const std::string in = d.file("names.ply"), out = d.file("names.4k");
  write_file(in, bytes(kAttributeNameBytes, sizeof kAttributeNameBytes - 1));
  std::string msg;
  try {
    oocsimp::build_hierarchy_file(in, out, {});
  } catch (const oocsimp::InputError& e) {
    msg = e.what();
  }
  CHECK_THAT(msg, StartsWith(in + ": the vertex attribute") && Contains("--attributes"));
  CHECK_FALSE(file_exists(out));
  oocsimp::HierarchyOptions none;
  none.attributes.mode = oocsimp::AttributeSelection::Mode::none;
  oocsimp::build_hierarchy_file(in, out, none);
  CHECK(oocsimp::read_hierarchy(out).levels.size() >= 1);
}

TEST_CASE("fuzz: a region keeps the finest level's topology where a boundary ear's vertex has faces held back",
          "[fuzz][hierarchy]") {
  ScratchDir d;
  const std::string in = d.file("ears.obj"), out = d.file("ears.4k");
  write_file(in, bytes(kEarOfAHeldBackVertex, sizeof kEarOfAHeldBackVertex - 1));
  oocsimp::build_hierarchy_file(in, out, {});
  const oocsimp::MeshHierarchy h = oocsimp::read_hierarchy(out);
  REQUIRE(h.levels.size() == 2);
  oocsimp::HierarchyQuery q;
  q.level = 0;
  const oocsimp::SimplifiedMesh finest = oocsimp::extract_mesh(h, q);
  oocsimp::Box3d bounds;
  for (std::size_t i = 0; i < finest.positions.size(); i += 3)
    bounds.add(oocsimp::Vec3d{finest.positions[i], finest.positions[i + 1], finest.positions[i + 2]});
  // The middle quarter of the box, each way.
  auto at = [&](double t) {
    return oocsimp::Vec3d{bounds.min.x + t * (bounds.max.x - bounds.min.x),
                          bounds.min.y + t * (bounds.max.y - bounds.min.y),
                          bounds.min.z + t * (bounds.max.z - bounds.min.z)};
  };
  q.level = 1;
  q.region = oocsimp::HierarchyQuery::Region::box;
  q.box.add(at(0.25));
  q.box.add(at(0.75));
  const oocsimp::SimplifiedMesh region = oocsimp::extract_mesh(h, q);
  const std::vector<std::uint32_t> fine(finest.triangles.begin(), finest.triangles.end()),
      mixed(region.triangles.begin(), region.triangles.end());
  const Topology before = topology(finest.positions, fine), after = topology(region.positions, mixed);
  CHECK(before.euler() == 3);
  CHECK(after.euler() == before.euler());
  CHECK(after.manifold);
  CHECK(after.boundary_loops == before.boundary_loops);
}

TEST_CASE("fuzz: a PLY element whose size wraps the skip past 2^64 is a truncated file", "[fuzz][readers]") {
  ScratchDir d;
  const std::string content = bytes(kSkipWraps, sizeof kSkipWraps - 1);
  REQUIRE(content.size() == 345);
  SECTION("plain") {
    std::string path = d.file("wrap.ply");
    write_file(path, content);
    std::string msg;
    try {
      load_mesh(path, d.path());
    } catch (const oocsimp::InputError& e) {
      msg = e.what();
    }
    CHECK_THAT(msg, StartsWith(path + ": byte 345: unexpected end of file"));
    CHECK_THAT(msg, Contains("\"junk\""));
  }
  SECTION("zstd-compressed: the same outcome") {
    std::string path = d.file("wrap.ply.zst");
    write_zstd_file(path, content);
    CHECK_THROWS_AS(load_mesh(path, d.path()), oocsimp::InputError);
  }
}

TEST_CASE("fuzz: double PLY coordinates beyond the float range are rejected by simplify", "[fuzz][simplify]") {
  ScratchDir d;
  std::string path = d.file("big.ply");
  write_file(path, bytes(kDoubleBeyondFloat, sizeof kDoubleBeyondFloat - 1));
  oocsimp::OpenOptions oo;
  oo.temp_dir = d.path();
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, oo);  // the reader keeps full precision
  REQUIRE(in.info.positions_in_place);
  REQUIRE(in.info.bounds.max.x == 1e300);
  oocsimp::SimplifyOptions o;
  o.threads = 1;
  o.temp_dir = d.path();
  SECTION("uniform") {
    o.method = oocsimp::ClusterMethod::uniform;
    o.sizing.grid = 8;
  }
  SECTION("floating") {
    o.method = oocsimp::ClusterMethod::floating;
    o.sizing.cell = in.info.bounds.diagonal() / 8;
    o.memory_budget = 64u << 20;
  }
  try {
    oocsimp::simplify(in, o, nullptr);
    FAIL("no InputError was thrown");
  } catch (const oocsimp::InputError& e) {
    CHECK_THAT(e.what(), StartsWith(path + ": vertex 1 "));
    CHECK_THAT(e.what(), Contains("float range"));
  }
}

namespace {

// Simplifies the kept input `name` (tests/fuzz/regressions/) of `faces` faces to each
// target with the edge collapse, as fuzz_simplify does, and checks what it checks:
// the count, indices in range, no degenerate face, no repeat of three vertices the
// input lacks (the collapse keeps what it is given).
void check_collapses_of(const std::string& name, std::uint64_t faces, std::initializer_list<std::uint64_t> targets) {
  ScratchDir d;
  const std::string path = std::string(OOCSIMP_SOURCE_DIR) + "/tests/fuzz/regressions/" + name;
  oocsimp::OpenOptions oo;
  oo.temp_dir = d.path();
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, oo);
  REQUIRE(in.info.face_count == faces);
  std::uint64_t input_repeats = 0;
  {
    std::set<std::array<std::uint64_t, 3>> seen;
    std::uint64_t buf[3 * 64];
    for (std::size_t n; (n = in.triangles->read(buf, 64)) != 0;)
      for (std::size_t t = 0; t < n; ++t) {
        std::array<std::uint64_t, 3> k = {buf[3 * t], buf[3 * t + 1], buf[3 * t + 2]};
        std::sort(k.begin(), k.end());
        input_repeats += !seen.insert(k).second;
      }
    in.restart_triangles();
  }
  for (const std::uint64_t target : targets) {
    INFO(name << " to " << target);
    oocsimp::SimplifyOptions o;
    o.target.triangles = target;
    o.threads = 1;
    o.temp_dir = d.path();
    const oocsimp::SimplifiedMesh m = oocsimp::simplify(in, o, nullptr);
    REQUIRE(m.triangles.size() == 3 * target);
    const std::size_t vertices = m.positions.size() / 3;
    std::set<std::array<std::uint32_t, 3>> seen;
    bool bad = false;
    std::uint64_t repeats = 0;
    for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
      std::array<std::uint32_t, 3> k = {m.triangles[t], m.triangles[t + 1], m.triangles[t + 2]};
      std::sort(k.begin(), k.end());
      bad = bad || k[2] >= vertices || k[0] == k[1] || k[1] == k[2];
      repeats += !seen.insert(k).second;
    }
    CHECK_FALSE(bad);
    CHECK(repeats <= input_repeats);
  }
}

}  // namespace

// fuzz_simplify's two slow inputs of 2026-12-08, each kept without the target's
// selector byte. Each took over the target's 10 s (21-26 s of CPU under the fuzz
// build) because a check of each edge tried at a vertex of a thousand faces listed
// and sorted that vertex's neighbours or walked its faces; the checks now walk the
// other end (docs/design.md, "The collapse in core", Hubs). Their time is not asserted
// here: this is the outcome the fuzz target checks.
TEST_CASE("fuzz: a vertex with a thousand faces in hundreds of fans collapses to each target", "[fuzz][simplify]") {
  // A binary STL of 1302 faces, 1018 of them at one vertex in hundreds of separate
  // fans (non-manifold, anchored), every collapse of cost 0.
  check_collapses_of("simplify-nonmanifold-hub.stl", 1302, {651, 325});
}

TEST_CASE("fuzz: a manifold vertex of many faces collapses to each target", "[fuzz][simplify]") {
  // A binary PLY of 2048 faces, the generator's 33 x 33 grid mutated (coordinates up
  // to 1.7e38), whose collapse gathers many faces at some vertex: each edge tried there
  // listed and sorted its neighbours for the link condition.
  check_collapses_of("simplify-manifold-hub.ply", 2048, {1024, 512});
}

TEST_CASE("fuzz: the CLI exits 3 on double coordinates beyond the float range", "[fuzz][cli]") {
  ScratchDir d;
  std::string path = d.file("big.ply");
  write_file(path, bytes(kDoubleBeyondFloat, sizeof kDoubleBeyondFloat - 1));
  CliResult r =
      run_cli("simplify --quiet '" + path + "' -o '" + d.file("out.ply") + "' --grid 4 --tmp '" + d.path() + "'");
  INFO(r.err);
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Contains("float range"));
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_FALSE(file_exists(d.file("out.ply")));
}

TEST_CASE("fuzz: the same bytes zstd-compressed are kept as double when converted and rejected by simplify",
          "[fuzz][readers]") {
  ScratchDir d;
  std::string path = d.file("big.ply.zst");
  write_zstd_file(path, bytes(kDoubleBeyondFloat, sizeof kDoubleBeyondFloat - 1));
  oocsimp::OpenOptions oo;
  oo.temp_dir = d.path();
  // Converted, the coordinates are kept as double, as when read in place; simplify
  // then refuses them like the uncompressed file's.
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, oo);
  CHECK(in.info.bounds.max.x == 1e300);
  oocsimp::SimplifyOptions o;
  o.threads = 1;
  o.temp_dir = d.path();
  o.method = oocsimp::ClusterMethod::uniform;
  o.sizing.grid = 8;
  CHECK_THROWS_AS(oocsimp::simplify(in, o, nullptr), oocsimp::InputError);
}
