// What the reader tests share (tests/test_readers_*.cpp): the reference mesh, the
// files written from it in each format, and the checks of a read mesh and of an error.
#pragma once

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

inline std::vector<double> as_doubles(const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); }

const std::vector<double> kPosD = as_doubles(kPos);
// kPosText as formats without a declared type (OBJ, ascii STL) read it: its numbers
// have no more digits than a float keeps, so the floats nearest them (kPos).
const std::vector<double> kTextD = kPosD;

template <class T>
inline void put(std::string& s, T v, bool big_endian) {
  if (big_endian)
    put_be(s, v);
  else
    put_le(s, v);
}

// Appends integer `v` stored as the PLY scalar type `type`.
inline void put_typed(std::string& s, const std::string& type, long long v, bool be) {
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

inline const char* format_line(bool big_endian) {
  return big_endian ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n";
}

const char* const kXyzFloat = "property float x\nproperty float y\nproperty float z\n";

// The reference mesh as ascii PLY (10 header lines, vertices on lines 11-15, faces on 16-17).
inline std::string ascii_ply() {
  std::string s = "ply\nformat ascii 1.0\ncomment reference mesh\nelement vertex 5\n";
  s += kXyzFloat;
  s += "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (const char* v : kPosText) s += std::string(v) + "\n";
  s += "4 0 1 2 3\n3 1 4 2\n";
  return s;
}

// The reference mesh as binary PLY with float x,y,z and "list uchar int" faces.
inline std::string binary_ply_header(bool be, std::uint64_t vertices = 5, std::uint64_t faces = 2) {
  return std::string("ply\n") + format_line(be) + "element vertex " + std::to_string(vertices) + "\n" + kXyzFloat +
         "element face " + std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

inline void put_faces(std::string& s, const std::vector<std::vector<int>>& faces, bool be) {
  for (const auto& f : faces) {
    s.push_back(char(f.size()));
    for (int i : f) put(s, std::int32_t(i), be);
  }
}

inline std::string binary_ply(bool be) {
  std::string s = binary_ply_header(be);
  for (float f : kPos) put(s, f, be);
  put_faces(s, kFaces, be);
  return s;
}

inline std::string obj_text() {
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

inline std::string ascii_stl() {
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

inline std::string binary_stl(const std::string& header_text, std::uint32_t declared, std::size_t triangles) {
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
inline std::string input_error(F&& f) {
  try {
    f();
  } catch (const oocsimp::InputError& e) {
    return e.what();
  }
  FAIL("no InputError was thrown");
  return {};
}

// The message of the InputError that loading `path` (positions and all triangles) throws.
inline std::string load_error(const std::string& path, const ScratchDir& tmp) {
  return input_error([&] { load_mesh(path, tmp.path()); });
}

// The message of the InputError that open_mesh_input itself throws.
inline std::string open_error(const std::string& path, const ScratchDir& tmp) {
  oocsimp::OpenOptions o;
  o.temp_dir = tmp.path();
  return input_error([&] { oocsimp::open_mesh_input(path, o); });
}

inline void check_same_mesh(const LoadedMesh& a, const LoadedMesh& b) {
  CHECK(a.positions == b.positions);
  CHECK(a.triangles == b.triangles);
  CHECK(a.info.format == b.info.format);
  CHECK(a.info.vertex_count == b.info.vertex_count);
  CHECK(a.info.face_count == b.info.face_count);
  CHECK(a.skipped_faces == b.skipped_faces);
}

}  // namespace
