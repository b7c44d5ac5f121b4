// Tests of the streaming mesh readers through the public open_mesh_input() API: damaged and refused inputs, and
// temporary files. Every input is written by the test itself into a scratch folder.
#include "reader_test_files.hpp"

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
