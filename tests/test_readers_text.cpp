// Tests of the streaming mesh readers through the public open_mesh_input() API: text encodings, number ranges,
// multi-frame zstd, FIFOs and face ranges. Every input is written by the test itself into a scratch folder.
#include "reader_test_files.hpp"

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
