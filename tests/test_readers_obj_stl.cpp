// Tests of the streaming mesh readers through the public open_mesh_input() API: OBJ and STL.
// Every input is written by the test itself into a scratch folder.
#include <nlohmann/json.hpp>

#include <cstring>
#include <map>
#include <sstream>

#include "reader_test_files.hpp"

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

TEST_CASE("a non-finite OBJ vertex split by its texture coordinates is counted once per vertex it becomes",
          "[readers][obj]") {
  // Found by fuzz_obj_reader: the split vertices were stored, but the count and the
  // first index were the file's (one NaN `v` line), not the arrays' (two vertices).
  ScratchDir dir;
  std::string path = dir.file("nan-seam.obj");
  write_file(path,
             "v 0 0 0\nv nan 0 0\nv 0 1 0\nv 1 1 0\n"
             "vt 0 0\nvt 1 0\nvt 0 1\n"
             "f 1/1 2/2 3/3\n"    // vertices 0 1 2
             "f 3/3 2/1 4/2\n");  // 2/1 is a new pair: vertex 4 (after 4/2, vertex 3), also NaN
  oocsimp::OpenOptions o;
  o.temp_dir = dir.path();
  o.attributes.texture_coordinates = true;
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
  std::uint64_t non_finite = 0, first = ~std::uint64_t(0);
  for (std::uint64_t i = 0; i < in.positions.count; ++i)
    if (!oocsimp::is_finite(in.positions.get(i))) first = std::min(first, i), ++non_finite;
  CHECK(non_finite == 2);
  CHECK(in.info.non_finite_vertices == non_finite);
  CHECK(in.info.first_non_finite_vertex == first);
  CHECK(in.info.first_non_finite_position == "line 2");  // the file's first, where it is the arrays' first
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

TEST_CASE("OBJ reads v and f past vn vt vp g o s l and comment lines, and keeps mtllib and usemtl", "[readers][obj]") {
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
  // The material library and the one material, which every face is of: no seam to
  // split a vertex at.
  CHECK(m.info.materials.libraries == std::vector<std::string>{"scene.mtl"});
  CHECK(m.info.materials.names == std::vector<std::string>{"red"});
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

// An n x n grid over [0, 1]^2 as OBJ: the faces left of x = 0.5 of material "left",
// the rest of "right", the two groups each written in two runs; with `mtllib`.
std::string two_material_obj(int n) {
  std::string s = "mtllib scene.mtl\n";
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      s += "v " + std::to_string(double(i) / n) + " " + std::to_string(double(j) / n) + " 0\n";
  const auto face = [&](int i, int j) {
    const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
    return "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(d) + "\nf " + std::to_string(a) +
           " " + std::to_string(d) + " " + std::to_string(c) + "\n";
  };
  for (int half = 0; half < 2; ++half)
    for (const char* material : {"left", "right"}) {
      s += std::string("usemtl ") + material + "\n";
      for (int j = half * n / 2; j < (half + 1) * n / 2; ++j)
        for (int i = 0; i < n; ++i)
          if ((i < n / 2) == (material[0] == 'l')) s += face(i, j);
    }
  return s;
}

// The faces of an OBJ file written by oocsimp, each with the material of the usemtl
// line before it ("" before any) and its corners' positions.
struct ObjFace {
  std::string material;
  double x[3];
};
std::vector<ObjFace> obj_faces(const std::string& text, std::vector<std::string>* libraries) {
  std::vector<double> xs;
  std::vector<ObjFace> faces;
  std::string material;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string key;
    l >> key;
    if (key == "v") {
      double x = 0;
      l >> x;
      xs.push_back(x);
    } else if (key == "usemtl") {
      l >> material;
    } else if (key == "mtllib") {
      std::string name;
      l >> name;
      libraries->push_back(name);
    } else if (key == "f") {
      ObjFace f{material, {0, 0, 0}};
      for (double& x : f.x) {
        std::string corner;
        l >> corner;
        x = xs[std::stoul(corner.substr(0, corner.find('/'))) - 1];
      }
      faces.push_back(f);
    }
  }
  return faces;
}

}  // namespace

TEST_CASE("OBJ materials: mtllib and usemtl groups survive the edge collapse and clustering", "[readers][obj][cli]") {
  ScratchDir d;
  const int n = 16;
  write_file(d.file("in.obj"), two_material_obj(n));
  // Read: the library, the names in order of first use, one attribute each, and the
  // vertices on x = 0.5 split, one per material.
  {
    oocsimp::MeshInput m = oocsimp::open_mesh_input(d.file("in.obj"));
    CHECK(m.info.materials.libraries == std::vector<std::string>{"scene.mtl"});
    CHECK(m.info.materials.names == std::vector<std::string>{"left", "right"});
    REQUIRE(m.attributes.size() == 2);
    CHECK(m.attributes.attributes[0].name == "material_0");
    CHECK(m.positions.count == std::uint64_t((n + 1) * (n + 1) + n + 1));
  }
  // The collapse keeps the seam between the materials as it keeps a texture seam: each
  // face stays on its material's side of x = 0.5.
  const auto check = [&](const std::string& out, double slack) {
    std::vector<std::string> libraries;
    const std::vector<ObjFace> faces = obj_faces(oocsimp_test::read_file(out), &libraries);
    CHECK(libraries == std::vector<std::string>{"scene.mtl"});
    REQUIRE_FALSE(faces.empty());
    std::size_t left = 0, right = 0, wrong = 0;
    for (const ObjFace& f : faces) {
      const double centre = (f.x[0] + f.x[1] + f.x[2]) / 3;
      left += f.material == "left";
      right += f.material == "right";
      wrong += (f.material == "left" && centre > 0.5 + slack) || (f.material == "right" && centre < 0.5 - slack) ||
               f.material.empty();
    }
    CHECK(left > 0);
    CHECK(right > 0);
    CHECK(wrong == 0);
  };
  const oocsimp_test::CliResult qem =
      oocsimp_test::run_cli("simplify --quiet " + d.file("in.obj") + " -o " + d.file("qem.obj") + " --target-tris 64");
  REQUIRE(qem.exit_code == 0);
  CHECK(qem.err.empty());  // no warning: OBJ keeps the materials
  check(d.file("qem.obj"), 0);
  // Clustering merges across the seam: a face takes the material its corners carry
  // most of, so a face is never more than a cell away from its material's side.
  const oocsimp_test::CliResult grid =
      oocsimp_test::run_cli("simplify --quiet " + d.file("in.obj") + " -o " + d.file("grid.obj") + " --grid 6");
  REQUIRE(grid.exit_code == 0);
  check(d.file("grid.obj"), 1.0 / 6);
  // Formats without materials say what they drop.
  const oocsimp_test::CliResult ply =
      oocsimp_test::run_cli("simplify " + d.file("in.obj") + " -o " + d.file("out.ply") + " --target-tris 64");
  REQUIRE(ply.exit_code == 0);
  CHECK_THAT(ply.err, Catch::Contains("only OBJ and glTF have materials") && Catch::Contains("mtllib scene.mtl"));
  // glTF keeps them (below).
  const oocsimp_test::CliResult glb =
      oocsimp_test::run_cli("simplify " + d.file("in.obj") + " -o " + d.file("out.glb") + " --target-tris 64");
  REQUIRE(glb.exit_code == 0);
  CHECK(glb.err.find("materials") == std::string::npos);
}

namespace {

// The triangles of each primitive of a .glb by its material's name ("" for none), and
// the libraries in its root's extras.mtllib, read from the JSON chunk.
std::map<std::string, std::size_t> glb_faces_per_material(const std::string& bytes,
                                                          std::vector<std::string>* libraries) {
  REQUIRE(bytes.size() >= 20);
  std::uint32_t json_length = 0;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  const nlohmann::json js = nlohmann::json::parse(bytes.substr(20, json_length));
  std::map<std::string, std::size_t> faces;
  for (const nlohmann::json& p : js.at("meshes").at(0).at("primitives")) {
    std::string name;
    if (p.contains("material"))
      name = js.at("materials").at(p.at("material").get<std::size_t>()).at("name").get<std::string>();
    faces[name] += js.at("accessors").at(p.at("indices").get<std::size_t>()).at("count").get<std::size_t>() / 3;
  }
  if (js.contains("extras"))
    for (const nlohmann::json& library : js.at("extras").at("mtllib")) libraries->push_back(library.get<std::string>());
  return faces;
}

std::map<std::string, std::size_t> obj_faces_per_material(const std::vector<ObjFace>& faces) {
  std::map<std::string, std::size_t> counts;
  for (const ObjFace& f : faces) ++counts[f.material];
  return counts;
}

}  // namespace

TEST_CASE("glTF keeps the materials: OBJ to glb to OBJ with the faces of each material", "[readers][glb][obj][cli]") {
  ScratchDir d;
  const int n = 16;  // 2 n^2 = 512 triangles, n^2 of each material
  const std::size_t half = std::size_t(n) * n;
  write_file(d.file("in.obj"), two_material_obj(n));
  const auto simplify = [&](const std::string& in, const std::string& out, int target) {
    const oocsimp_test::CliResult r = oocsimp_test::run_cli("simplify --quiet " + d.file(in) + " -o " + d.file(out) +
                                                            " --target-tris " + std::to_string(target));
    INFO(in << " -> " << out << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(r.err.find("materials") == std::string::npos);
  };
  // At the input's own count nothing is removed: each material keeps its n^2 faces.
  simplify("in.obj", "full.glb", 2 * n * n);
  std::vector<std::string> libraries;
  const std::map<std::string, std::size_t> both{{"left", half}, {"right", half}};
  CHECK(glb_faces_per_material(oocsimp_test::read_file(d.file("full.glb")), &libraries) == both);
  CHECK(libraries == std::vector<std::string>{"scene.mtl"});
  {
    oocsimp::MeshInput m = oocsimp::open_mesh_input(d.file("full.glb"));
    CHECK(m.info.materials.libraries == std::vector<std::string>{"scene.mtl"});
    CHECK(m.info.materials.names == std::vector<std::string>{"left", "right"});
    REQUIRE(m.attributes.size() == 2);
    CHECK(m.attributes.attributes[0].name == "material_0");
    CHECK(m.attributes.attributes[1].name == "material_1");
    // Each primitive holds the vertices of its half: n / 2 + 1 columns of n + 1, the
    // seam's column in both, as the OBJ reader split it.
    CHECK(m.positions.count == std::uint64_t(2 * (n / 2 + 1) * (n + 1)));
  }
  // glb to OBJ: the same groups, each face on its material's side of x = 0.5.
  simplify("full.glb", "back.obj", 2 * n * n);
  libraries.clear();
  const std::vector<ObjFace> back = obj_faces(oocsimp_test::read_file(d.file("back.obj")), &libraries);
  CHECK(libraries == std::vector<std::string>{"scene.mtl"});
  CHECK(obj_faces_per_material(back) == both);
  for (const ObjFace& f : back) {
    const double centre = (f.x[0] + f.x[1] + f.x[2]) / 3;
    CHECK((f.material == "left" ? centre < 0.5 : centre > 0.5));
  }
  // Simplified, the glb and the OBJ of one run have the same faces of each material.
  simplify("in.obj", "small.glb", 64);
  simplify("in.obj", "small.obj", 64);
  libraries.clear();
  const std::map<std::string, std::size_t> small_glb =
      glb_faces_per_material(oocsimp_test::read_file(d.file("small.glb")), &libraries);
  std::vector<std::string> obj_libraries;
  CHECK(small_glb == obj_faces_per_material(obj_faces(oocsimp_test::read_file(d.file("small.obj")), &obj_libraries)));
  CHECK(small_glb.size() == 2);
  CHECK(small_glb.count("left") + small_glb.count("right") == 2);
  CHECK(small_glb.at("left") + small_glb.at("right") == 64);
  // glb to glb keeps them too.
  simplify("full.glb", "small2.glb", 64);
  libraries.clear();
  const std::map<std::string, std::size_t> small2 =
      glb_faces_per_material(oocsimp_test::read_file(d.file("small2.glb")), &libraries);
  CHECK(libraries == std::vector<std::string>{"scene.mtl"});
  CHECK(small2.size() == 2);
  CHECK(small2.count("left") + small2.count("right") == 2);
}

TEST_CASE("formats without materials warn once, naming what they drop", "[readers][obj][cli]") {
  ScratchDir d;
  write_file(d.file("in.obj"), two_material_obj(16));
  for (const char* out : {"o.ply", "o.stl", "o.off"}) {
    const oocsimp_test::CliResult r =
        oocsimp_test::run_cli("simplify --quiet " + d.file("in.obj") + " -o " + d.file(out) + " --target-tris 64");
    INFO(out << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const std::string warning = "only OBJ and glTF have materials";
    const std::size_t at = r.err.find(warning);
    CHECK(at != std::string::npos);
    CHECK(r.err.find(warning, at + 1) == std::string::npos);
    CHECK_THAT(r.err, Catch::Contains("mtllib scene.mtl") && Catch::Contains("2 materials (usemtl)") &&
                          Catch::Contains("write .obj or .glb"));
  }
}
