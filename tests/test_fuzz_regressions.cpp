// Inputs found by the fuzz targets (tests/fuzz/, scripts/fuzz.sh), kept byte for byte,
// each with the clean outcome it must now have.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

#include "oocsimp/error.hpp"
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

}  // namespace

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
