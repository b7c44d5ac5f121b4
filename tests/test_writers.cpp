// Tests of write_mesh() and format_for_path(): every format round-trips exactly
// through the readers, and writing is atomic (temporary name, then rename).
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/stat.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "io/attribute_array.hpp"
#include "oocsimp/error.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using Catch::Matchers::StartsWith;
using oocsimp::format_for_path;
using oocsimp::MeshFormat;
using oocsimp::ScalarType;
using oocsimp::write_mesh;
using oocsimp_test::load_mesh;
using oocsimp_test::LoadedMesh;
using oocsimp_test::ScratchDir;

namespace {

// Values that need every digit of the shortest representation, tiny, huge and
// negative ones, and one subnormal.
const std::vector<float> kPositions = {0.1f,
                                       -3.25e7f,
                                       1e-20f,  //
                                       1.0f,
                                       2.0f,
                                       3.0f,  //
                                       -0.3f,
                                       1.0f / 3.0f,
                                       16777217.0f,  //
                                       std::numeric_limits<float>::max(),
                                       -std::numeric_limits<float>::min(),
                                       1e-40f,  //
                                       123.456f,
                                       -7.0e-8f,
                                       9.999999e9f};
const std::vector<std::uint32_t> kTriangles = {0, 1, 2, 2, 1, 3, 4, 0, 3, 1, 4, 2};

std::vector<double> as_doubles(const std::vector<float>& v) { return std::vector<double>(v.begin(), v.end()); }
std::vector<std::uint64_t> as_u64(const std::vector<std::uint32_t>& v) {
  return std::vector<std::uint64_t>(v.begin(), v.end());
}

// Writes `positions`/`triangles` to dir/name in `format` at `precision`, reads the
// file back and checks exact equality and that nothing but the output is left in the
// folder.
LoadedMesh round_trip(const std::string& name, MeshFormat format, const std::string& expected_format,
                      const std::vector<double>& positions, const std::vector<std::uint32_t>& triangles,
                      ScalarType precision) {
  ScratchDir dir, tmp;
  std::string path = dir.file(name);
  write_mesh(path, positions, triangles, format, precision);
  CHECK(dir.entries() == std::vector<std::string>{name});
  LoadedMesh m = load_mesh(path, tmp.path());
  CHECK(m.info.format == expected_format);
  CHECK(m.info.compressed == (name.size() > 4 && name.compare(name.size() - 4, 4, ".zst") == 0));
  CHECK(m.info.vertex_count == positions.size() / 3);
  CHECK(m.info.face_count == triangles.size() / 3);
  CHECK(m.info.double_precision == (precision == ScalarType::f64));
  CHECK(m.positions == positions);
  CHECK(m.triangles == as_u64(triangles));
  CHECK(m.skipped_faces == 0);
  return m;
}

LoadedMesh round_trip(const std::string& name, MeshFormat format, const std::string& expected_format,
                      const std::vector<float>& positions = kPositions,
                      const std::vector<std::uint32_t>& triangles = kTriangles) {
  return round_trip(name, format, expected_format, as_doubles(positions), triangles, ScalarType::f32);
}

// Doubles that no float holds: UTM-like coordinates with sub-millimetre digits,
// 0.1, a third, and the extremes of the double range.
const std::vector<double> kDoublePositions = {451234.56789012345,
                                              5412345.678901234,
                                              201.33333333333334,  //
                                              0.1,
                                              -1.0 / 3.0,
                                              1e-300,  //
                                              4.5e5,
                                              5.4e6 + 1e-7,
                                              -2e300,  //
                                              std::numeric_limits<double>::max(),
                                              -std::numeric_limits<double>::min(),
                                              4.9e-324,  //
                                              123.456,
                                              -7.0e-8,
                                              9.999999999999999e9};

}  // namespace

TEST_CASE("write_mesh binary PLY round trip is exact", "[writers]") {
  LoadedMesh m = round_trip("out.ply", MeshFormat::ply_binary, "ply binary_little_endian");
  CHECK(m.info.positions_in_place);
  CHECK(m.info.elements ==
        std::vector<std::string>{"vertex 5 (x float, y float, z float)", "face 4 (vertex_indices list uchar uint)"});
}

TEST_CASE("write_mesh ascii PLY round trip is exact", "[writers]") {
  round_trip("out.ply", MeshFormat::ply_ascii, "ply ascii");
}

TEST_CASE("write_mesh OBJ round trip is exact", "[writers]") { round_trip("out.obj", MeshFormat::obj, "obj"); }

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

TEST_CASE("write_mesh of an empty mesh reads back empty, as PLY and OFF, and OBJ has nothing to read", "[writers]") {
  const std::vector<float> no_positions;
  const std::vector<std::uint32_t> no_triangles;
  round_trip("empty.ply", MeshFormat::ply_binary, "ply binary_little_endian", no_positions, no_triangles);
  round_trip("empty.ply", MeshFormat::ply_ascii, "ply ascii", no_positions, no_triangles);
  round_trip("empty.off", MeshFormat::off, "off", no_positions, no_triangles);
  // OBJ has no header to declare an empty mesh: the file is a comment, which the
  // reader refuses like any OBJ without a vertex or face.
  ScratchDir dir;
  write_mesh(dir.file("empty.obj"), {}, {}, MeshFormat::obj);
  CHECK(oocsimp_test::read_file(dir.file("empty.obj")) == "# oocsimp\n");
  CHECK_THROWS_AS(load_mesh(dir.file("empty.obj"), dir.path()), oocsimp::InputError);
}

TEST_CASE("write_mesh replaces an existing file and leaves no temporary file", "[writers]") {
  ScratchDir dir, tmp;
  std::string path = dir.file("out.obj");
  oocsimp_test::write_file(path, "old content\n");
  write_mesh(path, as_doubles(kPositions), kTriangles, MeshFormat::obj);
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
    CHECK_THROWS_AS(write_mesh(path, as_doubles(kPositions), kTriangles, MeshFormat::ply_binary), oocsimp::IoError);
  }
  SECTION("compressed OBJ") {
    path = dir.file("missing/out.obj.zst");
    CHECK_THROWS_AS(write_mesh(path, as_doubles(kPositions), kTriangles, MeshFormat::obj), oocsimp::IoError);
  }
  CHECK_FALSE(oocsimp_test::file_exists(path));
  CHECK(dir.entries().empty());
}

TEST_CASE("write_mesh into a path that is a directory throws IoError", "[writers]") {
  ScratchDir dir;
  std::string path = dir.file("taken");
  REQUIRE(::mkdir(path.c_str(), 0755) == 0);
  CHECK_THROWS_AS(write_mesh(path, as_doubles(kPositions), kTriangles, MeshFormat::ply_binary), oocsimp::IoError);
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
  CHECK(format_for_path("obj.ply", false) == MeshFormat::ply_binary);
  CHECK(format_for_path(".obj", false) == MeshFormat::obj);
  CHECK(format_for_path("a.stl", false) == MeshFormat::stl_binary);
  CHECK(format_for_path("a.STL", true) == MeshFormat::stl_ascii);
  CHECK(format_for_path("a.stl.zst", false) == MeshFormat::stl_binary);
  CHECK(format_for_path("a.off", false) == MeshFormat::off);
  CHECK(format_for_path("a.Off.zst", true) == MeshFormat::off);
}

TEST_CASE("format_for_path refuses a name it cannot write, listing what it can", "[writers]") {
  for (const char* name : {"a.gltf", "noextension", "obj", "a.obj.gzip", "a.objx", "", ".zst", "a.zst", "a.gz",
                           "a.ply.zst.zst", "a.ply.gz.zst", "a.3ds"}) {
    CAPTURE(name);
    try {
      format_for_path(name, false);
      FAIL("no UsageError");
    } catch (const oocsimp::UsageError& e) {
      std::string msg = e.what();
      for (const char* ext : {".ply", ".obj", ".stl", ".off", ".glb", ".zst"})
        CHECK(msg.find(ext) != std::string::npos);
      CHECK(msg.find('\n') == std::string::npos);
    }
  }
}

TEST_CASE("write_mesh double PLY and text formats round trip doubles exactly", "[writers][precision]") {
  struct Case {
    const char* name;
    MeshFormat format;
    const char* expected;
  };
  const Case cases[] = {{"d.ply", MeshFormat::ply_binary, "ply binary_little_endian"},
                        {"d.ply", MeshFormat::ply_ascii, "ply ascii"},
                        {"d.obj", MeshFormat::obj, "obj"},
                        {"d.ply.zst", MeshFormat::ply_binary, "ply binary_little_endian"},
                        {"d.obj.zst", MeshFormat::obj, "obj"}};
  for (const Case& c : cases) {
    CAPTURE(c.name, c.expected);
    round_trip(c.name, c.format, c.expected, kDoublePositions, kTriangles, ScalarType::f64);
  }
  ScratchDir dir;
  write_mesh(dir.file("d.ply"), kDoublePositions, kTriangles, MeshFormat::ply_binary, ScalarType::f64);
  LoadedMesh m = load_mesh(dir.file("d.ply"), dir.path());
  CHECK(m.info.positions_in_place);
  CHECK(m.info.elements ==
        std::vector<std::string>{"vertex 5 (x double, y double, z double)", "face 4 (vertex_indices list uchar uint)"});
}

TEST_CASE("write_mesh at float precision writes the doubles rounded to float", "[writers][precision]") {
  std::vector<double> rounded;
  for (double v : kDoublePositions) rounded.push_back(std::isfinite(float(v)) ? double(float(v)) : 0.0);
  std::vector<double> in;  // finite as float: the values, rounded where a float cannot hold them
  for (double v : kDoublePositions) in.push_back(std::isfinite(float(v)) ? v : 0.0);
  for (MeshFormat f : {MeshFormat::ply_binary, MeshFormat::ply_ascii, MeshFormat::obj}) {
    ScratchDir dir;
    std::string path = dir.file(f == MeshFormat::obj ? "f.obj" : "f.ply");
    write_mesh(path, in, kTriangles, f, ScalarType::f32);
    LoadedMesh m = load_mesh(path, dir.path());
    CHECK_FALSE(m.info.double_precision);
    CHECK(m.positions == rounded);
  }
}

namespace {

// The corners of every triangle of a loaded mesh, as 9 doubles per triangle: meshes
// compared by geometry, whatever their vertex numbering (STL repeats corners).
std::vector<std::array<double, 9>> corner_triples(const std::vector<double>& pos,
                                                  const std::vector<std::uint64_t>& tri) {
  std::vector<std::array<double, 9>> out;
  for (std::size_t t = 0; t < tri.size(); t += 3) {
    std::array<double, 9> c;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) c[std::size_t(3 * k + a)] = pos[3 * tri[t + std::size_t(k)] + std::size_t(a)];
    out.push_back(c);
  }
  return out;
}

// A closed tetrahedron with outward-facing triangles (counter-clockwise seen from
// outside), at UTM-like coordinates: float values.
const std::vector<float> kTetra = {450000.f, 5400000.f, 200.f, 450001.f, 5400000.f, 200.f,
                                   450000.f, 5400001.f, 200.f, 450000.f, 5400000.f, 201.f};
const std::vector<std::uint32_t> kTetraTriangles = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};

}  // namespace

TEST_CASE("write_mesh STL, binary and ascii, reads back as the same triangles with outward normals", "[writers][stl]") {
  const std::vector<double> pos = as_doubles(kTetra);
  const auto want = corner_triples(pos, as_u64(kTetraTriangles));
  struct Case {
    const char* name;
    MeshFormat format;
    const char* expected;
  };
  for (const Case& c :
       {Case{"t.stl", MeshFormat::stl_binary, "stl binary"}, Case{"t.stl", MeshFormat::stl_ascii, "stl ascii"},
        Case{"t.stl.zst", MeshFormat::stl_binary, "stl binary"},
        Case{"t.stl.zst", MeshFormat::stl_ascii, "stl ascii"}}) {
    CAPTURE(c.name, c.expected);
    ScratchDir dir, tmp;
    std::string path = dir.file(c.name);
    write_mesh(path, pos, kTetraTriangles, c.format);
    CHECK(dir.entries() == std::vector<std::string>{c.name});
    LoadedMesh m = load_mesh(path, tmp.path());
    CHECK(m.info.format == c.expected);
    CHECK(m.info.face_count == 4);
    CHECK(corner_triples(m.positions, m.triangles) == want);
    if (c.format == MeshFormat::stl_binary && std::string(c.name) == "t.stl") {
      // 84 + 50 bytes per triangle; the header must not look like ascii STL.
      std::string bytes = oocsimp_test::read_file(path);
      REQUIRE(bytes.size() == 84 + 4 * 50);
      CHECK(bytes.compare(0, 5, "solid") != 0);
      // Facet normals: unit, pointing away from the tetrahedron's centroid.
      const double centre[3] = {450000.25, 5400000.25, 200.25};
      for (std::size_t t = 0; t < 4; ++t) {
        float n[3];
        std::memcpy(n, bytes.data() + 84 + 50 * t, 12);
        CHECK(std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]) == Approx(1.0).epsilon(1e-6));
        const std::array<double, 9>& c3 = want[t];
        double out = 0;
        for (std::size_t a = 0; a < 3; ++a) out += n[a] * ((c3[a] + c3[3 + a] + c3[6 + a]) / 3 - centre[a]);
        CHECK(out > 0);
      }
    }
  }
}

TEST_CASE("write_mesh ascii STL keeps doubles at double precision", "[writers][stl][precision]") {
  ScratchDir dir;
  std::vector<double> pos = {451234.56789012345, 5412345.678901234, 201.33333333333334,
                             451235.1,           5412345.2,         201.3,
                             451234.3,           5412346.4,         201.7};
  write_mesh(dir.file("d.stl"), pos, {0, 1, 2}, MeshFormat::stl_ascii, ScalarType::f64);
  LoadedMesh m = load_mesh(dir.file("d.stl"), dir.path());
  CHECK(corner_triples(m.positions, m.triangles) == corner_triples(pos, {0, 1, 2}));
  // Binary STL is float32 by format.
  write_mesh(dir.file("b.stl"), pos, {0, 1, 2}, MeshFormat::stl_binary, ScalarType::f64);
  LoadedMesh b = load_mesh(dir.file("b.stl"), dir.path());
  std::vector<double> rounded;
  for (double v : pos) rounded.push_back(double(float(v)));
  CHECK(corner_triples(b.positions, b.triangles) == corner_triples(rounded, {0, 1, 2}));
}

// OFF has no reader in the project: parsed here, by the format's definition.
TEST_CASE("write_mesh OFF holds the vertices and triangles exactly", "[writers][off]") {
  for (ScalarType precision : {ScalarType::f32, ScalarType::f64}) {
    ScratchDir dir;
    const std::vector<double> pos = precision == ScalarType::f32 ? as_doubles(kPositions) : kDoublePositions;
    write_mesh(dir.file("m.off"), pos, kTriangles, MeshFormat::off, precision);
    CHECK(dir.entries() == std::vector<std::string>{"m.off"});
    std::istringstream in(oocsimp_test::read_file(dir.file("m.off")));
    std::string magic;
    std::size_t nv = 0, nf = 0, ne = 1;
    in >> magic >> nv >> nf >> ne;
    CHECK(magic == "OFF");
    REQUIRE(nv == 5);
    REQUIRE(nf == 4);
    CHECK(ne == 0);
    std::vector<double> got(3 * nv);
    for (double& v : got) {
      std::string word;
      in >> word;
      v = std::strtod(word.c_str(), nullptr);
      if (precision == ScalarType::f32) v = double(std::strtof(word.c_str(), nullptr));  // float text, as a float
    }
    CHECK(got == pos);
    std::vector<std::uint32_t> tri;
    for (std::size_t f = 0; f < nf; ++f) {
      std::uint32_t n = 0, a = 0, b = 0, c = 0;
      in >> n >> a >> b >> c;
      CHECK(n == 3);
      tri.insert(tri.end(), {a, b, c});
    }
    CHECK(tri == kTriangles);
    std::string rest;
    CHECK_FALSE(in >> rest);
  }
  ScratchDir dir;
  write_mesh(dir.file("m.off.zst"), as_doubles(kPositions), kTriangles, MeshFormat::off);
  CHECK(dir.entries() == std::vector<std::string>{"m.off.zst"});
}

TEST_CASE("OBJ keeps vertex normals as vn lines the faces name with the vertex's index", "[writers][obj]") {
  ScratchDir dir;
  const std::vector<double> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<std::uint32_t> tri = {0, 1, 2};
  oocsimp::AttributeValues attrs;
  for (const char* n : {"red", "green", "blue", "nx", "ny", "nz"})
    attrs.attributes.push_back({n, oocsimp::AttributeType::f32, 0, 1});
  // Per vertex: a grey, then the normal (0, 0, 1), (0, 0.6, 0.8), (1, 0, 0).
  attrs.values = {0.5, 0.5, 0.5, 0, 0, 1, 0.5, 0.5, 0.5, 0, 0.6, 0.8, 0.5, 0.5, 0.5, 1, 0, 0};
  CHECK(oocsimp::format_keeps_attributes(MeshFormat::obj, attrs));
  write_mesh(dir.file("n.obj"), pos, tri, MeshFormat::obj, ScalarType::f32, &attrs);
  CHECK(oocsimp_test::read_file(dir.file("n.obj")) ==
        "# oocsimp\nv 0 0 0 0.5 0.5 0.5\nvn 0 0 1\nv 1 0 0 0.5 0.5 0.5\nvn 0 0.6 0.8\nv 0 1 0 0.5 0.5 0.5\nvn 1 0 0\n"
        "f 1//1 2//2 3//3\n");
  // Another attribute beside them is not kept.
  attrs.attributes.push_back({"quality", oocsimp::AttributeType::f32, 0, 1});
  CHECK_FALSE(oocsimp::format_keeps_attributes(MeshFormat::obj, attrs));
}

namespace {

// A .glb read back by the specification (glTF 2.0 §4.4): its JSON and BIN chunks.
struct Glb {
  nlohmann::json json;
  std::string bin;
};

Glb read_glb(const std::string& bytes) {
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  REQUIRE(bytes.size() >= 20);
  CHECK(u32(0) == 0x46546C67);  // "glTF"
  CHECK(u32(4) == 2);
  CHECK(u32(8) == bytes.size());
  const std::uint32_t json_length = u32(12);
  CHECK(u32(16) == 0x4E4F534A);
  CHECK(json_length % 4 == 0);
  Glb g;
  g.json = nlohmann::json::parse(bytes.substr(20, json_length));
  if (20 + json_length < bytes.size()) {
    CHECK(u32(20 + json_length + 4) == 0x004E4942);
    g.bin = bytes.substr(28 + json_length, u32(20 + json_length));
    CHECK(28 + json_length + g.bin.size() == bytes.size());
  }
  return g;
}

// Accessor `a`'s values as floats (or unsigned ints, converted).
std::vector<double> accessor(const Glb& g, int a) {
  const auto& acc = g.json["accessors"][a];
  const auto& view = g.json["bufferViews"][acc["bufferView"].get<int>()];
  const std::size_t width = acc["type"] == "VEC2" ? 2 : acc["type"] == "VEC3" ? 3 : acc["type"] == "VEC4" ? 4 : 1;
  const std::size_t n = acc["count"].get<std::size_t>() * width;
  REQUIRE(view["byteLength"].get<std::size_t>() == 4 * n);
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* p = g.bin.data() + view["byteOffset"].get<std::size_t>() + 4 * i;
    if (acc["componentType"] == 5126) {
      float f;
      std::memcpy(&f, p, 4);
      out[i] = f;
    } else {
      std::uint32_t u;
      std::memcpy(&u, p, 4);
      out[i] = u;
    }
  }
  return out;
}

}  // namespace

TEST_CASE("glTF binary holds positions, indices, unit normals and colours as the specification reads them",
          "[writers][gltf]") {
  ScratchDir dir;
  const std::vector<double> pos = {0, 0, 0, 1, 0, 0, 0, 2, 0, 0.1, 0.2, 3};
  const std::vector<std::uint32_t> tri = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  oocsimp::AttributeValues attrs;
  for (const char* n : {"red", "green", "blue", "alpha"})
    attrs.attributes.push_back({n, oocsimp::AttributeType::u8, 0, 255});
  for (const char* n : {"nx", "ny", "nz", "u", "v"})
    attrs.attributes.push_back({n, oocsimp::AttributeType::f32, -1, 1});
  for (int v = 0; v < 4; ++v)  // normal (0, 0, 2): not unit; uv (0.25 v, 0.75)
    for (double x : {255.0, 51.0 * v, 0.0, 255.0, 0.0, 0.0, 2.0, 0.25 * v, 0.75}) attrs.values.push_back(x);
  CHECK(oocsimp::format_keeps_attributes(MeshFormat::glb, attrs));
  CHECK(format_for_path("m.glb", false) == MeshFormat::glb);
  write_mesh(dir.file("m.glb"), pos, tri, MeshFormat::glb, ScalarType::f32, &attrs);
  const Glb g = read_glb(oocsimp_test::read_file(dir.file("m.glb")));
  const auto& prim = g.json["meshes"][0]["primitives"][0];
  CHECK(prim["mode"] == 4);
  std::vector<double> as_floats;
  for (double x : pos) as_floats.push_back(double(float(x)));  // glTF positions are float
  CHECK(accessor(g, prim["attributes"]["POSITION"].get<int>()) == as_floats);
  const auto& p = g.json["accessors"][prim["attributes"]["POSITION"].get<int>()];
  CHECK(p["min"] == nlohmann::json::array({0, 0, 0}));
  CHECK(p["max"][1] == 2);
  CHECK(p["max"][2] == 3);
  const std::vector<double> indices = accessor(g, prim["indices"].get<int>());
  CHECK(indices == std::vector<double>(tri.begin(), tri.end()));
  const std::vector<double> normals = accessor(g, prim["attributes"]["NORMAL"].get<int>());
  for (std::size_t v = 0; v < 4; ++v) CHECK(normals[3 * v + 2] == 1.0);  // made unit
  const std::vector<double> colours = accessor(g, prim["attributes"]["COLOR_0"].get<int>());
  REQUIRE(colours.size() == 16);
  CHECK(colours[4 * 2 + 1] == Approx(102.0 / 255).epsilon(1e-6));
  CHECK(colours[4 * 3 + 3] == 1.0);
  // TEXCOORD_0 with v turned to glTF's top-left origin.
  const std::vector<double> uv = accessor(g, prim["attributes"]["TEXCOORD_0"].get<int>());
  CHECK(uv == std::vector<double>{0, 0.25, 0.25, 0.25, 0.5, 0.25, 0.75, 0.25});
  // Another attribute is dropped; a mesh without triangles is an empty scene.
  attrs.attributes.push_back({"quality", oocsimp::AttributeType::f32, 0, 1});
  CHECK_FALSE(oocsimp::format_keeps_attributes(MeshFormat::glb, attrs));
  write_mesh(dir.file("empty.glb"), {}, {}, MeshFormat::glb);
  const Glb e = read_glb(oocsimp_test::read_file(dir.file("empty.glb")));
  CHECK(e.bin.empty());
  CHECK(e.json["scenes"][0]["nodes"].empty());
}

TEST_CASE("simplify writes the format its output's extension names, and refuses others before any work",
          "[writers][cli]") {
  ScratchDir d;
  auto q = [](const std::string& s) { return "'" + s + "'"; };
  REQUIRE(oocsimp_test::run_cli("generate --tris 5000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  const std::string base = "simplify --quiet " + q(d.file("s.ply")) + " --grid 12 --tmp " + q(d.path()) + " -o ";
  REQUIRE(oocsimp_test::run_cli(base + q(d.file("ref.ply"))).exit_code == 0);
  LoadedMesh ref = load_mesh(d.file("ref.ply"), d.path());
  const auto want = corner_triples(ref.positions, ref.triangles);
  struct Case {
    const char* name;
    const char* flags;
    const char* format;
  };
  for (const Case& c : {Case{"o.stl", "", "stl binary"}, Case{"o.stl", " --ascii", "stl ascii"},
                        Case{"o.STL.zst", "", "stl binary"}, Case{"o.obj", "", "obj"}}) {
    CAPTURE(c.name, c.flags);
    oocsimp_test::CliResult r = oocsimp_test::run_cli(base + q(d.file(c.name)) + c.flags);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    LoadedMesh m = load_mesh(d.file(c.name), d.path());
    CHECK(m.info.format == c.format);
    CHECK(corner_triples(m.positions, m.triangles) == want);
  }
  REQUIRE(oocsimp_test::run_cli(base + q(d.file("o.off"))).exit_code == 0);
  CHECK(oocsimp_test::read_file(d.file("o.off")).compare(0, 4, "OFF\n") == 0);
  for (const char* name : {"o.gltf", "o.off.bz2", "noext"}) {
    CAPTURE(name);
    oocsimp_test::CliResult r = oocsimp_test::run_cli(base + q(d.file(name)));
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(".stl") != std::string::npos);
    CHECK_FALSE(oocsimp_test::file_exists(d.file(name)));
  }
  // Refused before any work: no temporary position array, no spill was made.
  for (const std::string& e : d.entries()) CHECK(e.find("oocsimp-") == std::string::npos);
}

TEST_CASE("text coordinates: the shortest float for float output, the shortest double for double output",
          "[writers][precision]") {
  ScratchDir dir;
  const std::vector<double> pos = {double(0.1f), 0.5, -2, 1, 0, 0, 0, 1, 0};
  write_mesh(dir.file("f.ply"), pos, {0, 1, 2}, MeshFormat::ply_ascii, ScalarType::f32);
  write_mesh(dir.file("f.obj"), pos, {0, 1, 2}, MeshFormat::obj, ScalarType::f32);
  write_mesh(dir.file("d.obj"), {451234.5673829, 0.5, -2, 1, 0, 0, 0, 1, 0}, {0, 1, 2}, MeshFormat::obj,
             ScalarType::f64);
  CHECK(oocsimp_test::read_file(dir.file("f.ply")).find("\n0.1 0.5 -2\n") != std::string::npos);
  CHECK(oocsimp_test::read_file(dir.file("f.obj")).find("\nv 0.1 0.5 -2\n") != std::string::npos);
  CHECK(oocsimp_test::read_file(dir.file("d.obj")).find("\nv 451234.5673829 0.5 -2\n") != std::string::npos);
  // Read back: the float text as the same floats, the double text as the same doubles.
  LoadedMesh f = load_mesh(dir.file("f.obj"), dir.path());
  CHECK_FALSE(f.info.double_precision);
  CHECK(f.positions == pos);
  LoadedMesh d = load_mesh(dir.file("d.obj"), dir.path());
  CHECK(d.info.double_precision);
  CHECK(d.positions[0] == 451234.5673829);
}

TEST_CASE("simplify writes area-weighted unit normals per vertex with normals asked", "[writers][cli]") {
  oocsimp_test::ScratchDir d;
  auto normals_of = [](const std::string& path) {
    oocsimp::MeshInput m = oocsimp::open_mesh_input(path);
    int at[3] = {-1, -1, -1};
    for (std::size_t k = 0; k < m.attributes.size(); ++k)
      for (int j = 0; j < 3; ++j)
        if (m.attributes.attributes[k].name == std::string("n") + "xyz"[j]) at[j] = int(k);
    REQUIRE(at[0] >= 0);
    REQUIRE(at[1] >= 0);
    REQUIRE(at[2] >= 0);
    std::vector<std::array<double, 6>> out;  // position, normal
    for (std::uint64_t v = 0; v < m.positions.count; ++v) {
      const oocsimp::Vec3d p = m.positions.get(v);
      out.push_back({p.x, p.y, p.z, attribute_value(m.attributes, v, std::size_t(at[0])),
                     attribute_value(m.attributes, v, std::size_t(at[1])),
                     attribute_value(m.attributes, v, std::size_t(at[2]))});
    }
    return out;
  };
  // The octahedron: each corner has four faces of equal area around its axis, so its
  // normal is the axis itself. (A target at its own count gives it back.)
  oocsimp_test::write_binary_ply(d.file("oct.ply"), {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1},
                                 {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5});
  REQUIRE(oocsimp_test::run_cli("simplify --quiet '" + d.file("oct.ply") + "' -o '" + d.file("o.ply") +
                                "' --target-tris 8 --normals")
              .exit_code == 0);
  for (const auto& v : normals_of(d.file("o.ply")))
    for (int k = 0; k < 3; ++k) CHECK(v[3 + std::size_t(k)] == Approx(v[std::size_t(k)]).margin(1e-7));
  // A plane z = 0.3 x - 0.2 y + 0.1, simplified: every normal is (-0.3, 0.2, 1) / |.|.
  oocsimp_test::write_plane_ply(d.file("plane.ply"), 40, 0.3, -0.2, 0.1);
  REQUIRE(oocsimp_test::run_cli("simplify --quiet '" + d.file("plane.ply") + "' -o '" + d.file("p.ply") +
                                "' --target-tris 100 --normals")
              .exit_code == 0);
  const double l = std::sqrt(0.09 + 0.04 + 1);
  for (const auto& v : normals_of(d.file("p.ply"))) {
    CHECK(v[3] == Approx(-0.3 / l).margin(1e-6));
    CHECK(v[4] == Approx(0.2 / l).margin(1e-6));
    CHECK(v[5] == Approx(1 / l).margin(1e-6));
  }
}
