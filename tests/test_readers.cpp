// Tests of the streaming mesh readers (PLY, OBJ, STL, each optionally zstd-compressed)
// through the public open_mesh_input() API. Every input is written by the test itself
// into a scratch folder.
#include <catch2/catch.hpp>
#include <zlib.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "io/attribute_array.hpp"
#include "io/error_text.hpp"
#include "io/face_range.hpp"
#include "oocsimp/error.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using oocsimp_test::load_mesh;
using oocsimp_test::LoadedMesh;
using oocsimp_test::put_be;
using oocsimp_test::put_le;
using oocsimp_test::ScratchDir;
using oocsimp_test::write_file;
using oocsimp_test::write_zstd_file;

namespace {

// The reference mesh used by most tests: five vertices, one quad and one triangle.
const std::vector<float> kPos = {0.0f,  0.0f, 0.0f,   1.5f,     -2.25f, 0.1f, -3.25e7f, 1e-20f,
                                 42.0f, 7.5f, 8.125f, -9.0625f, 100.0f, 0.2f, -0.3f};
// The same coordinates as text, one vertex per entry.
const char* const kPosText[5] = {"0 0 0", "1.5 -2.25 0.1", "-3.25e7 1e-20 42", "7.5 8.125 -9.0625", "100 0.2 -0.3"};
const std::vector<std::vector<int>> kFaces = {{0, 1, 2, 3}, {1, 4, 2}};
// kFaces fanned into triangles.
const std::vector<std::uint64_t> kTris = {0, 1, 2, 0, 2, 3, 1, 4, 2};

std::vector<double> as_doubles(const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); }

const std::vector<double> kPosD = as_doubles(kPos);
// kPosText as formats without a declared type (OBJ, ascii STL) read it: its numbers
// have no more digits than a float keeps, so the floats nearest them (kPos).
const std::vector<double> kTextD = kPosD;

template <class T>
void put(std::string& s, T v, bool big_endian) {
  if (big_endian)
    put_be(s, v);
  else
    put_le(s, v);
}

// Appends integer `v` stored as the PLY scalar type `type`.
void put_typed(std::string& s, const std::string& type, long long v, bool be) {
  if (type == "char")
    put(s, std::int8_t(v), be);
  else if (type == "uchar")
    put(s, std::uint8_t(v), be);
  else if (type == "short")
    put(s, std::int16_t(v), be);
  else if (type == "ushort")
    put(s, std::uint16_t(v), be);
  else if (type == "int")
    put(s, std::int32_t(v), be);
  else if (type == "uint")
    put(s, std::uint32_t(v), be);
  else
    FAIL("bad type " << type);
}

const char* format_line(bool big_endian) {
  return big_endian ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n";
}

const char* const kXyzFloat = "property float x\nproperty float y\nproperty float z\n";

// The reference mesh as ascii PLY (10 header lines, vertices on lines 11-15, faces on 16-17).
std::string ascii_ply() {
  std::string s = "ply\nformat ascii 1.0\ncomment reference mesh\nelement vertex 5\n";
  s += kXyzFloat;
  s += "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (const char* v : kPosText) s += std::string(v) + "\n";
  s += "4 0 1 2 3\n3 1 4 2\n";
  return s;
}

// The reference mesh as binary PLY with float x,y,z and "list uchar int" faces.
std::string binary_ply_header(bool be, std::uint64_t vertices = 5, std::uint64_t faces = 2) {
  return std::string("ply\n") + format_line(be) + "element vertex " + std::to_string(vertices) + "\n" + kXyzFloat +
         "element face " + std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

void put_faces(std::string& s, const std::vector<std::vector<int>>& faces, bool be) {
  for (const auto& f : faces) {
    s.push_back(char(f.size()));
    for (int i : f) put(s, std::int32_t(i), be);
  }
}

std::string binary_ply(bool be) {
  std::string s = binary_ply_header(be);
  for (float f : kPos) put(s, f, be);
  put_faces(s, kFaces, be);
  return s;
}

std::string obj_text() {
  std::string s = "# reference mesh\n";
  for (const char* v : kPosText) s += std::string("v ") + v + "\n";
  s += "f 1 2 3 4\nf 2 5 3\n";
  return s;
}

// Two triangles with corners kPos[0..2] and kPos[3..5] (vertex 5 of the second
// triangle is (1, 2, 3)).
const std::vector<float> kStlPos = {0.0f, 0.0f,   0.0f,     1.5f,   -2.25f, 0.1f,  -3.25e7f, 1e-20f, 42.0f,
                                    7.5f, 8.125f, -9.0625f, 100.0f, 0.2f,   -0.3f, 1.0f,     2.0f,   3.0f};
// The same as ascii STL text reads it: floats, as for kTextD.
const std::vector<double> kStlTextD = as_doubles(kStlPos);

std::string ascii_stl() {
  return "solid reference\n"
         "  facet normal 0 0 1\n"
         "    outer loop\n"
         "      vertex 0 0 0\n"
         "      vertex 1.5 -2.25 0.1\n"
         "      vertex -3.25e7 1e-20 42\n"
         "    endloop\n"
         "  endfacet\n"
         "  facet normal 0 0 -1\n"
         "    outer loop\n"
         "      vertex 7.5 8.125 -9.0625\n"
         "      vertex 100 0.2 -0.3\n"
         "      vertex 1 2 3\n"
         "    endloop\n"
         "  endfacet\n"
         "endsolid reference\n";
}

std::string binary_stl(const std::string& header_text, std::uint32_t declared, std::size_t triangles) {
  std::string s = header_text;
  s.resize(80, ' ');
  put_le(s, declared);
  for (std::size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) put_le(s, 0.0f);  // normal
    for (int k = 0; k < 9; ++k) put_le(s, kStlPos[(9 * t + std::size_t(k)) % kStlPos.size()]);
    put_le(s, std::uint16_t(0));  // attribute byte count
  }
  return s;
}

// Runs f, which must throw InputError, and returns its message.
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const oocsimp::InputError& e) {
    return e.what();
  }
  FAIL("no InputError was thrown");
  return {};
}

// The message of the InputError that loading `path` (positions and all triangles) throws.
std::string load_error(const std::string& path, const ScratchDir& tmp) {
  return input_error([&] { load_mesh(path, tmp.path()); });
}

// The message of the InputError that open_mesh_input itself throws.
std::string open_error(const std::string& path, const ScratchDir& tmp) {
  oocsimp::OpenOptions o;
  o.temp_dir = tmp.path();
  return input_error([&] { oocsimp::open_mesh_input(path, o); });
}

void check_same_mesh(const LoadedMesh& a, const LoadedMesh& b) {
  CHECK(a.positions == b.positions);
  CHECK(a.triangles == b.triangles);
  CHECK(a.info.format == b.info.format);
  CHECK(a.info.vertex_count == b.info.vertex_count);
  CHECK(a.info.face_count == b.info.face_count);
  CHECK(a.skipped_faces == b.skipped_faces);
}

}  // namespace

// ---------------------------------------------------------------------------------
// PLY

TEST_CASE("PLY ascii: positions fanned faces and info", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  write_file(path, ascii_ply());
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "ply ascii");
  CHECK_FALSE(m.info.compressed);
  CHECK_FALSE(m.info.positions_in_place);
  CHECK(m.info.path == path);
  CHECK(m.info.vertex_count == 5);
  CHECK(m.info.face_count == 2);
  CHECK(m.vertex_count() == 5);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
  CHECK(m.skipped_faces == 0);
  CHECK(m.info.elements ==
        std::vector<std::string>{"vertex 5 (x float, y float, z float)", "face 2 (vertex_indices list uchar int)"});
  CHECK(m.info.comments == std::vector<std::string>{"comment reference mesh"});
  CHECK(m.info.bounds.min.x == double(-3.25e7f));
  CHECK(m.info.bounds.max.x == 100.0);
  CHECK(m.info.bounds.min.y == -2.25);
  CHECK(m.info.bounds.max.y == double(8.125f));
  CHECK(m.info.bounds.min.z == -9.0625);
  CHECK(m.info.bounds.max.z == 42.0);
}

TEST_CASE("PLY binary_little_endian with float coordinates is read in place", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  write_file(path, binary_ply(false));
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "ply binary_little_endian");
  CHECK(m.info.positions_in_place);
  CHECK_FALSE(m.info.compressed);
  CHECK(m.info.vertex_count == 5);
  CHECK(m.info.face_count == 2);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
  // Read in place: no temporary position file.
  CHECK(dir.entries() == std::vector<std::string>{"mesh.ply"});
}

TEST_CASE("PLY binary_big_endian with float coordinates is read in place and byte-swapped", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  write_file(path, binary_ply(true));
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "ply binary_big_endian");
  CHECK(m.info.positions_in_place);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY binary with double coordinates is read in place at full precision", "[readers][ply]") {
  bool be = GENERATE(false, true);
  CAPTURE(be);
  // Values that a float cannot hold exactly.
  const std::vector<double> pos = {0.1, -1e-300, 123456789.123456789, 1e300, 2.0 / 3.0, -0.3, 5, 6, 7};
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = std::string("ply\n") + format_line(be) +
                  "element vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
                  "element face 1\nproperty list uchar uint vertex_indices\nend_header\n";
  for (double d : pos) put(s, d, be);
  s.push_back(3);
  for (std::uint32_t i : {2u, 0u, 1u}) put(s, i, be);
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == (be ? "ply binary_big_endian" : "ply binary_little_endian"));
  CHECK(m.info.positions_in_place);
  CHECK(m.positions == pos);
  CHECK(m.triangles == std::vector<std::uint64_t>{2, 0, 1});
  CHECK(m.info.bounds.max.x == 1e300);
  CHECK(m.info.bounds.min.y == -1e-300);
}

TEST_CASE("PLY binary with extra vertex properties around xyz is read in place", "[readers][ply]") {
  bool be = GENERATE(false, true);
  CAPTURE(be);
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = std::string("ply\n") + format_line(be) +
                  "element vertex 5\nproperty uchar red\nproperty float confidence\n" + kXyzFloat +
                  "property float nx\nproperty float ny\nproperty float nz\nproperty short flags\n"
                  "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (int v = 0; v < 5; ++v) {
    put(s, std::uint8_t(200 + v), be);
    put(s, 0.5f * float(v) - 7.0f, be);
    for (int k = 0; k < 3; ++k) put(s, kPos[std::size_t(3 * v + k)], be);
    for (int k = 0; k < 3; ++k) put(s, -1.0f - float(k), be);
    put(s, std::int16_t(-v), be);
  }
  put_faces(s, kFaces, be);
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.positions_in_place);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
  // Confidence values and normals (up to -7) must not leak into the bounds.
  CHECK(m.info.bounds.min.z == -9.0625);
  CHECK(m.info.bounds.min.y == -2.25);
}

TEST_CASE("PLY ascii with extra vertex properties around xyz", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = "ply\nformat ascii 1.0\nelement vertex 5\nproperty uchar red\nproperty float confidence\n" +
                  std::string(kXyzFloat) +
                  "property float nx\nproperty float ny\nproperty float nz\n"
                  "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (int v = 0; v < 5; ++v) s += std::to_string(200 + v) + " -1e30 " + kPosText[v] + " 0 0 1\n";
  s += "4 0 1 2 3\n3 1 4 2\n";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "ply ascii");
  CHECK_FALSE(m.info.positions_in_place);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY vertex element with a list property is converted and not read in place", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  SECTION("binary") {
    bool be = GENERATE(false, true);
    CAPTURE(be);
    std::string s = std::string("ply\n") + format_line(be) +
                    "element vertex 5\nproperty float x\nproperty list uchar int tags\nproperty float y\n"
                    "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
    for (int v = 0; v < 5; ++v) {
      put(s, kPos[std::size_t(3 * v)], be);
      s.push_back(char(v));  // v tags
      for (int t = 0; t < v; ++t) put(s, std::int32_t(1000 + t), be);
      put(s, kPos[std::size_t(3 * v + 1)], be);
      put(s, kPos[std::size_t(3 * v + 2)], be);
    }
    put_faces(s, kFaces, be);
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.info.format == (be ? "ply binary_big_endian" : "ply binary_little_endian"));
    CHECK_FALSE(m.info.positions_in_place);
    CHECK(m.positions == kPosD);
    CHECK(m.triangles == kTris);
  }
  SECTION("ascii") {
    std::string s =
        "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty list uchar int tags\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0 0\n1.5 1 7 -2.25 0.1\n-3.25e7 2 7 8 1e-20 42\n7.5 3 1 2 3 8.125 -9.0625\n100 0 0.2 -0.3\n"
        "4 0 1 2 3\n3 1 4 2\n";
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK_FALSE(m.info.positions_in_place);
    CHECK(m.positions == kPosD);
    CHECK(m.triangles == kTris);
  }
}

TEST_CASE("PLY binary face list count and index types", "[readers][ply]") {
  std::string count_type = GENERATE(as<std::string>{}, "uchar", "ushort", "uint", "int", "char", "short");
  std::string index_type = GENERATE(as<std::string>{}, "int", "uint");
  bool be = GENERATE(false, true);
  CAPTURE(count_type, index_type, be);
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = std::string("ply\n") + format_line(be) + "element vertex 5\n" + kXyzFloat +
                  "element face 2\nproperty list " + count_type + " " + index_type + " vertex_indices\nend_header\n";
  for (float f : kPos) put(s, f, be);
  for (const auto& f : kFaces) {
    put_typed(s, count_type, static_cast<long long>(f.size()), be);
    for (int i : f) put_typed(s, index_type, i, be);
  }
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.positions_in_place);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY face element with other properties and the vertex_index name", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = std::string("ply\n") + format_line(false) + "element vertex 5\n" + kXyzFloat +
                  "element face 2\nproperty uchar flags\nproperty list uchar float texcoord\n"
                  "property list ushort uint vertex_index\nproperty int material\nend_header\n";
  for (float f : kPos) put_le(s, f);
  for (const auto& f : kFaces) {
    put_le(s, std::uint8_t(9));
    put_le(s, std::uint8_t(2));
    put_le(s, 0.25f);
    put_le(s, 0.75f);
    put_le(s, std::uint16_t(f.size()));
    for (int i : f) put_le(s, std::uint32_t(i));
    put_le(s, std::int32_t(-5));
  }
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY quads and pentagons are fanned into (v0 vi vi+1) triangles", "[readers][ply]") {
  ScratchDir dir;
  const std::vector<std::vector<int>> faces = {{4, 3, 2, 1, 0}, {1, 2, 3, 4}, {0, 2, 4}, {3, 0, 1, 4, 2}};
  const std::vector<std::uint64_t> tris = {4, 3, 2, 4, 2, 1, 4, 1, 0,  // pentagon
                                           1, 2, 3, 1, 3, 4,           // quad
                                           0, 2, 4,                    // triangle
                                           3, 0, 1, 3, 1, 4, 3, 4, 2};
  SECTION("binary") {
    std::string path = dir.file("binary.ply");
    std::string s = binary_ply_header(false, 5, 4);
    for (float f : kPos) put_le(s, f);
    put_faces(s, faces, false);
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.info.face_count == 4);
    CHECK(m.triangles == tris);
  }
  SECTION("ascii") {
    std::string path = dir.file("ascii.ply");
    std::string s = "ply\nformat ascii 1.0\nelement vertex 5\n" + std::string(kXyzFloat) +
                    "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
    for (const char* v : kPosText) s += std::string(v) + "\n";
    s += "5 4 3 2 1 0\n4 1 2 3 4\n3 0 2 4\n5 3 0 1 4 2\n";
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.triangles == tris);
  }
}

TEST_CASE("PLY extra elements before and between and after vertex and face are skipped", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  SECTION("binary, fixed-size element before the vertices (still in place)") {
    bool be = GENERATE(false, true);
    CAPTURE(be);
    std::string s = std::string("ply\n") + format_line(be) +
                    "element camera 1\nproperty double fx\nproperty uchar id\n"
                    "element vertex 5\n" +
                    kXyzFloat +
                    "element edge 2\nproperty int vertex1\nproperty int vertex2\n"
                    "element face 2\nproperty list uchar int vertex_indices\n"
                    "element material 2\nproperty uchar ambient_red\nproperty list uchar float coefficients\n"
                    "end_header\n";
    put(s, 1234.5, be);
    put(s, std::uint8_t(7), be);
    for (float f : kPos) put(s, f, be);
    for (int e = 0; e < 2; ++e) {
      put(s, std::int32_t(e), be);
      put(s, std::int32_t(e + 1), be);
    }
    put_faces(s, kFaces, be);
    for (int k = 0; k < 2; ++k) {
      put(s, std::uint8_t(k), be);
      put(s, std::uint8_t(k + 1), be);
      for (int j = 0; j <= k; ++j) put(s, 0.5f, be);
    }
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.info.positions_in_place);
    CHECK(m.info.vertex_count == 5);
    CHECK(m.info.face_count == 2);
    CHECK(m.info.elements.size() == 5);
    CHECK(m.positions == kPosD);
    CHECK(m.triangles == kTris);
  }
  SECTION("binary, variable-size element before the vertices (converted)") {
    std::string s = std::string("ply\n") + format_line(false) +
                    "element header_info 2\nproperty list uchar uchar text\n"
                    "element vertex 5\n" +
                    kXyzFloat +
                    "element edge 2\nproperty int vertex1\nproperty int vertex2\n"
                    "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
    s += std::string(
        "\x03"
        "abc"
        "\x01"
        "z",
        6);
    for (float f : kPos) put_le(s, f);
    for (int e = 0; e < 4; ++e) put_le(s, std::int32_t(e));
    put_faces(s, kFaces, false);
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK_FALSE(m.info.positions_in_place);
    CHECK(m.positions == kPosD);
    CHECK(m.triangles == kTris);
  }
  SECTION("ascii") {
    std::string s = "ply\nformat ascii 1.0\nelement camera 1\nproperty float f\nelement vertex 5\n" +
                    std::string(kXyzFloat) +
                    "element edge 2\nproperty int vertex1\nproperty int vertex2\n"
                    "element face 2\nproperty list uchar int vertex_indices\n"
                    "element material 1\nproperty list uchar float coefficients\nproperty uchar id\nend_header\n"
                    "35.5\n";
    for (const char* v : kPosText) s += std::string(v) + "\n";
    s += "0 1\n1 2\n4 0 1 2 3\n3 1 4 2\n3 0.5 0.25 0.125 9\n";
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.positions == kPosD);
    CHECK(m.triangles == kTris);
  }
}

TEST_CASE("PLY without a face element has positions and no triangles", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("points.ply");
  std::string s = std::string("ply\n") + format_line(false) + "element vertex 5\n" + kXyzFloat + "end_header\n";
  for (float f : kPos) put_le(s, f);
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.face_count == 0);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles.empty());
}

TEST_CASE("PLY face element before the vertex element", "[readers][ply]") {
  bool be = GENERATE(false, true);
  CAPTURE(be);
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = std::string("ply\n") + format_line(be) +
                  "element face 2\nproperty list uchar int vertex_indices\nelement vertex 5\n" + kXyzFloat +
                  "end_header\n";
  put_faces(s, kFaces, be);
  for (float f : kPos) put(s, f, be);
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK_FALSE(m.info.positions_in_place);  // the face records have variable size
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY comment and obj_info lines are reported and otherwise ignored", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = std::string("ply\ncomment first line\n") + format_line(false) +
                  "obj_info scanner 3 v1.2\nelement vertex 5\ncomment between element and property\n" + kXyzFloat +
                  "comment\nelement face 2\nproperty list uchar int vertex_indices\ncomment last one\nend_header\n";
  for (float f : kPos) put_le(s, f);
  put_faces(s, kFaces, false);
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.comments == std::vector<std::string>{"comment first line", "obj_info scanner 3 v1.2",
                                                    "comment between element and property", "comment",
                                                    "comment last one"});
  CHECK(m.info.positions_in_place);
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY ascii with CRLF line endings", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string lf = ascii_ply(), crlf;
  for (char c : lf) {
    if (c == '\n')
      crlf += "\r\n";
    else
      crlf += c;
  }
  write_file(path, crlf);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "ply ascii");
  CHECK(m.info.comments == std::vector<std::string>{"comment reference mesh"});
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY ascii tolerates blank lines and tabs and a missing final newline", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = "ply\nformat ascii 1.0\nelement vertex 5\n" + std::string(kXyzFloat) +
                  "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                  "0\t0 0\n\n1.5   -2.25\t0.1 \n-3.25e7 1e-20 +42\n7.5 8.125 -9.0625\n100 0.2 -0.3\n"
                  "\n4 0 1 2 3\n3 1 4 2";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("PLY faces with fewer than three corners are skipped and counted", "[readers][ply]") {
  ScratchDir dir;
  const std::vector<std::vector<int>> faces = {{0, 1}, {0, 1, 2}, {}, {3}, {1, 4, 2}};
  SECTION("binary") {
    std::string path = dir.file("mesh.ply");
    std::string s = binary_ply_header(false, 5, 5);
    for (float f : kPos) put_le(s, f);
    put_faces(s, faces, false);
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 1, 4, 2});
    CHECK(m.skipped_faces == 3);
  }
  SECTION("ascii, a single two-corner face") {
    std::string path = dir.file("mesh.ply");
    std::string s = "ply\nformat ascii 1.0\nelement vertex 5\n" + std::string(kXyzFloat) +
                    "element face 3\nproperty list uchar int vertex_indices\nend_header\n";
    for (const char* v : kPosText) s += std::string(v) + "\n";
    s += "3 0 1 2\n2 3 4\n3 1 4 2\n";
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 1, 4, 2});
    CHECK(m.skipped_faces == 1);
  }
}

TEST_CASE("PLY triangle stream can be restarted", "[readers][ply]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  write_file(path, binary_ply(false));
  oocsimp::OpenOptions o;
  o.temp_dir = dir.path();
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<std::uint64_t> got, buf(6);
    // Two triangles at a time, so the quad's fan is split across calls.
    while (std::size_t n = in.triangles->read(buf.data(), 2))
      got.insert(got.end(), buf.begin(), buf.begin() + 3 * std::ptrdiff_t(n));
    CHECK(got == kTris);
    in.restart_triangles();
  }
}

// ---------------------------------------------------------------------------------
// OBJ

TEST_CASE("OBJ v and f lines", "[readers][obj]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  write_file(path, obj_text());
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "obj");
  CHECK_FALSE(m.info.compressed);
  CHECK_FALSE(m.info.positions_in_place);
  CHECK(m.info.vertex_count == 5);
  CHECK(m.info.face_count == 2);
  CHECK(m.positions == kTextD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("OBJ face index forms v and v/vt and v//vn and v/vt/vn", "[readers][obj]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  std::string s;
  for (const char* v : kPosText) s += std::string("v ") + v + "\n";
  s += "vt 0.5 0.5\nvt 0.25 0.75\nvn 0 0 1\n"
       "f 1 2 3\n"
       "f 1/1 3/2 4/1\n"
       "f 2//1 5//1 3//1\n"
       "f 5/2/1 4/1/1 3/2/1 2/1/1\n";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.face_count == 4);
  CHECK(m.positions == kTextD);
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 0, 2, 3, 1, 4, 2, 4, 3, 2, 4, 2, 1});
}

TEST_CASE("OBJ texture coordinates split a position per pair its corners name, in file order",
          "[readers][obj][attributes]") {
  ScratchDir dir;
  std::string path = dir.file("seam.obj");
  write_file(path,
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
             "vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nvt 0.5 0.5\nvt 0.25 0.25\n"
             "vn 0 0 1\nvn 0 1 1\n"
             "f 1/1/1 2/2/1 3/3/1\n"  // first pairs: vertices 0 1 2
             "f 2/5/2 4/4/2 3/6/2\n"  // 2/5 and 3/6 are new pairs: vertices 4 and 5
             "f 2/5 1/1 2/2\n");      // pairs seen before: 4 0 1
  oocsimp::OpenOptions o;
  o.temp_dir = dir.path();
  o.attributes.texture_coordinates = true;
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
  REQUIRE(in.info.vertex_count == 6);
  REQUIRE(in.positions.count == 6);
  std::vector<std::uint64_t> tris(9);
  REQUIRE(in.triangles->read(tris.data(), 3) == 3);
  CHECK(tris == std::vector<std::uint64_t>{0, 1, 2, 4, 3, 5, 4, 0, 1});
  // The split vertices sit at their positions.
  const oocsimp::Vec3d p4 = in.positions.get(4), p5 = in.positions.get(5);
  CHECK((p4.x == 1 && p4.y == 0 && p4.z == 0));
  CHECK((p5.x == 0 && p5.y == 1 && p5.z == 0));
  REQUIRE(in.attributes.size() == 5);
  const char* names[5] = {"u", "v", "nx", "ny", "nz"};
  for (std::size_t k = 0; k < 5; ++k) CHECK(in.attributes.attributes[k].name == names[k]);
  const double uv[6][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {0.5, 0.5}, {0.25, 0.25}};
  for (std::uint64_t i = 0; i < 6; ++i) {
    CHECK(oocsimp::attribute_value(in.attributes, i, 0) == uv[i][0]);
    CHECK(oocsimp::attribute_value(in.attributes, i, 1) == uv[i][1]);
  }
  // Normals are averaged per position (vn 1 and vn 2 at positions 2 and 3), and a split
  // vertex has its position's.
  const double s5 = 1 / std::sqrt(5.0), s2 = 1 / std::sqrt(2.0);
  const double normal[6][3] = {{0, 0, 1},   {0, s5, 2 * s5}, {0, s5, 2 * s5},
                               {0, s2, s2}, {0, s5, 2 * s5}, {0, s5, 2 * s5}};
  for (std::uint64_t i = 0; i < 6; ++i)
    for (std::size_t k = 0; k < 3; ++k)
      CHECK(oocsimp::attribute_value(in.attributes, i, 2 + k) == Approx(normal[i][k]).margin(1e-6));
  // Without texture coordinates (clustering) no position is split.
  o.attributes.texture_coordinates = false;
  oocsimp::MeshInput plain = oocsimp::open_mesh_input(path, o);
  CHECK(plain.info.vertex_count == 4);
  CHECK(plain.attributes.size() == 3);
  // Corner indices beyond what the file has defined so far name the line.
  const struct {
    const char* face;
    const char* message;
  } bad[] = {{"f 1/7 2/1 3/1\n",
              "line 12: texture coordinate index 7 refers to a texture coordinate not defined yet (6 so far)"},
             {"f 1//3 2//1 3//1\n", "line 12: normal index 3 refers to a normal not defined yet (2 so far)"},
             {"f 1/x 2/1 3/1\n", "line 12: malformed texture coordinate index \"1/x\""}};
  for (const auto& b : bad) {
    write_file(
        path,
        std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nvt 0 0\nvt 1 1\nvn 0 0 1\nvn 0 1 0\n") +
            b.face);
    o.attributes.texture_coordinates = true;
    CHECK_THROWS_WITH(oocsimp::open_mesh_input(path, o), Catch::Contains(b.message));
  }
}

TEST_CASE("OBJ positions with many texture coordinates split into as many vertices", "[readers][obj][attributes]") {
  // Position 1 is named with 300 texture coordinates (past the chains' walk, as at the
  // pole of a UV sphere): 299 vertices more, each corner on its own.
  ScratchDir dir;
  std::string s = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int k = 0; k < 300; ++k) s += "vt " + std::to_string(k) + " 0\n";
  for (int k = 0; k < 300; ++k) s += "f 1/" + std::to_string(k + 1) + " 2/1 3/1\n";
  for (int k = 299; k >= 0; --k) s += "f 1/" + std::to_string(k + 1) + " 3/1 2/1\n";
  write_file(dir.file("pole.obj"), s);
  oocsimp::OpenOptions o;
  o.temp_dir = dir.path();
  o.attributes.texture_coordinates = true;
  oocsimp::MeshInput in = oocsimp::open_mesh_input(dir.file("pole.obj"), o);
  REQUIRE(in.positions.count == 3 + 299);
  std::vector<std::uint64_t> t(3 * 600);
  REQUIRE(in.triangles->read(t.data(), 600) == 600);
  for (int k = 0; k < 300; ++k) {
    const std::uint64_t v = t[3 * std::size_t(k)], back = t[3 * std::size_t(599 - k)];
    CHECK(v == back);  // the same pair, the same vertex
    CHECK(oocsimp::attribute_value(in.attributes, v, 0) == double(k));
  }
}

TEST_CASE("An OBJ with normals but no vertex opens with empty attribute arrays", "[readers][obj][attributes]") {
  // Found by fuzz_obj_reader: the empty attribute file mapped to no address, and the
  // arrays were offset from it.
  ScratchDir dir;
  write_file(dir.file("n.obj"), "vn 0 0 1\nvt 0 0\np 1\n");
  oocsimp::OpenOptions o;
  o.temp_dir = dir.path();
  o.attributes.texture_coordinates = true;
  oocsimp::MeshInput in = oocsimp::open_mesh_input(dir.file("n.obj"), o);
  CHECK(in.positions.count == 0);
  CHECK(in.attributes.size() == 5);
  in.triangles->set_primitive_sink([](const oocsimp::LinePrimitive*, std::size_t) {});
  std::vector<std::uint64_t> buf(3);
  CHECK_THROWS_WITH(in.triangles->read(buf.data(), 1), Catch::Contains("line 3: vertex index 1 refers to a vertex"));
}

TEST_CASE("OBJ v lines with extra colour values use the first three", "[readers][obj]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  std::string s =
      "v 0 0 0 1 0 0\n"
      "v 1.5 -2.25 0.1 0.5 0.5 0.5\n"
      "v -3.25e7 1e-20 42 1\n"  // with w
      "v 7.5 8.125 -9.0625 0 1 0\n"
      "v 100 0.2 -0.3 0.1 0.2 0.3\n"
      "f 1 2 3 4\nf 2 5 3\n";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.vertex_count == 5);
  CHECK(m.positions == kTextD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("OBJ negative indices count back from the latest vertex", "[readers][obj]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  std::string s =
      "v 0 0 0\nv 1.5 -2.25 0.1\nv -3.25e7 1e-20 42\n"
      "f -3 -2 -1\n"  // 0 1 2
      "v 7.5 8.125 -9.0625\n"
      "f -1/1/1 -4//2 -2\n"  // 3 0 2
      "v 100 0.2 -0.3\n"
      "f 1 -1 -3 -2\n";  // 0 4 2 3 -> (0 4 2) (0 2 3)
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.positions == kTextD);
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 3, 0, 2, 0, 4, 2, 0, 2, 3});
}

TEST_CASE("OBJ polygons are fanned", "[readers][obj]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  std::string s;
  for (const char* v : kPosText) s += std::string("v ") + v + "\n";
  s += "f 5 4 3 2 1\nf 2 3 4 5\n";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.triangles == std::vector<std::uint64_t>{4, 3, 2, 4, 2, 1, 4, 1, 0, 1, 2, 3, 1, 3, 4});
}

TEST_CASE("OBJ ignores vn vt vp g o s usemtl mtllib l and comment lines", "[readers][obj]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  std::string s =
      "# exported by a test\n"
      "mtllib scene.mtl\n"
      "o object\n"
      "\n"
      "v 0 0 0\n"
      "vn 0 0 1\n"
      "vt 0.5 0.5\n"
      "vp 0.1 0.2\n"
      "  v 1.5 -2.25 0.1\n"
      "\tv -3.25e7 1e-20 42\n"
      "g group1\n"
      "usemtl red\n"
      "s off\n"
      "v 7.5 8.125 -9.0625\r\n"
      "v 100 0.2 -0.3\n"
      "# f 9 9 9\n"
      "l 1 2\n"
      "f 1 2 3 4\r\n"
      "  f 2 5 3\n";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.vertex_count == 5);
  CHECK(m.info.face_count == 2);
  CHECK(m.positions == kTextD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("OBJ faces with fewer than three corners are skipped and counted", "[readers][obj]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  write_file(path, obj_text() + "f 1 2\nf 3\n");
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.triangles == kTris);
  CHECK(m.skipped_faces == 2);
}

// ---------------------------------------------------------------------------------
// STL

TEST_CASE("STL ascii gives one vertex per distinct corner", "[readers][stl]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.stl");
  write_file(path, ascii_stl());
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "stl ascii");
  CHECK_FALSE(m.info.positions_in_place);
  CHECK(m.info.vertex_count == 6);
  CHECK(m.info.face_count == 2);
  CHECK(m.positions == kStlTextD);
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5});
}

TEST_CASE("STL binary gives one vertex per distinct corner", "[readers][stl]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.stl");
  write_file(path, binary_stl("binary STL written by a test", 2, 2));
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "stl binary");
  CHECK_FALSE(m.info.positions_in_place);
  CHECK(m.info.vertex_count == 6);
  CHECK(m.info.face_count == 2);
  CHECK(m.positions == as_doubles(kStlPos));
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5});
}

TEST_CASE("STL binary whose header starts with solid is detected by its size", "[readers][stl]") {
  ScratchDir dir;
  // With and without the .stl extension (content detection by the "solid" prefix).
  std::string name = GENERATE(as<std::string>{}, "mesh.stl", "mesh.STL", "mesh.dat");
  CAPTURE(name);
  std::string path = dir.file(name);
  write_file(path, binary_stl("solid exported-by-cad-tool", 4, 4));
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.format == "stl binary");
  CHECK(m.info.face_count == 4);
  // Triangles 2 and 3 repeat the corners of 0 and 1: welded, they share their vertices.
  CHECK(m.info.vertex_count == 6);
  CHECK(m.info.unwelded_vertex_count == 12);
  CHECK(m.positions == as_doubles(kStlPos));
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5, 0, 1, 2, 3, 4, 5});
}

TEST_CASE("STL ascii with several solids", "[readers][stl]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.stl");
  std::string s = ascii_stl() +
                  "solid second\nfacet normal 0 0 1\nouter loop\nvertex 1 1 1\nvertex 2 2 2\n"
                  "vertex 3 3 3\nendloop\nendfacet\nendsolid second\n";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.info.face_count == 3);
  std::vector<double> expected = kStlTextD;
  expected.insert(expected.end(), {1, 1, 1, 2, 2, 2, 3, 3, 3});
  CHECK(m.positions == expected);
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8});
}

// ---------------------------------------------------------------------------------
// zstd

// ---------------------------------------------------------------------------------
// glTF binary

namespace {

// A .glb of `json` and, when not empty, a BIN chunk of `bin` (padded to 4 bytes).
std::string glb_bytes(std::string json, std::string bin) {
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  std::string s;
  const auto u32 = [&](std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); };
  u32(0x46546C67);
  u32(2);
  u32(std::uint32_t(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
  u32(std::uint32_t(json.size()));
  u32(0x4E4F534A);
  s += json;
  if (!bin.empty()) {
    u32(std::uint32_t(bin.size()));
    u32(0x004E4942);
    s += bin;
  }
  return s;
}

template <class T>
void append_values(std::string& bin, std::initializer_list<T> values) {
  for (T v : values) bin.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// Two meshes: a square of two triangles (float positions, u16 indices, float uvs, u8
// normalized colours) placed twice, by a translation and by a child's scale; and one
// unindexed triangle with normals. A line primitive is skipped.
std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t v = std::uint32_t(static_cast<unsigned char>(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= std::uint32_t(static_cast<unsigned char>(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 2]);
    out += digits[(v >> 18) & 63];
    out += digits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? digits[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? digits[v & 63] : '=';
  }
  return out;
}

// `buffer_uri`: the buffer as a uri instead of the BIN chunk ("base64": a data URI of
// it).
// `scene_json`: the scene and nodes instead of the default ones (ending in a comma).
std::string scene_glb(const std::string& extra_json = "", const std::string& buffer_uri = "",
                      const std::string& scene_json = "") {
  std::string bin;
  append_values<float>(bin, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});  // 0: 48 bytes of positions
  append_values<std::uint16_t>(bin, {0, 1, 2, 0, 2, 3});            // 48: 12 bytes of indices
  append_values<float>(bin, {0, 0, 1, 0, 1, 1, 0, 1});              // 60: 32 bytes of uvs
  append_values<std::uint8_t>(bin, {255, 0, 0, 0, 0, 255, 0, 0, 0, 0, 255, 0, 255, 255, 255, 0});  // 92: rgb, stride 4
  append_values<float>(bin, {0, 0, 5, 1, 0, 5, 0, 1, 5});  // 108: 36 bytes, a triangle
  append_values<float>(bin, {0, 0, 2, 0, 0, 2, 0, 0, 2});  // 144: its normals (0, 0, 2)
  const std::string json =
      R"({"asset":{"version":"2.0"},)" +
      (scene_json.empty()
           ? std::string(R"("scene":0,"scenes":[{"nodes":[0,1,3]}],)"
                         R"("nodes":[{"mesh":0,"translation":[10,0,0]},{"children":[2],"scale":[2,2,2]},)"
                         R"({"mesh":0},{"mesh":1}],)")
           : scene_json) +
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":2,"COLOR_0":3},"indices":1}]},)"
      R"({"primitives":[{"attributes":{"POSITION":4,"NORMAL":5}},{"attributes":{"POSITION":4},"mode":1}]}],)"
      R"("buffers":[{"byteLength":180)" +
      (buffer_uri.empty()       ? std::string()
       : buffer_uri == "base64" ? ",\"uri\":\"data:application/octet-stream;base64," + base64(bin) + "\""
                                : ",\"uri\":\"" + buffer_uri + "\"") +
      R"(}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12},)"
      R"({"buffer":0,"byteOffset":60,"byteLength":32},{"buffer":0,"byteOffset":92,"byteLength":16,"byteStride":4},)"
      R"({"buffer":0,"byteOffset":108,"byteLength":36},{"buffer":0,"byteOffset":144,"byteLength":36}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},)"
      R"({"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"},)"
      R"({"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"},)"
      R"({"bufferView":3,"componentType":5121,"normalized":true,"count":4,"type":"VEC3"},)"
      R"({"bufferView":4,"componentType":5126,"count":3,"type":"VEC3"},)"
      R"({"bufferView":5,"componentType":5126,"count":3,"type":"VEC3"}])" +
      extra_json + "}";
  return glb_bytes(json, buffer_uri.empty() ? bin : std::string());
}

}  // namespace

TEST_CASE("glb nodes place their meshes, and the attributes are carried", "[readers][glb]") {
  ScratchDir dir;
  write_file(dir.file("scene.glb"), scene_glb());
  oocsimp::OpenOptions o;
  o.temp_dir = dir.path();
  o.attributes.texture_coordinates = true;
  oocsimp::MeshInput in = oocsimp::open_mesh_input(dir.file("scene.glb"), o);
  CHECK(in.info.format == "glb");
  REQUIRE(in.positions.count == 11);
  const double want[11][3] = {{10, 0, 0}, {11, 0, 0}, {11, 1, 0}, {10, 1, 0},  // translated
                              {0, 0, 0},  {2, 0, 0},  {2, 2, 0},  {0, 2, 0},   // scaled by the parent
                              {0, 0, 5},  {1, 0, 5},  {0, 1, 5}};
  for (std::uint64_t i = 0; i < 11; ++i) {
    const oocsimp::Vec3d p = in.positions.get(i);
    CHECK((p.x == want[i][0] && p.y == want[i][1] && p.z == want[i][2]));
  }
  std::vector<std::uint64_t> tris(3 * 8);
  REQUIRE(in.triangles->read(tris.data(), 8) == 5);
  tris.resize(15);
  CHECK(tris == std::vector<std::uint64_t>{0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 8, 9, 10});
  // Colours in [0, 1], normals unit, v turned to the bottom-left origin.
  std::vector<std::string> names;
  for (const auto& a : in.attributes.attributes) names.push_back(a.name);
  CHECK(names == std::vector<std::string>{"red", "green", "blue", "nx", "ny", "nz", "u", "v"});
  CHECK(oocsimp::attribute_value(in.attributes, 1, 1) == 1.0);  // the second vertex is green
  CHECK(oocsimp::attribute_value(in.attributes, 8, 0) == 1.0);  // no COLOR_0: white
  CHECK(oocsimp::attribute_value(in.attributes, 9, 5) == 1.0);  // normal (0, 0, 2) made unit
  CHECK(oocsimp::attribute_value(in.attributes, 2, 6) == 1.0);
  CHECK(oocsimp::attribute_value(in.attributes, 2, 7) == 0.0);  // glTF v 1 is the bottom
  bool skipped = false;
  for (const std::string& n : in.info.not_carried) skipped = skipped || n.find("mode 1") != std::string::npos;
  CHECK(skipped);
  // The buffer as a base64 data URI (as Open3D writes .glb): the same mesh.
  write_file(dir.file("uri.glb"), scene_glb("", "base64"));
  oocsimp::MeshInput uri = oocsimp::open_mesh_input(dir.file("uri.glb"), o);
  REQUIRE(uri.positions.count == 11);
  CHECK(uri.positions.get(6).y == 2.0);
  CHECK(oocsimp::attribute_value(uri.attributes, 1, 1) == 1.0);
  // Compressed, the BIN chunk goes through a temporary file: the same mesh.
  write_zstd_file(dir.file("scene.glb.zst"), scene_glb());
  oocsimp::MeshInput packed = oocsimp::open_mesh_input(dir.file("scene.glb.zst"), o);
  REQUIRE(packed.positions.count == 11);
  CHECK(packed.positions.get(6).y == 2.0);
}

TEST_CASE("glb nodes form trees, however deep, and a mirroring node turns its faces", "[readers][glb]") {
  ScratchDir dir;
  oocsimp::OpenOptions o;
  o.temp_dir = dir.path();
  // A chain of 30000 nodes, the last naming the triangle of mesh 1: read without
  // recursion, placed by every translation on the way.
  std::string chain = R"("scene":0,"scenes":[{"nodes":[0]}],"nodes":[)";
  for (int i = 0; i < 30000; ++i) chain += "{\"translation\":[1,0,0],\"children\":[" + std::to_string(i + 1) + "]},";
  chain += R"({"mesh":1}],)";
  write_file(dir.file("chain.glb"), scene_glb("", "", chain));
  oocsimp::MeshInput in = oocsimp::open_mesh_input(dir.file("chain.glb"), o);
  REQUIRE(in.positions.count == 3);
  CHECK(in.positions.get(0).x == 30000.0);
  // Two parents of one node (2^39 placements, were it followed) and a cycle: refused.
  std::string doubled = R"("nodes":[)";
  for (int i = 0; i < 40; ++i)
    doubled += "{\"children\":[" + std::to_string(i + 1) + "," + std::to_string(i + 1) + "]},";
  doubled += R"({"mesh":1}],)";
  write_file(dir.file("doubled.glb"), scene_glb("", "", doubled));
  CHECK_THROWS_WITH(oocsimp::open_mesh_input(dir.file("doubled.glb"), o), Catch::Contains("has two parents"));
  write_file(dir.file("cycle.glb"),
             scene_glb("", "", R"("scenes":[{"nodes":[0]}],"nodes":[{"children":[1]},{"children":[0]}],)"));
  CHECK_THROWS_WITH(oocsimp::open_mesh_input(dir.file("cycle.glb"), o), Catch::Contains("own ancestor"));
  // Mirrored by scale -1 in x: the corners' order is reversed (the face still faces
  // out, now -x turned) and the normal (0, 0, 1) stays (0, 0, 1).
  write_file(dir.file("mirror.glb"),
             scene_glb("", "", R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":1,"scale":[-1,1,1]}],)"));
  oocsimp::MeshInput m = oocsimp::open_mesh_input(dir.file("mirror.glb"), o);
  REQUIRE(m.positions.count == 3);
  CHECK(m.positions.get(1).x == -1.0);
  std::vector<std::uint64_t> t(3);
  REQUIRE(m.triangles->read(t.data(), 1) == 1);
  CHECK(t == std::vector<std::uint64_t>{0, 2, 1});
  CHECK(oocsimp::attribute_value(m.attributes, 0, 2) == 1.0);
  // The normal of the face as read: (x1 - x0) x (x2 - x0) points along +z still.
  const oocsimp::Vec3d a = m.positions.get(t[0]), b = m.positions.get(t[1]), c = m.positions.get(t[2]);
  CHECK((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) > 0);
}

TEST_CASE("glb written by oocsimp reads back as the same mesh", "[readers][glb]") {
  ScratchDir dir;
  const std::vector<double> positions = {0, 0, 0, 1.5, 0, 0, 0, 2.25, 0, 0, 0, -3};
  const std::vector<std::uint32_t> triangles = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
  oocsimp::write_mesh(dir.file("t.glb"), positions, triangles, oocsimp::MeshFormat::glb, oocsimp::ScalarType::f32);
  LoadedMesh m = load_mesh(dir.file("t.glb"), dir.path());
  CHECK(m.positions == positions);
  CHECK(m.triangles == std::vector<std::uint64_t>(triangles.begin(), triangles.end()));
}

TEST_CASE("damaged or unsupported glb files exit with one line naming what", "[readers][glb][errors]") {
  ScratchDir dir;
  const std::string good = scene_glb();
  struct Case {
    std::string bytes;
    const char* message;
  };
  std::string v1 = good;
  v1[4] = 1;
  std::string bad_json = good;
  bad_json[20] = '[';
  bad_json[21] = '}';
  std::string out_of_range = good;
  const std::size_t at = out_of_range.find(R"("byteOffset":144,"byteLength":36)");
  out_of_range.replace(at, 32, R"("byteOffset":164,"byteLength":36)");
  const std::vector<Case> cases = {
      {v1, "byte 4: glTF version 1, where 2 is read"},
      {bad_json, "byte 2"},
      {good.substr(0, good.size() - 40), "file ends inside the BIN chunk"},
      {out_of_range, "bufferViews[5]: bytes 164 to 200 are beyond its buffer's 180"},
      {scene_glb(R"(,"extensionsRequired":["KHR_draco_mesh_compression"])"),
       "extensionsRequired: the extension \"KHR_draco_mesh_compression\" is not supported"},
      {"glTF", "unexpected end of file"},
      {scene_glb("", "scene.bin"), "buffers[0]: data in another file (scene.bin) is not read"},
      {scene_glb(R"(,"extras":1e999)"), "JSON chunk"},
      {scene_glb(",\"extensionsRequired\":" + std::string(100000, '[') + std::string(100000, ']')),
       "extensionsRequired: the extension (array) is not supported"},
  };
  for (const Case& c : cases) {
    write_file(dir.file("bad.glb"), c.bytes);
    CHECK_THROWS_WITH(oocsimp::open_mesh_input(dir.file("bad.glb")), Catch::Contains(c.message));
  }
  // An index beyond its primitive's vertices: named when the triangles are read.
  std::string index = good;
  const std::size_t bin = index.size() - 180;  // the BIN chunk's data
  index[bin + 48 + 2 * 5] = 9;                 // the sixth index: 9 of 4 vertices
  write_file(dir.file("index.glb"), index);
  CHECK_THROWS_WITH(load_mesh(dir.file("index.glb")), Catch::Contains("index 9 of triangle 1 of primitive 0"));
  // On the command line: exit 3 and one line.
  write_file(dir.file("bad.glb"), v1);
  const oocsimp_test::CliResult r = oocsimp_test::run_cli("info " + dir.file("bad.glb"));
  CHECK(r.exit_code == 3);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
}

TEST_CASE("zstd-compressed PLY OBJ and STL give the same mesh as uncompressed", "[readers][zstd]") {
  struct Case {
    const char* name;
    std::string content;
  };
  const Case cases[] = {{"mesh.ply", binary_ply(false)},
                        {"mesh_be.ply", binary_ply(true)},
                        {"mesh_ascii.ply", ascii_ply()},
                        {"mesh.obj", obj_text()},
                        {"mesh.stl", ascii_stl()},
                        {"mesh_binary.stl", binary_stl("binary STL", 2, 2)},
                        {"mesh_solid.stl", binary_stl("solid but binary", 2, 2)}};
  ScratchDir dir;
  for (const Case& c : cases) {
    CAPTURE(c.name);
    std::string plain = dir.file(c.name), packed = dir.file(std::string(c.name) + ".zst");
    write_file(plain, c.content);
    write_zstd_file(packed, c.content);
    LoadedMesh a = load_mesh(plain, dir.path());
    LoadedMesh b = load_mesh(packed, dir.path());
    CHECK_FALSE(a.info.compressed);
    CHECK(b.info.compressed);
    CHECK_FALSE(b.info.positions_in_place);  // compressed input is always converted
    CHECK(b.info.path == packed);
    check_same_mesh(a, b);
    CHECK(a.vertex_count() > 0);
    CHECK(a.triangle_count() > 0);
  }
}

namespace {

// `bytes` as one gzip member (RFC 1952), by zlib's deflate with a gzip wrapper.
std::string gzip_member(const std::string& bytes) {
  z_stream z{};
  REQUIRE(deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) == Z_OK);
  std::string out(deflateBound(&z, uLong(bytes.size())) + 64, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = uInt(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(&out[0]);
  z.avail_out = uInt(out.size());
  REQUIRE(deflate(&z, Z_FINISH) == Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

}  // namespace

TEST_CASE("gzip-compressed input reads as the plain file, members one after another", "[readers][gzip]") {
  ScratchDir dir;
  std::string ply = std::string("ply\n") + format_line(false) + "element vertex 40000\n" + kXyzFloat +
                    "element face 39998\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::uint32_t i = 0; i < 40000; ++i) {
    put_le(ply, float(i));
    put_le(ply, float(i % 7));
    put_le(ply, float(i % 13));
  }
  for (std::int32_t i = 0; i + 2 < 40000; ++i) {
    ply.push_back(3);
    put_le(ply, i);
    put_le(ply, i + 1);
    put_le(ply, i + 2);
  }
  const std::string cases[][2] = {{"mesh.obj", obj_text()}, {"mesh.stl", ascii_stl()}, {"big.ply", ply}};
  for (const auto& c : cases) {
    CAPTURE(c[0]);
    const std::string plain = dir.file(c[0]), packed = plain + ".gz", two = dir.file("two-" + c[0] + ".gz");
    write_file(plain, c[1]);
    write_file(packed, gzip_member(c[1]));
    // Split in two members, as `cat a.gz b.gz` or pigz gives.
    const std::size_t half = c[1].size() / 2;
    write_file(two, gzip_member(c[1].substr(0, half)) + gzip_member(c[1].substr(half)));
    const LoadedMesh a = load_mesh(plain, dir.path());
    for (const std::string& path : {packed, two}) {
      const LoadedMesh b = load_mesh(path, dir.path());
      CHECK(b.info.compressed);
      CHECK(b.info.compression == "gzip");
      CHECK(b.positions == a.positions);
      CHECK(b.triangles == a.triangles);
    }
  }
  // Damaged: cut short, a corrupt byte, something after the last member.
  const std::string member = gzip_member(ply);
  write_file(dir.file("short.ply.gz"), member.substr(0, member.size() / 2));
  CHECK_THAT(input_error([&] { load_mesh(dir.file("short.ply.gz"), dir.path()); }),
             StartsWith(dir.file("short.ply.gz") + ": byte ") && Contains("truncated gzip stream"));
  std::string corrupt = member;
  for (std::size_t i = 100; i < 140; ++i) corrupt[i] = char(corrupt[i] ^ 0x5A);
  write_file(dir.file("corrupt.ply.gz"), corrupt);
  CHECK_THAT(input_error([&] { load_mesh(dir.file("corrupt.ply.gz"), dir.path()); }), Contains("gzip"));
  write_file(dir.file("tail.ply.gz"), member + "garbage");
  CHECK_THAT(input_error([&] { load_mesh(dir.file("tail.ply.gz"), dir.path()); }),
             Contains("data after the gzip stream"));
}

TEST_CASE("zstd-compressed PLY with multi-megabyte content", "[readers][zstd]") {
  // Larger than the 1 MiB read buffer, so refills happen mid-record.
  ScratchDir dir;
  const std::uint32_t n = 100003;
  std::string s = std::string("ply\n") + format_line(false) + "element vertex " + std::to_string(n) + "\n" +
                  "property uchar pad\n" + kXyzFloat + "element face " + std::to_string(n - 2) +
                  "\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::uint32_t i = 0; i < n; ++i) {
    put_le(s, std::uint8_t(i));
    put_le(s, float(i) * 0.5f);
    put_le(s, -float(i));
    put_le(s, 1.0f / float(i + 1));
  }
  for (std::uint32_t i = 0; i + 2 < n; ++i) {
    s.push_back(3);
    put_le(s, std::int32_t(i));
    put_le(s, std::int32_t(i + 2));
    put_le(s, std::int32_t(i + 1));
  }
  write_file(dir.file("big.ply"), s);
  write_zstd_file(dir.file("big.ply.zst"), s);
  LoadedMesh a = load_mesh(dir.file("big.ply"), dir.path());
  LoadedMesh b = load_mesh(dir.file("big.ply.zst"), dir.path());
  CHECK(a.info.positions_in_place);
  CHECK(b.info.compressed);
  REQUIRE(a.vertex_count() == n);
  REQUIRE(a.triangle_count() == n - 2);
  CHECK(a.positions[3 * 99999 + 2] == double(1.0f / 100000.0f));
  CHECK(a.triangles[3 * 77777 + 1] == 77779);
  check_same_mesh(a, b);
}

// ---------------------------------------------------------------------------------
// Bad input

TEST_CASE("PLY binary truncated inside the vertex element", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = binary_ply(false);
  std::size_t header = binary_ply_header(false).size();
  s.resize(header + 4 * 12 + 5);  // four and a bit vertices
  write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": byte "));
  CHECK_THAT(msg, Contains("vertex"));
  CHECK(dir.entries() == std::vector<std::string>{"mesh.ply"});
}

TEST_CASE("PLY binary truncated inside the vertex element when converted", "[readers][errors]") {
  // A list property forces conversion, so the truncation is found record by record.
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = std::string("ply\n") + format_line(false) +
                  "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "property list uchar int tags\nend_header\n";
  std::size_t header = s.size();
  for (int v = 0; v < 2; ++v) {
    for (int k = 0; k < 3; ++k) put_le(s, 1.0f);
    s.push_back(0);
  }
  put_le(s, 1.0f);
  write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": byte " + std::to_string(header + 2 * 13) + ":"));
  CHECK(dir.entries() == std::vector<std::string>{"mesh.ply"});  // no temporary file left
}

TEST_CASE("PLY binary truncated inside the face element fails while reading triangles", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = binary_ply(false);
  std::size_t second_face = binary_ply_header(false).size() + kPos.size() * 4 + 1 + 4 * 4;
  s.resize(s.size() - 3);  // the last index is cut
  write_file(path, s);
  // Opening succeeds: faces are read lazily.
  {
    oocsimp::OpenOptions o;
    o.temp_dir = dir.path();
    oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
    CHECK(in.info.face_count == 2);
  }
  std::string msg = load_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": byte " + std::to_string(second_face) + ":"));
  CHECK_THAT(msg, Contains("face"));
}

TEST_CASE("PLY face element with fewer records than declared", "[readers][errors]") {
  ScratchDir dir;
  SECTION("binary") {
    std::string path = dir.file("mesh.ply");
    std::string s = binary_ply_header(false, 5, 3);
    for (float f : kPos) put_le(s, f);
    put_faces(s, kFaces, false);
    write_file(path, s);
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": byte " + std::to_string(s.size()) + ":"));
  }
  SECTION("ascii") {
    std::string path = dir.file("mesh.ply");
    std::string s = ascii_ply();
    s.replace(s.find("element face 2"), 14, "element face 3");
    write_file(path, s);
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": line "));
  }
}

TEST_CASE("PLY face index out of range", "[readers][errors]") {
  ScratchDir dir;
  SECTION("binary int index") {
    std::string path = dir.file("mesh.ply");
    std::string s = binary_ply_header(false);
    for (float f : kPos) put_le(s, f);
    put_faces(s, {{0, 1, 2}, {1, 5, 2}}, false);
    write_file(path, s);
    std::size_t second_face = binary_ply_header(false).size() + kPos.size() * 4 + 13;
    std::string msg = load_error(path, dir);
    CHECK_THAT(msg, StartsWith(path + ": byte " + std::to_string(second_face) + ":"));
    CHECK_THAT(msg, Contains("out of range"));
  }
  SECTION("binary uint index 0xFFFFFFFF, big-endian") {
    std::string path = dir.file("mesh.ply");
    std::string s = std::string("ply\n") + format_line(true) + "element vertex 5\n" + kXyzFloat +
                    "element face 1\nproperty list uchar uint vertex_indices\nend_header\n";
    for (float f : kPos) put_be(s, f);
    s.push_back(3);
    for (std::uint32_t i : {0u, 0xFFFFFFFFu, 1u}) put_be(s, i);
    write_file(path, s);
    std::string msg = load_error(path, dir);
    CHECK_THAT(msg, StartsWith(path + ": byte "));
    CHECK_THAT(msg, Contains("4294967295"));
  }
  SECTION("ascii") {
    std::string path = dir.file("mesh.ply");
    std::string s = ascii_ply();
    s.replace(s.find("3 1 4 2"), 7, "3 1 5 2");
    write_file(path, s);
    std::string msg = load_error(path, dir);
    CHECK_THAT(msg, StartsWith(path + ": line 17:"));  // the second face's line in the file
    CHECK_THAT(msg, Contains("out of range"));
  }
}

TEST_CASE("PLY negative face index", "[readers][errors]") {
  ScratchDir dir;
  SECTION("binary") {
    std::string path = dir.file("mesh.ply");
    std::string s = binary_ply_header(false);
    for (float f : kPos) put_le(s, f);
    put_faces(s, {{-1, 1, 2}, {1, 4, 2}}, false);
    write_file(path, s);
    std::string msg = load_error(path, dir);
    CHECK_THAT(msg, StartsWith(path + ": byte " + std::to_string(binary_ply_header(false).size() + 60) + ":"));
    CHECK_THAT(msg, Contains("negative"));
  }
  SECTION("ascii") {
    std::string path = dir.file("mesh.ply");
    std::string s = ascii_ply();
    s.replace(s.find("4 0 1 2 3"), 9, "4 0 1 -2 3");
    write_file(path, s);
    std::string msg = load_error(path, dir);
    CHECK_THAT(msg, StartsWith(path + ": line 16:"));
    CHECK_THAT(msg, Contains("negative"));
  }
}

// The policy (README, "Damaged input"): a vertex with a NaN or infinite coordinate is
// kept in the position array, so indices stay valid, but is ignored: the bounding box
// leaves it out and the triangle stream drops, and counts, the triangles using it.
// Vertex 3 of the reference mesh is used by one triangle of the fanned quad only.
void check_vertex_3_ignored(const LoadedMesh& m, const std::string& position) {
  CHECK(m.info.non_finite_vertices == 1);
  CHECK(m.info.first_non_finite_vertex == 3);
  CHECK(m.info.first_non_finite_position == position);
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 1, 4, 2});
  CHECK(m.skipped.non_finite == 1);
  CHECK(m.skipped.total() == 1);
  CHECK(m.info.bounds.max.y == m.positions[13]);  // vertex 4's y (0.2): vertex 3 (y = 8.125) is left out
  CHECK(m.info.bounds.min.z == m.positions[14]);  // vertex 4's z (-0.3): and so is vertex 3's z = -9.0625
}

TEST_CASE("NaN and infinite coordinates: the vertex is ignored, its triangles dropped and counted",
          "[readers][errors]") {
  ScratchDir dir;
  SECTION("ascii PLY") {
    std::string token = GENERATE(as<std::string>{}, "nan", "NaN", "inf", "-inf");
    CAPTURE(token);
    std::string path = dir.file("mesh.ply");
    std::string s = ascii_ply();
    s.replace(s.find("-9.0625"), 7, token);
    write_file(path, s);
    check_vertex_3_ignored(load_mesh(path, dir.path()), "line 14");
  }
  SECTION("OBJ, plain and compressed") {
    std::string path = dir.file(GENERATE(as<std::string>{}, "mesh.obj", "mesh.obj.zst"));
    std::string s = obj_text();
    s.replace(s.find("-9.0625"), 7, "nan");
    if (path.size() > 4 && path.substr(path.size() - 4) == ".zst")
      write_zstd_file(path, s);
    else
      write_file(path, s);
    check_vertex_3_ignored(load_mesh(path, dir.path()), "line 5");
    std::remove(path.c_str());
  }
  SECTION("binary PLY read in place") {
    bool be = GENERATE(false, true);
    CAPTURE(be);
    std::string path = dir.file("mesh.ply");
    std::string s = binary_ply_header(be);
    std::vector<float> pos = kPos;
    pos[3 * 3 + 1] = std::numeric_limits<float>::quiet_NaN();
    for (float f : pos) put(s, f, be);
    put_faces(s, kFaces, be);
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    REQUIRE(m.info.positions_in_place);
    CHECK(m.info.bounds.max.y == 0.2f);
    CHECK(m.info.non_finite_vertices == 1);
    CHECK(m.info.first_non_finite_vertex == 3);
    CHECK(m.info.first_non_finite_position == "byte " + std::to_string(binary_ply_header(be).size() + 3 * 12));
    CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 1, 4, 2});
    CHECK(m.skipped.non_finite == 1);
  }
  SECTION("binary PLY with double infinity") {
    std::string path = dir.file("mesh.ply");
    std::string s = std::string("ply\n") + format_line(false) +
                    "element vertex 2\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
    std::size_t header = s.size();
    for (double d : {1.0, 2.0, 3.0, 4.0, 5.0, -std::numeric_limits<double>::infinity()}) put_le(s, d);
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.info.non_finite_vertices == 1);
    CHECK(m.info.first_non_finite_vertex == 1);
    CHECK(m.info.first_non_finite_position == "byte " + std::to_string(header + 24));
    CHECK(m.info.bounds.max.z == 3.0);
  }
  SECTION("binary STL") {
    std::string path = dir.file("mesh.stl");
    std::string s = binary_stl("nan inside", 2, 2);
    float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(&s[84 + 50 + 12 + 12 + 4], &nan, 4);  // second triangle, corner 1, y
    write_file(path, s);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.info.non_finite_vertices == 1);
    CHECK(m.info.first_non_finite_vertex == 4);
    CHECK(m.info.first_non_finite_position == "byte " + std::to_string(84 + 50 + 12 + 12));  // the corner's record
    CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2});
    CHECK(m.skipped.non_finite == 1);
  }
  SECTION("every vertex NaN: an empty box, no triangles") {
    std::string path = dir.file("mesh.obj");
    write_file(path, "v nan 0 0\nv 0 nan 0\nv 0 0 inf\nf 1 2 3\nf 3 2 1\n");
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK(m.info.non_finite_vertices == 3);
    CHECK(m.info.first_non_finite_vertex == 0);
    CHECK(m.info.first_non_finite_position == "line 1");
    CHECK(m.info.bounds.empty());
    CHECK(m.triangles.empty());
    CHECK(m.skipped.non_finite == 2);
  }
  CHECK(dir.entries().size() <= 1);  // the input only: no temporary file left behind
}

TEST_CASE("the box of a converted file holds the stored floats, not the parsed doubles", "[readers]") {
  // GCC 12 -O3 once folded the float-to-double widening in the converter away, so
  // 0.2 and 0.3 bounded the box where the positions held the larger 0.2f and 0.3f.
  // (A PLY declaring float, and an OBJ whose text has no more than float precision.)
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  write_file(path,
             "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
             "end_header\n0.3 0.2 0.1\n0 0 0\n");
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK_FALSE(m.info.double_precision);
  CHECK(m.info.bounds.max.x == double(0.3f));
  CHECK(m.info.bounds.max.y == double(0.2f));
  CHECK(m.info.bounds.max.z == double(0.1f));
  for (std::size_t i = 0; i < m.positions.size(); i += 3) {
    CHECK(m.positions[i] <= m.info.bounds.max.x);
    CHECK(m.positions[i + 1] <= m.info.bounds.max.y);
    CHECK(m.positions[i + 2] <= m.info.bounds.max.z);
  }
  write_file(dir.file("mesh.obj"), "v 0.3 0.2 0.1\nv 0 0 0\nf 1 2 2\n");
  LoadedMesh o = load_mesh(dir.file("mesh.obj"), dir.path());
  CHECK_FALSE(o.info.double_precision);  // no more digits than a float keeps
  CHECK(o.positions == std::vector<double>{double(0.3f), double(0.2f), double(0.1f), 0, 0, 0});
  CHECK(o.info.bounds.max.x == double(0.3f));
  CHECK(o.info.bounds.max.y == double(0.2f));
  CHECK(o.info.bounds.max.z == double(0.1f));
}

TEST_CASE("A finite coordinate beyond the float range of a converted file is rejected", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = ascii_ply();
  s.replace(s.find("1e-20"), 5, "-1e39");
  write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": line 13:"));
  CHECK_THAT(msg, Contains("vertex 2"));
  CHECK_THAT(msg, Contains("beyond the float range"));
  CHECK(dir.entries().size() == 1);
}

TEST_CASE("Triangles naming one vertex twice are dropped and counted, zero-area ones are kept", "[readers]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  // Faces: a proper triangle, one with a repeated index, a quad with a repeated corner
  // (fanned: (0,1,1) dropped, (0,1,2) kept), and a zero-area triangle of three
  // distinct collinear vertices (kept: it still connects them).
  std::string s =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n2 0 0\n"
      "3 0 1 2\n3 0 0 2\n4 0 1 1 2\n3 0 1 3\n";
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 0, 1, 2, 0, 1, 3});
  CHECK(m.skipped.repeated_index == 2);
  CHECK(m.skipped.non_finite == 0);
  CHECK(m.skipped.total() == 2);
}

TEST_CASE("OBJ face index 0 is rejected", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  write_file(path, obj_text() + "f 0 1 2\n");
  std::string msg = load_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": line 9:"));
  CHECK_THAT(msg, Contains("index 0"));
}

TEST_CASE("OBJ forward and out-of-range references are rejected", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.obj");
  SECTION("forward reference to a vertex defined later") {
    write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\nv 1 1 0\n");
    std::string msg = load_error(path, dir);
    CHECK_THAT(msg, StartsWith(path + ": line 4:"));
    CHECK_THAT(msg, Contains("not defined yet"));
  }
  SECTION("index beyond all vertices") {
    write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1/1/1 2/2/2 9/9/9\n");
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": line 5:"));
  }
  SECTION("negative index reaching before the first vertex") {
    write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": line 4:"));
  }
  SECTION("malformed index") {
    write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x3\n");
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": line 4:"));
  }
  SECTION("vertex with two coordinates") {
    write_file(path, "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n");
    CHECK_THAT(open_error(path, dir), StartsWith(path + ": line 2:"));
  }
}

TEST_CASE("STL binary whose triangle count disagrees with its size", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.stl");
  SECTION("count too large") { write_file(path, binary_stl("binary", 3, 2)); }
  SECTION("count too small") { write_file(path, binary_stl("binary", 1, 2)); }
  SECTION("count too large, header says solid") { write_file(path, binary_stl("solid x", 5, 2)); }
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": byte 80:"));
  CHECK(dir.entries() == std::vector<std::string>{"mesh.stl"});
}

TEST_CASE("STL ascii with a malformed facet", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.stl");
  std::string s = ascii_stl();
  std::string expected;
  SECTION("missing endloop") {
    s.erase(s.find("    endloop\n"), 12);
    expected = ": line 7:";  // endfacet where endloop belongs
  }
  SECTION("two vertices in a loop") {
    s.erase(s.find("      vertex 1.5 -2.25 0.1\n"), 27);
    expected = ": line 6:";
  }
  SECTION("missing endsolid") {
    s.erase(s.find("endsolid"));
    expected = ": line ";
  }
  SECTION("malformed coordinate") {
    s.replace(s.find("8.125"), 5, "8.1.25");
    expected = ": line 11:";
  }
  write_file(path, s);
  CHECK_THAT(open_error(path, dir), StartsWith(path + expected));
}

TEST_CASE("PLY header errors", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = binary_ply(false), expected = ": line 2:", what;
  SECTION("unknown format") {
    s.replace(s.find("binary_little_endian"), 20, "binary_middle_endian");
    what = "binary_middle_endian";
  }
  SECTION("format version 2.0") {
    s.replace(s.find("1.0"), 3, "2.0");
    what = "2.0";
  }
  SECTION("unknown property type") {
    s.replace(s.find("float y"), 7, "quad y");
    expected = ": line 5:";
  }
  SECTION("unknown keyword") {
    s.replace(s.find("element face"), 0, "elephant 3\n");
    expected = ": line 7:";
  }
  SECTION("missing end_header") {
    s = "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n";
    expected = ": line ";
  }
  SECTION("missing format line") {
    s.erase(s.find("format"), s.find("element") - s.find("format"));
    expected = ": line ";
  }
  SECTION("vertex element without z") {
    s.replace(s.find("property float z"), 16, "property float w");
    expected = "";
  }
  write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + expected));
  if (!what.empty()) CHECK_THAT(msg, Contains(what));
}

TEST_CASE("PLY .ply file that does not start with ply is rejected", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  write_file(path, "plx\nformat ascii 1.0\n");
  CHECK_THAT(open_error(path, dir), StartsWith(path + ": byte 0:"));
}

TEST_CASE("PLY header claiming 10^12 vertices on a tiny file fails promptly", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s;
  SECTION("binary, read in place") {
    s = binary_ply(false);
    s.replace(s.find("element vertex 5"), 16, "element vertex 1000000000000");
    write_file(path, s);
  }
  SECTION("binary big-endian with doubles") {
    s = std::string("ply\n") + format_line(true) +
        "element vertex 1000000000000\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
    for (int k = 0; k < 6; ++k) put_be(s, 1.0);
    write_file(path, s);
  }
  SECTION("binary with a list property (converted)") {
    s = std::string("ply\n") + format_line(false) +
        "element vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\n"
        "property list uchar int tags\nend_header\n";
    for (int k = 0; k < 3; ++k) put_le(s, 1.0f);
    s.push_back(0);
    write_file(path, s);
  }
  SECTION("binary, zstd-compressed") {
    s = binary_ply(false);
    s.replace(s.find("element vertex 5"), 16, "element vertex 1000000000000");
    path = dir.file("mesh.ply.zst");
    write_zstd_file(path, s);
  }
  SECTION("ascii") {
    s = ascii_ply();
    s.replace(s.find("element vertex 5"), 16, "element vertex 1000000000000");
    write_file(path, s);
  }
  SECTION("faces, read lazily") {
    s = binary_ply(false);
    s.replace(s.find("element face 2"), 14, "element face 1000000000000");
    write_file(path, s);
  }
  auto start = std::chrono::steady_clock::now();
  std::string msg = load_error(path, dir);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(seconds < 5);
  CHECK_THAT(msg, StartsWith(path + ": "));
  CHECK((msg.find(": byte ") != std::string::npos || msg.find(": line ") != std::string::npos));
}

TEST_CASE("PLY vertex count whose byte size wraps around 2^64 is rejected", "[readers][errors]") {
  // 1537228672809129301 records of 12 bytes are 2^64 - 4 bytes: the end offset wraps
  // around to just before the start of the vertex data.
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  bool faces = GENERATE(true, false);
  CAPTURE(faces);
  std::string s = binary_ply(false);
  if (!faces) s.erase(s.find("element face"), s.find("end_header") - s.find("element face"));
  s.replace(s.find("element vertex 5"), 16, "element vertex 1537228672809129301");
  write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": byte "));
  CHECK_THAT(msg, Contains("vertex"));
}

TEST_CASE("PLY element before the vertices whose byte size exceeds the file is rejected", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  // Records of 4 bytes: 2^62 + 1 (2^64 + 4 bytes, i.e. 4 modulo 2^64), 2^62 (0 modulo
  // 2^64) and 2^40 (no overflow, just far beyond the end of the file).
  std::string count = GENERATE(as<std::string>{}, "4611686018427387905", "4611686018427387904", "1099511627776");
  bool faces = GENERATE(true, false);
  std::string s = binary_ply(false);
  CAPTURE(count, faces);
  if (!faces) s.erase(s.find("element face"), s.find("end_header") - s.find("element face"));
  s.replace(s.find("element vertex"), 0, "element junk " + count + "\nproperty int j\n");
  std::size_t header = s.find("end_header\n") + 11;
  s.insert(header, 4, 'j');  // as if there were one junk record
  write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": byte "));
}

TEST_CASE("PLY trailing data after the last element", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  SECTION("binary") {
    std::string s = binary_ply(false);
    std::size_t end = s.size();
    s += "garbage";
    write_file(path, s);
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": byte " + std::to_string(end) + ":"));
  }
  SECTION("binary, zstd-compressed") {
    std::string s = binary_ply(false);
    std::size_t end = s.size();
    s.push_back('\0');
    path += ".zst";
    write_zstd_file(path, s);
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": byte " + std::to_string(end) + ":"));
  }
  SECTION("ascii") {
    write_file(path, ascii_ply() + "\n3 0 1 2\n");
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": line 19:"));
  }
  SECTION("binary, after an element that follows the faces") {
    std::string s = binary_ply(false);
    s.replace(s.find("end_header"), 0, "element edge 2\nproperty int a\nproperty int b\n");
    for (int k = 0; k < 4; ++k) put_le(s, std::int32_t(k));
    std::size_t end = s.size();
    s += "x";
    write_file(path, s);
    CHECK_THAT(load_error(path, dir), StartsWith(path + ": byte " + std::to_string(end) + ":"));
  }
}

TEST_CASE("Truncated or corrupt zstd stream is an InputError", "[readers][errors]") {
  ScratchDir dir, tmp;
  std::string name = GENERATE(as<std::string>{}, "mesh.ply.zst", "mesh.obj.zst", "mesh.stl.zst");
  CAPTURE(name);
  std::string content = name == "mesh.ply.zst" ? ascii_ply() : name == "mesh.obj.zst" ? obj_text() : ascii_stl();
  std::string path = dir.file(name);
  write_zstd_file(path, content);
  std::string packed = oocsimp_test::read_file(path);
  SECTION("truncated") { packed.resize(packed.size() / 2); }
  SECTION("corrupt") {
    for (std::size_t i = 8; i < packed.size(); ++i) packed[i] = char(0xA5 ^ int(i));
  }
  write_file(path, packed);
  CHECK_THAT(load_error(path, tmp), StartsWith(path + ": byte "));
  CHECK(tmp.entries().empty());
}

TEST_CASE("Empty PLY, STL, OBJ and OFF files are rejected", "[readers][errors]") {
  ScratchDir dir;
  for (const char* name : {"empty.ply", "empty.stl", "empty.obj", "empty.off"}) write_file(dir.file(name), "");
  CHECK_THAT(open_error(dir.file("empty.ply"), dir), StartsWith(dir.file("empty.ply") + ": byte 0:"));
  CHECK_THAT(open_error(dir.file("empty.stl"), dir), StartsWith(dir.file("empty.stl") + ": byte 0:"));
  CHECK(open_error(dir.file("empty.obj"), dir) == dir.file("empty.obj") + ": line 0: no vertices or faces found");
  CHECK_THAT(open_error(dir.file("empty.off"), dir), StartsWith(dir.file("empty.off") + ": byte 0:"));
}

TEST_CASE("A file named .obj with no OBJ statement is refused, naming its first foreign line", "[readers][errors]") {
  ScratchDir dir;
  // Text: every line is read, and none opens a statement.
  write_file(dir.file("text.obj"), "# a comment\n\nhello world\nmore text\n");
  CHECK(open_error(dir.file("text.obj"), dir) ==
        dir.file("text.obj") +
            ": line 3: not an OBJ file: no line opens an OBJ statement (this one opens with \"hello\")");
  // Binary: refused after 1000 foreign lines, whatever follows.
  std::string binary;
  for (int i = 0; i < 1500; ++i) binary += std::string("\x01\x02\xFF\x80", 4) + "\n";
  binary += "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  write_file(dir.file("binary.obj"), binary);
  CHECK_THAT(open_error(dir.file("binary.obj"), dir),
             StartsWith(dir.file("binary.obj") + ": line 1: not an OBJ file: none of the first 1000 lines"));
  // A statement anywhere makes it OBJ, read for what it holds: here no vertex or face.
  write_file(dir.file("named.obj"), "hello\no object\n");
  CHECK(open_error(dir.file("named.obj"), dir) == dir.file("named.obj") + ": line 2: no vertices or faces found");
  write_file(dir.file("point.obj"), "hello\nv 1 2 3\n");
  CHECK(load_mesh(dir.file("point.obj"), dir.path()).vertex_count() == 1);
}

TEST_CASE("OFF is read: comments, counts on the keyword line, polygons, the prefixes", "[readers][off]") {
  ScratchDir dir;
  // A unit square as a quad and a triangle beside it; comments and blank lines between.
  write_file(dir.file("quad.off"),
             "OFF # a comment\n\n# counts next\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0 # the last corner\n2 0.5 0\n"
             "4 0 1 2 3\n3 1 4 2 255 0 0\n");
  LoadedMesh m = load_mesh(dir.file("quad.off"), dir.path());
  CHECK(m.info.format == "off");
  CHECK(m.vertex_count() == 5);
  CHECK(m.triangles == std::vector<std::uint64_t>{0, 1, 2, 0, 2, 3, 1, 4, 2});  // the quad fanned from its first corner
  CHECK(m.positions[3 * 4] == 2.0);
  // Counts on the keyword line, colours and normals after x y z (not carried), no
  // extension: the content says OFF.
  write_file(dir.file("coloured.mesh"),
             "CNOFF 3 1 0\n0 0 0 0 0 1 255 0 0\n1 0 0 0 0 1 0 255 0\n0 1 0 0 0 1 0 0 255\n3 0 1 2\n");
  LoadedMesh c = load_mesh(dir.file("coloured.mesh"), dir.path());
  CHECK(c.info.format == "off");
  CHECK(c.triangles == std::vector<std::uint64_t>{0, 1, 2});
  REQUIRE(c.info.not_carried.size() == 1);
  CHECK_THAT(c.info.not_carried[0], Contains("OFF vertex normals, colours are not carried"));
  // Written by the writer, read back: the same mesh as the PLY.
  const std::vector<double> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::vector<std::uint32_t> triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  oocsimp::write_mesh(dir.file("t.off"), positions, triangles, oocsimp::MeshFormat::off);
  oocsimp::write_mesh(dir.file("t.ply"), positions, triangles, oocsimp::MeshFormat::ply_binary);
  const LoadedMesh off = load_mesh(dir.file("t.off"), dir.path()), ply = load_mesh(dir.file("t.ply"), dir.path());
  CHECK(off.positions == ply.positions);
  CHECK(off.triangles == ply.triangles);
}

TEST_CASE("damaged OFF is refused naming the line", "[readers][off][errors]") {
  ScratchDir dir;
  struct Case {
    const char* content;
    const char* message;
  } cases[] = {
      {"OFF\n3 1 0\n0 0 0\n1 0 0\n", "line 4: the file ends after 2 of its 3 vertices"},
      {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 x\n3 0 1 2\n", "line 5: malformed vertex coordinate \"x\""},
      {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6: vertex index 3 is not below the vertex count 3"},
      {"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "the file ends after 1 of its 2 faces"},
      {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "line 6: a face of 4 corners lists 3 indices"},
      {"OFF\nthree 1 0\n", "line 2: expected the counts"},
      {"OFF BINARY\n", "binary OFF is not read"},
      {"4OFF\n1 0 0\n0 0 0 0\n", "only three-dimensional OFF"},
  };
  int i = 0;
  for (const Case& c : cases) {
    const std::string path = dir.file("bad" + std::to_string(i++) + ".off");
    write_file(path, c.content);
    CAPTURE(c.content);
    const std::string error = input_error([&] { load_mesh(path, dir.path()); });
    CHECK_THAT(error, StartsWith(path + ": "));
    CHECK_THAT(error, Contains(c.message));
  }
}

TEST_CASE("Missing input file throws IoError", "[readers][errors]") {
  ScratchDir dir;
  CHECK_THROWS_AS(oocsimp::open_mesh_input(dir.file("absent.ply")), oocsimp::IoError);
}

TEST_CASE("Unknown format is rejected", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.xyz");
  write_file(path, "1 2 3\n");
  CHECK_THAT(input_error([&] { oocsimp::open_mesh_input(path); }), StartsWith(path + ": "));
}

// ---------------------------------------------------------------------------------
// Temporary files

TEST_CASE("Temporary position files live exactly as long as the MeshInput", "[readers][temp]") {
  ScratchDir inputs, tmp;
  std::string name = GENERATE(as<std::string>{}, "mesh.obj", "mesh.ply", "mesh.stl", "mesh_binary.ply.zst");
  CAPTURE(name);
  std::string path = inputs.file(name);
  if (name == "mesh.obj")
    write_file(path, obj_text());
  else if (name == "mesh.ply")
    write_file(path, ascii_ply());
  else if (name == "mesh.stl")
    write_file(path, ascii_stl());
  else
    write_zstd_file(path, binary_ply(false));
  {
    oocsimp::OpenOptions o;
    o.temp_dir = tmp.path();
    oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
    CHECK_FALSE(in.info.positions_in_place);
    std::vector<std::string> e = tmp.entries();
    const std::size_t files = name == "mesh.stl" ? 2 : 1;  // STL: and the map of welded vertex numbers
    REQUIRE(e.size() == files);
    CHECK_THAT(e[0], StartsWith("oocsimp-positions-"));
    if (files == 2) CHECK_THAT(e[1], StartsWith("oocsimp-weld-map-"));
    // Moving the input keeps the files alive.
    oocsimp::MeshInput moved = std::move(in);
    CHECK(tmp.entries().size() == files);
    CHECK(moved.positions.get(1).y == -2.25);
  }
  CHECK(tmp.entries().empty());
  CHECK(inputs.entries() == std::vector<std::string>{name});
}

TEST_CASE("Binary PLY read in place creates no temporary file", "[readers][temp]") {
  ScratchDir inputs, tmp;
  std::string path = inputs.file("mesh.ply");
  write_file(path, binary_ply(false));
  oocsimp::OpenOptions o;
  o.temp_dir = tmp.path();
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
  CHECK(in.info.positions_in_place);
  CHECK(tmp.entries().empty());
}

// ---------------------------------------------------------------------------------
// Text: line ends, byte order marks, long lines (files written by other tools and
// systems read the same, and no line can make memory grow without bound)

namespace {

std::string with_line_ends(const std::string& lf, const std::string& ending) {
  std::string s;
  for (char c : lf) {
    if (c == '\n')
      s += ending;
    else
      s += c;
  }
  return s;
}

const std::string kBom = "\xEF\xBB\xBF";

}  // namespace

TEST_CASE("A UTF-8 byte order mark before the first line is skipped in OBJ, ascii PLY and ascii STL",
          "[readers][text]") {
  struct Case {
    const char* name;
    std::string content;
  };
  const Case cases[] = {{"mesh.obj", obj_text()},
                        {"mesh.ply", ascii_ply()},
                        {"mesh.stl", ascii_stl()},
                        {"mesh_v_first.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
                        {"mesh_binary.ply", binary_ply(false)}};
  ScratchDir dir;
  for (const Case& c : cases) {
    for (bool packed : {false, true}) {
      CAPTURE(c.name, packed);
      std::string plain = dir.file(std::string("plain_") + c.name), bom = dir.file(std::string("bom_") + c.name);
      if (packed) {
        plain += ".zst";
        bom += ".zst";
        write_zstd_file(plain, c.content);
        write_zstd_file(bom, kBom + c.content);
      } else {
        write_file(plain, c.content);
        write_file(bom, kBom + c.content);
      }
      LoadedMesh a = load_mesh(plain, dir.path());
      LoadedMesh b = load_mesh(bom, dir.path());
      check_same_mesh(a, b);
      CHECK(a.info.comments == b.info.comments);
      CHECK(a.vertex_count() >= 3);
      CHECK(a.triangle_count() >= 1);
    }
  }
}

TEST_CASE("CR LF and CRLF line ends read the same mesh in every text format", "[readers][text]") {
  struct Case {
    const char* name;
    std::string content;
  };
  std::string obj = obj_text() + "# comment\n\nvn 0 0 1\nf 1 3 5\n";
  const Case cases[] = {{"mesh.obj", obj}, {"mesh.ply", ascii_ply()}, {"mesh.stl", ascii_stl()}};
  ScratchDir dir;
  for (const Case& c : cases) {
    LoadedMesh lf = load_mesh(
        [&] {
          std::string p = dir.file(std::string("lf_") + c.name);
          write_file(p, c.content);
          return p;
        }(),
        dir.path());
    for (const char* ending : {"\r", "\r\n"}) {
      for (bool packed : {false, true}) {
        CAPTURE(c.name, std::strlen(ending), packed);
        std::string p = dir.file(std::string("other_") + c.name) + (packed ? ".zst" : "");
        std::string content = with_line_ends(c.content, ending);
        if (packed)
          write_zstd_file(p, content);
        else
          write_file(p, content);
        check_same_mesh(lf, load_mesh(p, dir.path()));
      }
    }
    // Line ends mixed within one file.
    std::string mixed;
    int k = 0;
    for (char ch : c.content) {
      if (ch == '\n')
        mixed += (k++ % 3 == 0) ? "\r" : (k % 3 == 1) ? "\n" : "\r\n";
      else
        mixed += ch;
    }
    write_file(dir.file(std::string("mixed_") + c.name), mixed);
    check_same_mesh(lf, load_mesh(dir.file(std::string("mixed_") + c.name), dir.path()));
  }
}

TEST_CASE("Line numbers count CR-only and CRLF lines, also when a CRLF straddles the read buffer", "[readers][text]") {
  // The reader fills a 1 MiB buffer; "\r" as the last byte of a fill must wait for the
  // next byte before the line ends, or "\r\n" would count as two lines.
  ScratchDir dir;
  const std::size_t kBuffer = 1 << 20;
  for (const char* ending : {"\r", "\r\n"}) {
    CAPTURE(std::strlen(ending));
    std::string s = "v 0 0 0\rv 1 0 0\r";
    s = with_line_ends("v 0 0 0\nv 1 0 0\n", ending);
    std::uint64_t line = 3;
    // Comment lines of 1000 bytes until the next line end would cross kBuffer - 1.
    while (s.size() + 1000 + std::strlen(ending) < kBuffer - 1) {
      s += "#" + std::string(998, 'c') + ending;
      ++line;
    }
    s += "#" + std::string(kBuffer - 1 - s.size() - 1, 'c');
    s += ending;  // its '\r' is the buffer's last byte
    REQUIRE(s[kBuffer - 1] == '\r');
    ++line;
    s += std::string("v 1 1 0") + ending + "v 1 bad 0" + ending;
    ++line;
    std::string path = dir.file("mesh.obj");
    write_file(path, s);
    std::string msg = load_error(path, dir);
    CHECK_THAT(msg, StartsWith(path + ": line " + std::to_string(line) + ":"));
    CHECK_THAT(msg, Contains("\"bad\""));
  }
}

TEST_CASE("A data line longer than 64 KiB is an InputError naming its line", "[readers][text][errors]") {
  ScratchDir dir;
  const std::string long_line(100000, '1');
  std::string path, expected;
  SECTION("OBJ") {
    path = dir.file("mesh.obj");
    write_file(path, "v 0 0 0\n# " + long_line + "\nv 1 1 1\n");
    expected = ": line 2:";
  }
  SECTION("OBJ without any line end, compressed") {
    path = dir.file("mesh.obj.zst");
    write_zstd_file(path, std::string(3 << 20, '\0'));
    expected = ": line 1:";
  }
  SECTION("ascii PLY") {
    path = dir.file("mesh.ply");
    std::string s = ascii_ply();
    s.replace(s.find("100 0.2 -0.3"), 0, long_line);
    write_file(path, s);
    expected = ": line 15:";
  }
  SECTION("ascii STL") {
    path = dir.file("mesh.stl");
    std::string s = ascii_stl();
    s.replace(s.find("      vertex 7.5"), 0, std::string(100000, ' '));
    write_file(path, s);
    expected = ": line 11:";
  }
  std::string msg = load_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + expected));
  CHECK_THAT(msg, Contains("longer than 64 KiB"));
}

TEST_CASE("A 100 KB PLY comment line is a valid header line", "[readers][text]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = ascii_ply();
  s.replace(s.find("comment reference mesh"), 0, "comment " + std::string(100000, 'x') + "\n");
  write_file(path, s);
  LoadedMesh m = load_mesh(path, dir.path());
  CHECK(m.positions == kPosD);
  CHECK(m.triangles == kTris);
}

TEST_CASE("A PLY header is bounded at 1 MiB, in one line or in many", "[readers][text][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = ascii_ply();
  std::string expected;
  SECTION("one comment line of 2 MiB") {
    s.replace(s.find("comment reference mesh"), 0, "comment " + std::string(2 << 20, 'x') + "\n");
    expected = ": line 3:";
  }
  SECTION("2 MiB of short comment lines") {
    std::string comments;
    while (comments.size() < (2u << 20)) comments += "comment " + std::string(90, 'y') + "\n";
    s.replace(s.find("comment reference mesh"), 0, comments);
    expected = ": line ";
  }
  SECTION("a binary PLY header without end_header, zstd-compressed") {
    s = "ply\nformat binary_little_endian 1.0\ncomment " + std::string(3 << 20, '\0');
    path += ".zst";
    expected = ": line 3:";
  }
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".zst") == 0)
    write_zstd_file(path, s);
  else
    write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + expected));
  CHECK_THAT(msg, Contains("PLY header longer than 1 MiB"));
}

// ---------------------------------------------------------------------------------
// Numbers and messages (out-of-range numbers behave as strtod does, and a damaged
// token cannot garble the error message)

TEST_CASE("A coordinate below the double range rounds to zero as strtod does, one above it is rejected",
          "[readers][text]") {
  ScratchDir dir;
  const char* const tokens[] = {"1e-400", "-1e-400",     "1e-310",         "-4.9e-324",
                                "2e-324", "100000e-329", "0.0000001e-320", "123456789e-330"};
  std::string obj, ply_body;
  for (const char* t : tokens) {
    obj += std::string("v ") + t + " " + t + " 1\n";
    ply_body += std::string(t) + " 1 " + t + "\n";
  }
  obj += "f 1 2 3\n";
  const std::size_t n = sizeof tokens / sizeof tokens[0];
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) + "\n" + kXyzFloat + "end_header\n" + ply_body;
  write_file(dir.file("tiny.obj"), obj);
  write_file(dir.file("tiny.ply"), ply);
  LoadedMesh mo = load_mesh(dir.file("tiny.obj"), dir.path());
  LoadedMesh mp = load_mesh(dir.file("tiny.ply"), dir.path());
  REQUIRE(mo.vertex_count() == n);
  REQUIRE(mp.vertex_count() == n);
  for (std::size_t i = 0; i < n; ++i) {
    CAPTURE(tokens[i]);
    // The reference: the C library's strtod. The OBJ keeps it (denormal doubles are more
    // than a float holds, so its array is double); the PLY declares float.
    const double exact = std::strtod(tokens[i], nullptr);
    const double expected = double(float(exact));
    CHECK(mo.positions[3 * i] == exact);
    CHECK(std::signbit(mo.positions[3 * i]) == std::signbit(exact));
    CHECK(mp.positions[3 * i + 2] == expected);
    CHECK(mp.positions[3 * i + 1] == 1.0);
  }
  for (const char* huge : {"1e400", "-1e309", "0.01e311"}) {
    CAPTURE(huge);
    write_file(dir.file("huge.obj"), std::string("v 0 0 0\nv 1 ") + huge + " 0\n");
    std::string msg = load_error(dir.file("huge.obj"), dir);
    CHECK_THAT(msg, StartsWith(dir.file("huge.obj") + ": line 2:"));
    CHECK_THAT(msg, Contains(huge));
  }
}

TEST_CASE("A NUL or control byte in a token is escaped in the message, which goes on past it", "[readers][errors]") {
  ScratchDir dir;
  std::string path, escaped;
  SECTION("OBJ coordinate") {
    path = dir.file("mesh.obj");
    write_file(path, std::string("v 0 0 0\nv 1 2\0x 3\n", 18));
    escaped = "\"2\\x00x\"";
  }
  SECTION("OBJ face index with a control byte") {
    path = dir.file("mesh.obj");
    write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\x1b[2J 3\n");
    escaped = "\"2\\x1B[2J\"";
  }
  SECTION("ascii PLY number") {
    path = dir.file("mesh.ply");
    std::string s = ascii_ply();
    s.replace(s.find("8.125"), 5,
              std::string("8.1\0"
                          "25",
                          6));
    write_file(path, s);
    escaped = "\"8.1\\x0025\" for \"y\"";
  }
  SECTION("PLY header keyword") {
    path = dir.file("mesh.ply");
    std::string s = ascii_ply();
    s.replace(s.find("comment"), 7, std::string("comm\0nt", 7));
    write_file(path, s);
    escaped = "\"comm\\x00nt\"";
  }
  std::string msg = load_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + ": line "));
  CHECK_THAT(msg, Contains(escaped));
  CHECK(msg.find('\0') == std::string::npos);
}

// ---------------------------------------------------------------------------------
// PLY header contradictions and trailing data (a file that disagrees with itself is
// rejected rather than read one way of several)

TEST_CASE("PLY headers that contradict themselves are rejected naming the line", "[readers][errors]") {
  ScratchDir dir;
  std::string path = dir.file("mesh.ply");
  std::string s = binary_ply(false), expected, what;
  SECTION("two format lines") {
    s.replace(s.find("element vertex"), 0, "format binary_big_endian 1.0\n");
    expected = ": line 3:";
    what = "format";
  }
  SECTION("the same format line twice") {
    s.replace(s.find("element vertex"), 0, "format binary_little_endian 1.0\n");
    expected = ": line 3:";
    what = "format";
  }
  SECTION("a property declared twice in one element") {
    s.replace(s.find("element face"), 0, "property float x\n");
    expected = ": line 7:";
    what = "\"x\"";
  }
  SECTION("a list property declared twice") {
    s.replace(s.find("end_header"), 0, "property list uchar uint vertex_indices\n");
    expected = ": line 9:";
    what = "\"vertex_indices\"";
  }
  SECTION("an element declared twice") {
    s.replace(s.find("end_header"), 0, "element vertex 0\nproperty float x\n");
    expected = ": line 9:";
    what = "\"vertex\"";
  }
  write_file(path, s);
  std::string msg = open_error(path, dir);
  CHECK_THAT(msg, StartsWith(path + expected));
  CHECK_THAT(msg, Contains(what));
  CHECK_THAT(msg, Contains("twice") || Contains("second"));
}

TEST_CASE("PLY without a face element: garbage after the last element is rejected, blank ascii lines are not",
          "[readers][errors]") {
  ScratchDir dir;
  auto vertices_only = [](std::string s) {
    s.erase(s.find("element face"), s.find("end_header") - s.find("element face"));
    return s.substr(0, s.find("4 0 1 2 3\n") == std::string::npos ? s.size() : s.find("4 0 1 2 3\n"));
  };
  SECTION("binary, read in place") {
    std::string s = binary_ply_header(false);
    s.erase(s.find("element face"), s.find("end_header") - s.find("element face"));
    for (float f : kPos) put_le(s, f);
    std::size_t end = s.size();
    write_file(dir.file("ok.ply"), s);
    CHECK(load_mesh(dir.file("ok.ply"), dir.path()).positions == kPosD);
    s += std::string(700, 'g');
    write_file(dir.file("mesh.ply"), s);
    CHECK_THAT(open_error(dir.file("mesh.ply"), dir),
               StartsWith(dir.file("mesh.ply") + ": byte " + std::to_string(end) + ": trailing data"));
    // The same through zstd (converted, not mapped).
    write_zstd_file(dir.file("mesh.ply.zst"), s);
    CHECK_THAT(open_error(dir.file("mesh.ply.zst"), dir),
               StartsWith(dir.file("mesh.ply.zst") + ": byte " + std::to_string(end) + ": trailing data"));
  }
  SECTION("binary, with an element after the vertices") {
    std::string s = binary_ply_header(false);
    s.replace(s.find("element face"), s.find("end_header") - s.find("element face"),
              "element note 2\nproperty int n\n");
    for (float f : kPos) put_le(s, f);
    put_le(s, std::int32_t(1));
    put_le(s, std::int32_t(2));
    std::size_t end = s.size();
    write_file(dir.file("ok.ply"), s);
    CHECK(load_mesh(dir.file("ok.ply"), dir.path()).positions == kPosD);
    s += "\n";
    write_file(dir.file("mesh.ply"), s);
    CHECK_THAT(open_error(dir.file("mesh.ply"), dir),
               StartsWith(dir.file("mesh.ply") + ": byte " + std::to_string(end) + ": trailing data"));
  }
  SECTION("ascii") {
    std::string s = vertices_only(ascii_ply());
    write_file(dir.file("ok.ply"), s + "\n  \n\t\n");
    LoadedMesh m = load_mesh(dir.file("ok.ply"), dir.path());
    CHECK(m.positions == kPosD);
    CHECK(m.triangle_count() == 0);
    write_file(dir.file("mesh.ply"), s + "\n1 2 3\n");
    CHECK_THAT(open_error(dir.file("mesh.ply"), dir), StartsWith(dir.file("mesh.ply") + ": line 15: trailing data"));
  }
}

// ---------------------------------------------------------------------------------
// zstd frames (every file zstd -d accepts reads the same here)

namespace {

// A zstd skippable frame (RFC 8878 §3.1.2) with `payload`.
std::string skippable_frame(unsigned variant, const std::string& payload) {
  std::string s;
  put_le(s, std::uint32_t(0x184D2A50u + variant));
  put_le(s, std::uint32_t(payload.size()));
  return s + payload;
}

// `content` compressed as one frame, through the test helper.
std::string zstd_frame(const ScratchDir& dir, const std::string& content) {
  std::string p = dir.file("frame.zst");
  write_zstd_file(p, content);
  return oocsimp_test::read_file(p);
}

}  // namespace

TEST_CASE("zstd files of several frames, with skippable frames before or between them, read like zstd -d",
          "[readers][zstd]") {
  struct Case {
    const char* name;
    std::string content;
  };
  const Case cases[] = {{"mesh.ply", binary_ply(false)},
                        {"mesh_ascii.ply", ascii_ply()},
                        {"mesh.obj", obj_text()},
                        {"mesh.stl", ascii_stl()},
                        {"mesh_binary.stl", binary_stl("binary", 2, 2)}};
  ScratchDir dir;
  for (const Case& c : cases) {
    std::string plain = dir.file(c.name);
    write_file(plain, c.content);
    LoadedMesh expected = load_mesh(plain, dir.path());
    // Three pieces, cut inside lines and records.
    const std::string& t = c.content;
    std::size_t a = t.size() / 3, b = 2 * t.size() / 3 + 1;
    std::string f1 = zstd_frame(dir, t.substr(0, a)), f2 = zstd_frame(dir, t.substr(a, b - a)),
                f3 = zstd_frame(dir, t.substr(b));
    // pzstd writes a skippable frame holding the size of the next frame before each one.
    auto pz = [](const std::string& f) {
      std::string size;
      put_le(size, std::uint32_t(f.size()));
      return skippable_frame(0, size) + f;
    };
    const std::pair<const char*, std::string> layouts[] = {
        {"concatenated frames", f1 + f2 + f3},
        {"pzstd layout", pz(f1) + pz(f2) + pz(f3)},
        {"leading skippable frame", skippable_frame(7, "not a mesh") + zstd_frame(dir, t)},
        {"inner and trailing skippable frames",
         f1 + skippable_frame(15, "") + f2 + skippable_frame(3, "x\ny") + f3 + skippable_frame(1, "end")},
        {"an empty frame first", zstd_frame(dir, "") + f1 + f2 + f3}};
    for (const auto& layout : layouts) {
      CAPTURE(c.name, layout.first);
      std::string packed = dir.file(std::string("packed_") + c.name + ".zst");
      write_file(packed, layout.second);
      LoadedMesh m = load_mesh(packed, dir.path());
      CHECK(m.info.compressed);
      check_same_mesh(expected, m);
    }
  }
}

// ---------------------------------------------------------------------------------
// Non-seekable input and an input replaced between passes (a stream can be read only
// once and a path can change under the run, yet every pass must read the same mesh)

namespace {

// Calls read(path) while a writer thread feeds `content` through a FIFO at `path`.
template <class F>
auto read_through_fifo(const std::string& path, const std::string& content, F&& read) {
  REQUIRE(::mkfifo(path.c_str(), 0600) == 0);
  ::signal(SIGPIPE, SIG_IGN);  // a reader that stops early makes the writer's write fail instead
  std::thread writer([&] {
    int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) return;
    for (std::size_t done = 0; done < content.size();) {
      ssize_t n = ::write(fd, content.data() + done, content.size() - done);
      if (n <= 0) break;
      done += std::size_t(n);
    }
    ::close(fd);
  });
  struct Join {
    std::thread& t;
    std::string path;
    ~Join() {
      // Releases a writer still waiting for a reader to open the FIFO.
      int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
      t.join();
      if (fd >= 0) ::close(fd);
    }
  } join{writer, path};
  return read(path);
}

}  // namespace

TEST_CASE("A FIFO reads like the regular file, and its copy in --tmp goes with the mesh", "[readers][fifo]") {
  struct Case {
    const char* name;
    std::string content;
    bool packed;
  };
  // More than the 1 MiB read buffer and a few copy chunks, so the face pass reads the
  // copy that the vertex pass made as it went.
  std::string big_obj;
  for (int i = 0; i < 60000; ++i) big_obj += "v " + std::to_string(i) + " " + std::to_string(i % 7) + " 0.5\n";
  for (int i = 1; i + 2 <= 60000; ++i)
    big_obj += "f " + std::to_string(i) + " " + std::to_string(i + 1) + " " + std::to_string(i + 2) + "\n";
  const Case cases[] = {{"mesh_ascii.ply", ascii_ply(), false},
                        {"mesh.obj", obj_text(), false},
                        {"mesh_binary.ply", binary_ply(false), false},
                        {"mesh_be.ply", binary_ply(true), false},
                        {"mesh.stl", ascii_stl(), false},
                        {"mesh_binary.stl", binary_stl("binary", 2, 2), false},
                        {"mesh.ply.zst", binary_ply(false), true},
                        {"mesh.obj.zst", obj_text(), true},
                        {"big.obj", big_obj, false},
                        {"big.obj.zst", big_obj, true}};
  for (const Case& c : cases) {
    CAPTURE(c.name);
    ScratchDir inputs, tmp;
    std::string file = inputs.file(std::string("file_") + c.name), fifo = inputs.file(std::string("fifo_") + c.name);
    if (c.packed)
      write_zstd_file(file, c.content);
    else
      write_file(file, c.content);
    std::string bytes = oocsimp_test::read_file(file);
    LoadedMesh expected = load_mesh(file, tmp.path());
    LoadedMesh m = read_through_fifo(fifo, bytes, [&](const std::string& p) { return load_mesh(p, tmp.path()); });
    CHECK(m.positions == expected.positions);
    CHECK(m.triangles == expected.triangles);
    CHECK(m.info.vertex_count == expected.info.vertex_count);
    CHECK(m.info.face_count == expected.info.face_count);
    CHECK(m.info.compressed == c.packed);
    CHECK_FALSE(m.info.positions_in_place);
    CHECK(tmp.entries().empty());
    // The triangles can be read again (from the copy), and the copy lives as long as the mesh.
    oocsimp::OpenOptions o;
    o.temp_dir = tmp.path();
    std::remove(fifo.c_str());
    read_through_fifo(fifo, bytes, [&](const std::string& p) {
      oocsimp::MeshInput in = oocsimp::open_mesh_input(p, o);
      // The position array, and the copy while a triangle stream needs it (STL's does not:
      // its triangles come from the weld's vertex map, beside the welded positions).
      CHECK(tmp.entries().size() == 2u);
      std::vector<std::uint64_t> buf(3 * 64), all;
      for (int pass = 0; pass < 2; ++pass) {
        all.clear();
        while (std::size_t n = in.triangles->read(buf.data(), 64))
          all.insert(all.end(), buf.begin(), buf.begin() + 3 * n);
        CHECK(all == expected.triangles);
        in.restart_triangles();
      }
      CHECK(in.file_size == bytes.size());
      return 0;
    });
    CHECK(tmp.entries().empty());
  }
}

TEST_CASE("A damaged FIFO input fails like the file and leaves nothing in --tmp", "[readers][fifo][errors]") {
  ScratchDir inputs, tmp;
  std::string s = ascii_ply();
  s.replace(s.find("3 1 4 2"), 7, "3 1 9 2");  // index out of range, line 17
  std::string msg =
      read_through_fifo(inputs.file("mesh.ply"), s, [&](const std::string& p) { return load_error(p, tmp); });
  CHECK_THAT(msg, StartsWith(inputs.file("mesh.ply") + ": line 17:"));
  CHECK(tmp.entries().empty());
  // /dev/zero never ends: it is rejected after the first 64 KiB, not copied without end.
  std::string zero = inputs.file("zero.obj");
  REQUIRE(::symlink("/dev/zero", zero.c_str()) == 0);
  CHECK_THAT(load_error(zero, tmp), StartsWith(zero + ": line 1: line longer than 64 KiB"));
  CHECK(tmp.entries().empty());
}

TEST_CASE("An input replaced after opening is not read: every pass reads the file that was opened",
          "[readers][replaced]") {
  struct Case {
    const char* name;
    std::string first, second;
  };
  // The second file has the same layout and other indices, as a rewritten scan would.
  std::string obj2 = obj_text(), ascii2 = ascii_ply(), bin2 = binary_ply(false);
  obj2.replace(obj2.find("f 2 5 3"), 7, "f 5 4 3");
  ascii2.replace(ascii2.find("3 1 4 2"), 7, "3 4 3 2");
  std::string tail;
  put_faces(tail, {{3, 2, 1, 0}, {4, 3, 2}}, false);
  bin2.replace(bin2.size() - tail.size(), tail.size(), tail);
  const Case cases[] = {
      {"mesh.obj", obj_text(), obj2}, {"mesh.ply", ascii_ply(), ascii2}, {"mesh_binary.ply", binary_ply(false), bin2}};
  for (const Case& c : cases) {
    for (bool rename : {true, false}) {
      CAPTURE(c.name, rename);
      ScratchDir dir;
      std::string path = dir.file(c.name);
      write_file(path, c.first);
      oocsimp::OpenOptions o;
      o.temp_dir = dir.path();
      oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
      if (rename) {
        write_file(dir.file("other"), c.second);
        REQUIRE(std::rename(dir.file("other").c_str(), path.c_str()) == 0);
      } else {
        REQUIRE(std::remove(path.c_str()) == 0);
      }
      in.restart_triangles();
      std::vector<std::uint64_t> buf(300), all;
      while (std::size_t n = in.triangles->read(buf.data(), 100))
        all.insert(all.end(), buf.begin(), buf.begin() + 3 * n);
      CHECK(all == kTris);
      CHECK(in.positions.get(1).y == -2.25);
    }
  }
}

// ---------------------------------------------------------------------------------
// Face ranges (parts that read only their own faces)

namespace {

// Binary PLY with kPos and `faces` (each its own corner count).
std::string binary_ply_with_faces(const std::vector<std::vector<int>>& faces, bool be) {
  std::string s = binary_ply_header(be, 5, faces.size());
  for (float f : kPos) put(s, f, be);
  put_faces(s, faces, be);
  return s;
}

// Every triangle of faces [first, end) of `m`, read as a range.
std::vector<std::uint64_t> range_triangles(const oocsimp::MeshInput& m, std::uint64_t first, std::uint64_t end) {
  std::vector<std::uint64_t> out, chunk(3 * 4);
  const std::unique_ptr<oocsimp::TriangleStream> s = oocsimp::open_face_range(m, first, end, first);
  while (const std::size_t n = s->read(chunk.data(), 4)) out.insert(out.end(), chunk.begin(), chunk.begin() + 3 * n);
  return out;
}

}  // namespace

TEST_CASE("face ranges of binary PLY triangles give the whole stream's triangles, split anywhere",
          "[readers][ply][ranges]") {
  ScratchDir d;
  const std::vector<std::vector<int>> faces = {{0, 1, 2}, {1, 4, 2}, {2, 2, 3}, {0, 3, 4},
                                               {4, 3, 1}, {0, 0, 1}, {3, 2, 1}};
  for (bool be : {false, true}) {
    const std::string path = d.file(be ? "be.ply" : "le.ply");
    write_file(path, binary_ply_with_faces(faces, be));
    oocsimp::OpenOptions o;
    o.temp_dir = d.path();
    oocsimp::MeshInput m = oocsimp::open_mesh_input(path, o);
    REQUIRE(m.fixed_faces.available());
    CHECK(m.fixed_faces.count == faces.size());
    // The stream's triangles: the faces that do not name a vertex twice.
    const std::vector<std::uint64_t> whole = {0, 1, 2, 1, 4, 2, 0, 3, 4, 4, 3, 1, 3, 2, 1};
    for (std::uint32_t parts = 1; parts <= 9; ++parts) {  // 8 and 9: some ranges empty
      std::vector<std::uint64_t> joined;
      std::uint64_t triangles = 0, repeated = 0;
      for (std::uint32_t p = 0; p < parts; ++p) {
        const std::uint64_t first = oocsimp::even_split_start(faces.size(), p, parts);
        const std::uint64_t end = oocsimp::even_split_start(faces.size(), p + 1, parts);
        const oocsimp::FaceRangeScan scan = oocsimp::scan_face_range(m, first, end);
        CHECK(scan.readable);
        triangles += scan.triangles;
        repeated += scan.skipped.repeated_index;
        const std::vector<std::uint64_t> mine = range_triangles(m, first, end);
        CHECK(mine.size() == 3 * scan.triangles);
        joined.insert(joined.end(), mine.begin(), mine.end());
      }
      INFO(parts << " parts");
      CHECK(joined == whole);
      CHECK(triangles == 5);
      CHECK(repeated == 2);
    }
  }
}

TEST_CASE("face ranges are refused where a face is not a triangle, and name a bad index's byte",
          "[readers][ply][ranges]") {
  ScratchDir d;
  oocsimp::OpenOptions o;
  o.temp_dir = d.path();
  // The reference mesh's quad and triangle do not fill 13 bytes a face: no table.
  write_file(d.file("quad.ply"), binary_ply(false));
  CHECK_FALSE(oocsimp::open_mesh_input(d.file("quad.ply"), o).fixed_faces.available());
  // A quad and a two-corner face fill 26 bytes: the table is there, but the range
  // holding the quad is not readable (so no part reads alone).
  write_file(d.file("quad2.ply"), binary_ply_with_faces({{0, 1, 2, 3}, {1, 4}}, false));
  oocsimp::MeshInput quad = oocsimp::open_mesh_input(d.file("quad2.ply"), o);
  REQUIRE(quad.fixed_faces.available());
  CHECK_FALSE(oocsimp::scan_face_range(quad, 0, 2).readable);
  CHECK_FALSE(oocsimp::scan_face_range(quad, 0, 1).readable);
  // After the quad the bytes are no records: the second "face" reads the quad's last
  // index as a count of 3 and garbage as indices. Not readable, and no error of its
  // own: the whole stream says what is wrong (here nothing: a quad and a short face).
  CHECK_FALSE(oocsimp::scan_face_range(quad, 1, 2).readable);
  CHECK(load_mesh(d.file("quad2.ply"), d.path()).triangles == std::vector<std::uint64_t>{0, 1, 2, 0, 2, 3});
  // Ascii, and binary with data after the faces, have no table.
  write_file(d.file("ascii.ply"), ascii_ply());
  CHECK_FALSE(oocsimp::open_mesh_input(d.file("ascii.ply"), o).fixed_faces.available());
  write_file(d.file("trailing.ply"), binary_ply_with_faces({{0, 1, 2}}, false) + "x");
  CHECK_FALSE(oocsimp::open_mesh_input(d.file("trailing.ply"), o).fixed_faces.available());
  // An index out of range: the range is not readable (the parts then read the whole
  // stream, which names the face's byte); a range stream meeting it names it too.
  const std::string bad = binary_ply_with_faces({{0, 1, 2}, {1, 9, 2}}, false);
  write_file(d.file("bad.ply"), bad);
  oocsimp::MeshInput m = oocsimp::open_mesh_input(d.file("bad.ply"), o);
  const std::string byte = "byte " + std::to_string(bad.size() - 13);
  CHECK(oocsimp::scan_face_range(m, 0, 1).readable);
  CHECK_FALSE(oocsimp::scan_face_range(m, 1, 2).readable);
  CHECK_THAT(load_error(d.file("bad.ply"), d), Contains(byte) && Contains("vertex index 9 out of range (5 vertices)"));
  CHECK_THAT(input_error([&] { range_triangles(m, 0, 2); }),
             Contains(byte) && Contains("vertex index 9 out of range (5 vertices)"));
}
