// Tests of the streaming mesh readers through the public open_mesh_input() API: PLY: positions, fanned faces, elements
// and properties. Every input is written by the test itself into a scratch folder.
#include "reader_test_files.hpp"

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
