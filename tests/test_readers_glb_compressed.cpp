// Tests of the streaming mesh readers through the public open_mesh_input() API: glb, and zstd- and gzip-compressed
// inputs. Every input is written by the test itself into a scratch folder.
#include "reader_test_files.hpp"

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
  const oocsimp_test::CliResult r = oocsimp_test::run_cli("info --quiet " + dir.file("bad.glb"));
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
