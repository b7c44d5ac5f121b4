// Tests of write_mesh() and format_for_path(): every format round-trips exactly
// through the readers, and writing is atomic (temporary name, then rename).
#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "oocsimp/error.hpp"
#include "oocsimp/mesh_input.hpp"
#include "oocsimp/mesh_writer.hpp"
#include "test_support.hpp"

using oocsimp::MeshFormat;
using oocsimp::format_for_path;
using oocsimp::write_mesh;
using oocsimp_test::LoadedMesh;
using oocsimp_test::load_mesh;
using oocsimp_test::ScratchDir;
using Catch::Matchers::StartsWith;

namespace {

// Values that need every digit of the shortest representation, tiny, huge and
// negative ones, and one subnormal.
const std::vector<float> kPositions = {
    0.1f,     -3.25e7f, 1e-20f,                                 //
    1.0f,     2.0f,     3.0f,                                   //
    -0.3f,    1.0f / 3.0f, 16777217.0f,                         //
    std::numeric_limits<float>::max(), -std::numeric_limits<float>::min(), 1e-40f,  //
    123.456f, -7.0e-8f, 9.999999e9f};
const std::vector<std::uint32_t> kTriangles = {0, 1, 2, 2, 1, 3, 4, 0, 3, 1, 4, 2};

std::vector<double> as_doubles(const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); }
std::vector<std::uint64_t> as_u64(const std::vector<std::uint32_t>& v) {
  return std::vector<std::uint64_t>(v.begin(), v.end());
}

// Writes `positions`/`triangles` to dir/name in `format`, reads the file back and
// checks exact equality and that nothing but the output is left in the folder.
LoadedMesh round_trip(const std::string& name, MeshFormat format, const std::string& expected_format,
                      const std::vector<float>& positions = kPositions,
                      const std::vector<std::uint32_t>& triangles = kTriangles) {
  ScratchDir dir, tmp;
  std::string path = dir.file(name);
  write_mesh(path, positions, triangles, format);
  CHECK(dir.entries() == std::vector<std::string>{name});
  LoadedMesh m = load_mesh(path, tmp.path());
  CHECK(m.info.format == expected_format);
  CHECK(m.info.compressed == (name.size() > 4 && name.compare(name.size() - 4, 4, ".zst") == 0));
  CHECK(m.info.vertex_count == positions.size() / 3);
  CHECK(m.info.face_count == triangles.size() / 3);
  CHECK(m.positions == as_doubles(positions));
  CHECK(m.triangles == as_u64(triangles));
  CHECK(m.skipped_faces == 0);
  return m;
}

}  // namespace

TEST_CASE("write_mesh binary PLY round trip is exact", "[writers]") {
  LoadedMesh m = round_trip("out.ply", MeshFormat::ply_binary, "ply binary_little_endian");
  CHECK(m.info.positions_in_place);
  CHECK(m.info.elements == std::vector<std::string>{"vertex 5 (x float, y float, z float)",
                                                    "face 4 (vertex_indices list uchar uint)"});
}

TEST_CASE("write_mesh ascii PLY round trip is exact", "[writers]") {
  round_trip("out.ply", MeshFormat::ply_ascii, "ply ascii");
}

TEST_CASE("write_mesh OBJ round trip is exact", "[writers]") {
  round_trip("out.obj", MeshFormat::obj, "obj");
}

TEST_CASE("write_mesh zstd-compressed binary PLY round trip is exact", "[writers]") {
  round_trip("out.ply.zst", MeshFormat::ply_binary, "ply binary_little_endian");
}

TEST_CASE("write_mesh zstd-compressed ascii PLY round trip is exact", "[writers]") {
  round_trip("out.ply.zst", MeshFormat::ply_ascii, "ply ascii");
}

TEST_CASE("write_mesh zstd-compressed OBJ round trip is exact", "[writers]") {
  round_trip("out.obj.zst", MeshFormat::obj, "obj");
}

TEST_CASE("write_mesh round trip of a mesh larger than the write buffer", "[writers]") {
  // Over a megabyte of output in every format, with float values spread over the
  // whole finite range (deterministic bit patterns).
  std::vector<float> pos;
  std::uint32_t state = 12345;
  const std::size_t n = 60000;
  while (pos.size() < 3 * n) {
    state = state * 1664525u + 1013904223u;
    std::uint32_t bits = state;
    float f;
    std::memcpy(&f, &bits, 4);
    if (std::isfinite(f)) pos.push_back(f);
  }
  std::vector<std::uint32_t> tri;
  for (std::uint32_t i = 0; i + 2 < n; ++i) tri.insert(tri.end(), {i, std::uint32_t(n - 1 - i), i + 2});
  struct Case {
    const char* name;
    MeshFormat format;
    const char* expected;
  };
  const Case cases[] = {{"big.ply", MeshFormat::ply_binary, "ply binary_little_endian"},
                        {"big.ply", MeshFormat::ply_ascii, "ply ascii"},
                        {"big.obj", MeshFormat::obj, "obj"},
                        {"big.ply.zst", MeshFormat::ply_binary, "ply binary_little_endian"},
                        {"big.ply.zst", MeshFormat::ply_ascii, "ply ascii"},
                        {"big.obj.zst", MeshFormat::obj, "obj"}};
  for (const Case& c : cases) {
    CAPTURE(c.name, c.expected);
    round_trip(c.name, c.format, c.expected, pos, tri);
  }
}

TEST_CASE("write_mesh of an empty mesh reads back empty", "[writers]") {
  const std::vector<float> no_positions;
  const std::vector<std::uint32_t> no_triangles;
  round_trip("empty.ply", MeshFormat::ply_binary, "ply binary_little_endian", no_positions, no_triangles);
  round_trip("empty.ply", MeshFormat::ply_ascii, "ply ascii", no_positions, no_triangles);
  round_trip("empty.obj", MeshFormat::obj, "obj", no_positions, no_triangles);
  round_trip("empty.obj.zst", MeshFormat::obj, "obj", no_positions, no_triangles);
}

TEST_CASE("write_mesh replaces an existing file and leaves no temporary file", "[writers]") {
  ScratchDir dir, tmp;
  std::string path = dir.file("out.obj");
  oocsimp_test::write_file(path, "old content\n");
  write_mesh(path, kPositions, kTriangles, MeshFormat::obj);
  CHECK(dir.entries() == std::vector<std::string>{"out.obj"});
  write_mesh(path, {1, 2, 3, 4, 5, 6, 7, 8, 9}, {2, 1, 0}, MeshFormat::obj);
  CHECK(dir.entries() == std::vector<std::string>{"out.obj"});
  LoadedMesh m = load_mesh(path, tmp.path());
  CHECK(m.positions == std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9});
  CHECK(m.triangles == std::vector<std::uint64_t>{2, 1, 0});
}

TEST_CASE("write_mesh into a nonexistent directory throws IoError and leaves no file", "[writers]") {
  ScratchDir dir;
  std::string path = dir.file("missing/sub/out.ply");
  SECTION("binary PLY") {
    CHECK_THROWS_AS(write_mesh(path, kPositions, kTriangles, MeshFormat::ply_binary), oocsimp::IoError);
  }
  SECTION("compressed OBJ") {
    path = dir.file("missing/out.obj.zst");
    CHECK_THROWS_AS(write_mesh(path, kPositions, kTriangles, MeshFormat::obj), oocsimp::IoError);
  }
  CHECK_FALSE(oocsimp_test::file_exists(path));
  CHECK(dir.entries().empty());
}

TEST_CASE("write_mesh into a path that is a directory throws IoError", "[writers]") {
  ScratchDir dir;
  std::string path = dir.file("taken");
  REQUIRE(::mkdir(path.c_str(), 0755) == 0);
  CHECK_THROWS_AS(write_mesh(path, kPositions, kTriangles, MeshFormat::ply_binary), oocsimp::IoError);
  CHECK(dir.entries() == std::vector<std::string>{"taken"});
}

TEST_CASE("format_for_path picks the format from the name", "[writers]") {
  CHECK(format_for_path("a.obj", false) == MeshFormat::obj);
  CHECK(format_for_path("a.obj", true) == MeshFormat::obj);
  CHECK(format_for_path("dir/a.OBJ", false) == MeshFormat::obj);
  CHECK(format_for_path("a.Obj", false) == MeshFormat::obj);
  CHECK(format_for_path("a.obj.zst", false) == MeshFormat::obj);
  CHECK(format_for_path("/tmp/x/a.obj.zst", true) == MeshFormat::obj);
  CHECK(format_for_path("a.ply", false) == MeshFormat::ply_binary);
  CHECK(format_for_path("a.ply", true) == MeshFormat::ply_ascii);
  CHECK(format_for_path("a.ply.zst", false) == MeshFormat::ply_binary);
  CHECK(format_for_path("a.ply.zst", true) == MeshFormat::ply_ascii);
  CHECK(format_for_path("a.stl", false) == MeshFormat::ply_binary);
  CHECK(format_for_path("noextension", true) == MeshFormat::ply_ascii);
  CHECK(format_for_path("obj", false) == MeshFormat::ply_binary);
  CHECK(format_for_path(".obj", false) == MeshFormat::obj);
  CHECK(format_for_path("a.obj.gz", false) == MeshFormat::ply_binary);
  CHECK(format_for_path("a.objx", false) == MeshFormat::ply_binary);
  CHECK(format_for_path("obj.ply", false) == MeshFormat::ply_binary);
  CHECK(format_for_path("", false) == MeshFormat::ply_binary);
  CHECK(format_for_path(".zst", true) == MeshFormat::ply_ascii);
}
