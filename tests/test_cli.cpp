#include <catch2/catch.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

std::string small_ply_header(int nv, int nf) {
  return "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(nv) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(nf) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

// Four vertices and two triangles, with one face index replaced by `bad_index`
// and the vertex coordinate 0 of vertex 1 by `x1`.
std::string small_ply(int bad_index, float x1) {
  std::string s = small_ply_header(4, 2);
  float v[12] = {0, 0, 0, x1, 0, 0, 1, 1, 0, 0, 1, 0};
  for (float f : v) put_le(s, f);
  int t[6] = {0, 1, 2, 0, 2, bad_index};
  for (int i = 0; i < 6; i += 3) {
    s.push_back(3);
    for (int k = 0; k < 3; ++k) put_le(s, std::int32_t(t[i + k]));
  }
  return s;
}

void expect_bad_input(const ScratchDir& d, const std::string& file, const char* what) {
  CliResult r =
      run_cli("simplify --quiet " + q(file) + " -o " + q(d.file("out.ply")) + " --grid 4 --tmp " + q(d.path()));
  INFO(what << ": " << r.err);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find(file) != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);  // one line
  CHECK_FALSE(file_exists(d.file("out.ply")));
}

}  // namespace

TEST_CASE("simplify writes the output, the stats and a summary", "[cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 100000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  CliResult r = run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --grid 32 --stats " +
                        q(d.file("st.json")));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("Mtri/s") != std::string::npos);
  LoadedMesh m = load_mesh(d.file("o.ply"));
  CHECK(m.triangle_count() > 1000);
  std::string js = read_file(d.file("st.json"));
  CHECK(js.find("\"triangles\": " + std::to_string(m.triangle_count())) != std::string::npos);
  CHECK(js.find("\"peak_anon_bytes\"") != std::string::npos);
  CHECK(js.find("\"input_mtris_per_second\"") != std::string::npos);
  // Only the inputs and outputs remain: no temporary files.
  CHECK(d.entries() == std::vector<std::string>{"o.ply", "s.ply", "st.json"});
}

TEST_CASE("simplify output is byte-identical for --threads 1 and 2", "[cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 200000 --shape terrain --quiet -o " + q(d.file("t.ply"))).exit_code == 0);
  for (const char* t : {"1", "2"})
    REQUIRE(run_cli(std::string("simplify --quiet --threads ") + t + " " + q(d.file("t.ply")) + " -o " +
                    q(d.file(std::string("o") + t + ".ply")) + " --grid 100")
                .exit_code == 0);
  std::string a = read_file(d.file("o1.ply")), b = read_file(d.file("o2.ply"));
  CHECK(a.size() > 10000);
  CHECK(a == b);
  // Nor does the spill's compression change it.
  for (const char* c : {"zstd", "none"}) {
    REQUIRE(run_cli(std::string("simplify --quiet --spill-compress ") + c + " " + q(d.file("t.ply")) + " -o " +
                    q(d.file(std::string("o") + c + ".ply")) + " --grid 100")
                .exit_code == 0);
    CHECK(read_file(d.file(std::string("o") + c + ".ply")) == a);
  }
  CHECK(
      run_cli("simplify --quiet --spill-compress lz4 " + q(d.file("t.ply")) + " -o " + q(d.file("x.ply"))).exit_code ==
      2);
}

TEST_CASE("every output format is chosen by extension", "[cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  LoadedMesh ref;
  for (const char* out : {"o.ply", "o.obj", "o.ply.zst", "o.obj.zst"}) {
    REQUIRE(run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file(out)) + " --grid 16").exit_code == 0);
    LoadedMesh m = load_mesh(d.file(out));
    if (ref.positions.empty()) ref = m;
    CHECK(m.triangles == ref.triangles);
    CHECK(m.positions == ref.positions);
  }
  REQUIRE(run_cli("simplify --quiet --ascii " + q(d.file("s.ply")) + " -o " + q(d.file("a.ply")) + " --grid 16")
              .exit_code == 0);
  CHECK(read_file(d.file("a.ply")).find("format ascii 1.0") != std::string::npos);
  CHECK(load_mesh(d.file("a.ply")).positions == ref.positions);
  // --normals into OBJ: a vn line per vertex, no warning, the same mesh.
  const CliResult r = run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("n.obj")) + " --grid 16 --normals");
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("warning") == std::string::npos);
  const std::string obj = read_file(d.file("n.obj"));
  std::size_t v = 0, vn = 0;
  for (std::size_t at = obj.find("\nv "); at != std::string::npos; at = obj.find("\nv ", at + 1)) ++v;
  for (std::size_t at = obj.find("\nvn "); at != std::string::npos; at = obj.find("\nvn ", at + 1)) ++vn;
  CHECK(v == ref.vertex_count());
  CHECK(vn == v);
  CHECK(load_mesh(d.file("n.obj")).triangles == ref.triangles);
}

TEST_CASE("bad input exits 3 with one line naming the file and no output", "[cli]") {
  ScratchDir d;
  std::string good = small_ply(3, 1.0f);
  write_file(d.file("truncated.ply"), good.substr(0, good.size() - 7));
  expect_bad_input(d, d.file("truncated.ply"), "truncated");
  write_file(d.file("range.ply"), small_ply(4, 1.0f));
  expect_bad_input(d, d.file("range.ply"), "out of range");
  // (NaN coordinates are not among these: their faces are skipped, see test_damaged_input.)
  write_file(d.file("huge.obj"), "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_bad_input(d, d.file("huge.obj"), "beyond float range");
  write_file(d.file("garbage.ply"), "plyx\n\x01\x02");
  expect_bad_input(d, d.file("garbage.ply"), "garbage");
}

TEST_CASE("usage errors exit 2, missing files exit 4", "[cli]") {
  ScratchDir d;
  CHECK(run_cli("").exit_code == 2);
  CHECK(run_cli("simplify").exit_code == 2);
  CHECK(run_cli("frobnicate").exit_code == 2);
  CHECK(run_cli("generate --tris 10 --shape cone -o " + q(d.file("x.ply"))).exit_code == 2);
  write_file(d.file("s.ply"), small_ply(3, 1.0f));
  CHECK(run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --grid 4 --cell 0.1").exit_code ==
        2);
  CHECK(run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --ratio 7").exit_code == 2);
  CliResult r = run_cli("simplify " + q(d.file("missing.ply")) + " -o " + q(d.file("o.ply")));
  CHECK(r.exit_code == 4);
  CHECK(r.err.find("missing.ply") != std::string::npos);
  CHECK(run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("no/such/dir/o.ply")) + " --grid 4").exit_code ==
        4);
  CHECK(d.entries() == std::vector<std::string>{"s.ply"});
}

TEST_CASE("info prints format, counts, properties and bounds", "[cli]") {
  ScratchDir d;
  write_file(d.file("s.ply"), small_ply(3, 1.0f));
  CliResult r = run_cli("info " + q(d.file("s.ply")));
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("ply binary_little_endian") != std::string::npos);
  CHECK(r.out.find("vertices  4") != std::string::npos);
  CHECK(r.out.find("faces     2") != std::string::npos);
  CHECK(r.out.find("x float") != std::string::npos);
  CHECK(r.out.find("max 1 1 0") != std::string::npos);
  CHECK(r.out.find("non-finite") == std::string::npos);
  // Vertex 1 NaN: left out of the box, counted, the first named with its byte offset.
  write_file(d.file("nan.ply"), small_ply(3, std::nanf("")));
  r = run_cli("info " + q(d.file("nan.ply")));
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("max 1 1 0") != std::string::npos);
  std::size_t vertex1 = small_ply_header(4, 2).size() + 12;
  CHECK(r.out.find("non-finite 1 (vertices with a NaN or infinite coordinate, ignored; the first: vertex 1 at byte " +
                   std::to_string(vertex1) + ")") != std::string::npos);
}

namespace {
// The number after "key": in a stats file (the first occurrence), or -1.
double json_number(const std::string& js, const std::string& key) {
  std::size_t at = js.find("\"" + key + "\":");
  return at == std::string::npos ? -1 : std::stod(js.substr(at + key.size() + 3));
}
}  // namespace

TEST_CASE("floating cells stay inside --mem on an input larger than the budget", "[cli][memory]") {
  // A 2M-triangle sphere is a 38 MB file; with a 32 MiB budget the anonymous
  // memory (heap and stacks: what the budget bounds; the mapped input and spill
  // files are page cache the kernel reclaims) must stay below 32 MiB, with any
  // thread count.
#if OOCSIMP_TEST_UNDER_ASAN
  // AddressSanitizer's shadow memory and quarantine are anonymous memory too: the
  // bound is the normal build's to check.
  skip_test("AddressSanitizer build: the bound is the normal build's to check");
  return;
#endif
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 2000000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  REQUIRE(std::filesystem::file_size(d.file("s.ply")) > (32u << 20));
  for (const char* threads : {"1", "2"}) {
    REQUIRE(run_cli(std::string("simplify --quiet --mem 32M --grid 128 --threads ") + threads + " " +
                    q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --tmp " + q(d.path()) + " --stats " +
                    q(d.file("st.json")))
                .exit_code == 0);
    std::string js = read_file(d.file("st.json"));
    INFO("threads " << threads << ": " << js);
    CHECK(json_number(js, "count") > 8);  // tiles
    CHECK(json_number(js, "peak_anon_bytes") > 0);
    CHECK(json_number(js, "peak_anon_bytes") < double(32u << 20));
    CHECK(json_number(js, "spill_bytes") > double(16u << 20));  // most of the spill went to the disk
  }
}

TEST_CASE("a run whose spill fits in --mem writes no spill file, with the output of a run that spills",
          "[cli][memory]") {
  ScratchDir d, tmp;
  REQUIRE(run_cli("generate --tris 400000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  auto run = [&](const std::string& mem, const std::string& out) {
    REQUIRE(run_cli("simplify --quiet --grid 128 --threads 2" + mem + " " + q(d.file("s.ply")) + " -o " +
                    q(d.file(out)) + " --tmp " + q(tmp.path()) + " --stats " + q(d.file("st.json")))
                .exit_code == 0);
    return read_file(d.file("st.json"));
  };
  // The default budget (a quarter of the memory) holds a 400k-triangle run's spill.
  std::string js = run("", "fits.ply");
  INFO(js);
  CHECK(json_number(js, "spill_bytes") == 0);
  CHECK(json_number(js, "spill_raw_bytes") == 0);
  CHECK(json_number(js, "spill_bytes_in_memory") > 400000.0 * 32);  // every triangle record at least
  // At the smallest budget most of it goes to the disk, inside the budget.
  js = run(" --mem 32M", "spills.ply");
  CHECK(json_number(js, "spill_bytes") > 0);
  if (!OOCSIMP_TEST_UNDER_ASAN) CHECK(json_number(js, "peak_anon_bytes") < double(32u << 20));  // ASan's shadow counts
  CHECK(read_file(d.file("fits.ply")) == read_file(d.file("spills.ply")));
  CHECK(tmp.entries().empty());
}

TEST_CASE("a memory budget too small to work is refused up front", "[cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 1000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  CliResult r = run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --method floating --mem 1M");
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--mem") != std::string::npos);
  CHECK(run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --mem lots").exit_code == 2);
  CHECK_FALSE(file_exists(d.file("o.ply")));
  CHECK(run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --method floating --mem 64M --quiet")
            .exit_code == 0);
}

// --- The budget is the process's: both methods keep the whole process,
// output tables included, under --mem, or refuse with exit 2 naming --mem.

TEST_CASE("uniform at a --mem its tables fit in stays under it, with the output of a run without --mem",
          "[cli][memory]") {
  ScratchDir d, tmp;
  REQUIRE(run_cli("generate --tris 400000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  // A sphere 64 cells across crosses about 4 pi 32^2 ~ 13k cells (a surface meets at
  // most a few cells per cell of area): with ~26k kept triangles, 2-3 MiB of tables.
  auto run = [&](const std::string& mem, const std::string& out) {
    REQUIRE(run_cli("simplify --quiet --method uniform --grid 64 --threads 2" + mem + " " + q(d.file("s.ply")) +
                    " -o " + q(d.file(out)) + " --tmp " + q(tmp.path()) + " --stats " + q(d.file("st.json")))
                .exit_code == 0);
    return read_file(d.file("st.json"));
  };
  run("", "free.ply");
  std::string js = run(" --mem 32M", "bounded.ply");
  INFO(js);
  CHECK(read_file(d.file("free.ply")) == read_file(d.file("bounded.ply")));
  CHECK(json_number(js, "occupied_cells") < 4 * 3.1416 * 32 * 32 * 3);
#if !OOCSIMP_TEST_UNDER_ASAN  // ASan's shadow memory is anonymous memory too
  CHECK(json_number(js, "peak_anon_bytes") > 0);
  CHECK(json_number(js, "peak_anon_bytes") < double(32u << 20));
#endif
  CHECK(tmp.entries().empty());
}

TEST_CASE("a fine grid whose cell table cannot fit in --mem exits 2 for uniform, and floating streams its output",
          "[cli][memory]") {
  ScratchDir d, tmp;
  REQUIRE(run_cli("generate --tris 1000000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  // At --grid 2048 a cell is far smaller than an edge of the 1M-triangle sphere (500k
  // vertices on a surface of ~4 pi 1024^2 = 13M cells): nearly every vertex is a cell
  // or cluster of its own and nearly every triangle survives. Uniform: 500k cells of
  // a 112-byte record and an 8-byte key are 57 MiB before any triangle, which cannot
  // fit in 32 MiB. Floating: 1M kept triangles of 32 bytes, and the output's 12 bytes
  // per triangle and 24 per vertex, are 53 MiB, all of them in mapped files: it runs.
  const std::string common = "simplify --quiet --grid 2048 --tmp " + q(tmp.path()) + " " + q(d.file("s.ply"));
  CliResult r =
      run_cli(common + " --mem 32M --method uniform -o " + q(d.file("o.ply")) + " --stats " + q(d.file("st.json")));
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--mem 32 MiB") != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);  // one line
  CHECK_FALSE(file_exists(d.file("o.ply")));
  CHECK_FALSE(file_exists(d.file("st.json")));
  CHECK(tmp.entries().empty());

  // One thread and two: the tiles in work wait while what the process holds would not
  // leave them room (TileMemoryGate), so a second thread takes no more than the budget.
  for (const char* threads : {"1", "2"}) {
    r = run_cli(common + " --mem 32M --threads " + threads + " --method floating -o " + q(d.file("small.ply")) +
                " --stats " + q(d.file("st.json")));
    REQUIRE(r.exit_code == 0);
    const std::string js = read_file(d.file("st.json"));
    INFO("threads " << threads << ": " << js);
    CHECK(json_number(js.substr(js.find("\"output\"")), "triangles") > 900000);
#if !OOCSIMP_TEST_UNDER_ASAN  // ASan's shadow memory is anonymous memory too
    CHECK(json_number(js, "peak_anon_bytes") < double(32u << 20));
#endif
    CHECK(tmp.entries().empty());
  }
  REQUIRE(run_cli(common + " --mem 1G --method floating -o " + q(d.file("large.ply"))).exit_code == 0);
  CHECK(read_file(d.file("small.ply")) == read_file(d.file("large.ply")));
}

TEST_CASE("a dense part whose tile cannot fit in --mem is refused up front and runs within a --mem that fits",
          "[cli][memory]") {
  // A coarse 100 x 100 plane (20k triangles) and, apart, a dense 300 x 300 patch 1/100
  // as wide (180k triangles): tiles sized for the average put the whole patch into
  // one tile, whose working set (about 200 bytes a record: 36 MB) is more than three
  // quarters of 32 MiB, and fits in 64 MiB.
  ScratchDir d, tmp;
  std::vector<float> pos;
  std::vector<std::uint32_t> tri;
  auto grid = [&](int n, float size, float z) {
    const auto base = std::uint32_t(pos.size() / 3);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        pos.push_back(size * float(i) / float(n));
        pos.push_back(size * float(j) / float(n));
        pos.push_back(z);
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::uint32_t a = base + std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1);
        for (std::uint32_t v : {a, b, c + 1, a, c + 1, c}) tri.push_back(v);
      }
  };
  grid(100, 1.0f, 0.0f);
  grid(300, 0.01f, 0.5f);
  write_binary_ply(d.file("dense.ply"), pos, tri);
  const std::string args = " --grid 200 --threads 2 " + q(d.file("dense.ply")) + " -o " + q(d.file("o.ply")) +
                           " --tmp " + q(tmp.path()) + " --stats " + q(d.file("st.json"));
  CliResult r = run_cli("simplify --quiet --mem 32M" + args);
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--mem 32 MiB cannot hold the fullest tile of " + d.file("dense.ply")) != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK_FALSE(file_exists(d.file("o.ply")));
  CHECK(tmp.entries().empty());
  REQUIRE(run_cli("simplify --quiet --mem 64M" + args).exit_code == 0);
  const std::string js = read_file(d.file("st.json"));
  INFO(js);
  CHECK(json_number(js, "largest_tile_records") >= 180000);
#if !OOCSIMP_TEST_UNDER_ASAN  // ASan's shadow memory is anonymous memory too
  CHECK(json_number(js, "peak_anon_bytes") < double(64u << 20));
#endif
  CHECK(tmp.entries().empty());
}

// --- Outputs: only regular files and new names go through a temporary name and a
// rename (so a failed run leaves no partial file); anything else (a device, a FIFO, a
// socket, a link's target, standard output) is written where it is, since a rename
// would replace it instead of writing to it.

namespace {

// A 20k-triangle sphere at s.ply and its simplification at ref.ply, written as a plain
// file: the bytes every other destination must receive.
std::string reference_output(const ScratchDir& d) {
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  REQUIRE(run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("ref.ply")) + " --grid 16").exit_code ==
          0);
  std::string ref = read_file(d.file("ref.ply"));
  REQUIRE(ref.size() > 1000);
  return ref;
}

bool is_char_device(const std::string& path) {
  struct stat st;
  return ::lstat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

}  // namespace

TEST_CASE("an output that is a character device is written, not replaced", "[cli][outputs]") {
  ScratchDir d;
  reference_output(d);
  // mknod needs CAP_MKNOD (root): elsewhere the check cannot be made here.
  if (::mknod(d.file("null").c_str(), S_IFCHR | 0666, ::makedev(1, 3)) != 0) {
    skip_test("mknod failed (not root?): no character device to write to");
    return;
  }
  CliResult r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("null")) + " --grid 16 --stats " +
                        q(d.file("null")));
  CHECK(r.exit_code == 2);  // one device for both: refused
  r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("null")) + " --grid 16");
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(is_char_device(d.file("null")));
  r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --grid 16 --stats " +
              q(d.file("null")));
  CHECK(r.exit_code == 0);
  CHECK(is_char_device(d.file("null")));
  CHECK(d.entries() == std::vector<std::string>{"null", "o.ply", "ref.ply", "s.ply"});
}

TEST_CASE("an output that is a FIFO streams the mesh to its reader", "[cli][outputs]") {
  ScratchDir d;
  std::string ref = reference_output(d);
  REQUIRE(::mkfifo(d.file("fifo").c_str(), 0600) == 0);
  // Opened for reading first (non-blocking, so that nothing waits on the writer), and
  // read until the run has ended and the pipe is drained: no hang whatever the run does.
  int fd = ::open(d.file("fifo").c_str(), O_RDONLY | O_NONBLOCK);
  REQUIRE(fd >= 0);
  std::atomic<bool> done{false};
  CliResult r;
  std::thread run([&] {
    r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("fifo")) + " --grid 16");
    done = true;
  });
  std::string got;
  char buf[65536];
  for (;;) {
    bool finished = done.load();
    ssize_t n = ::read(fd, buf, sizeof buf);
    if (n > 0) {
      got.append(buf, std::size_t(n));
      continue;
    }
    if (finished) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  run.join();
  ::close(fd);
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(got == ref);
  struct stat st;
  REQUIRE(::lstat(d.file("fifo").c_str(), &st) == 0);
  CHECK(S_ISFIFO(st.st_mode));
}

TEST_CASE("an output FIFO whose reader goes away exits 4 and leaves nothing in --tmp", "[cli][outputs]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 200000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  ScratchDir tmp;
  REQUIRE(::mkfifo(d.file("fifo").c_str(), 0600) == 0);
  // O_CLOEXEC: a reader inherited by the run would keep the pipe open.
  int fd = ::open(d.file("fifo").c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  REQUIRE(fd >= 0);
  std::atomic<bool> done{false};
  CliResult r;
  // About 180k output triangles: far more than a pipe holds, so the run is still writing
  // when the reader closes after the first bytes.
  std::thread run([&] {
    r = run_cli("simplify --quiet --method uniform --grid 256 " + q(d.file("s.ply")) + " -o " + q(d.file("fifo")) +
                " --tmp " + q(tmp.path()));
    done = true;
  });
  char buf[16];
  while (!done.load() && ::read(fd, buf, sizeof buf) <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ::close(fd);
  run.join();
  INFO(r.err);
  CHECK(r.exit_code == 4);
  CHECK(r.err.find(d.file("fifo")) != std::string::npos);
  CHECK(tmp.entries().empty());
}

TEST_CASE("an output that is a Unix socket is connected to and streamed into", "[cli][outputs]") {
  ScratchDir d;
  std::string ref = reference_output(d);
  int listener = ::socket(AF_UNIX, SOCK_STREAM, 0);
  REQUIRE(listener >= 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::string path = d.file("sock");
  REQUIRE(path.size() < sizeof addr.sun_path);
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  REQUIRE(::bind(listener, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0);
  REQUIRE(::listen(listener, 1) == 0);
  REQUIRE(::fcntl(listener, F_SETFL, O_NONBLOCK) == 0);
  std::atomic<bool> done{false};
  CliResult r;
  std::thread run([&] {
    r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(path) + " --grid 16");
    done = true;
  });
  // Accept without blocking until the run ends (it may fail before connecting), then
  // read the connection to its end.
  std::string got;
  for (;;) {
    bool finished = done.load();
    int c = ::accept(listener, nullptr, nullptr);
    if (c >= 0) {
      char buf[65536];
      ssize_t n;
      while ((n = ::read(c, buf, sizeof buf)) > 0) got.append(buf, std::size_t(n));
      ::close(c);
      break;
    }
    if (finished) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  run.join();
  ::close(listener);
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(got == ref);
  struct stat st;
  REQUIRE(::lstat(path.c_str(), &st) == 0);
  CHECK(S_ISSOCK(st.st_mode));
}

TEST_CASE("an output that is a symbolic link writes the link's target, the link stays", "[cli][outputs]") {
  ScratchDir d;
  std::string ref = reference_output(d);
  std::filesystem::create_directory(d.file("sub"));
  // A relative link to a file that does not exist yet, in another folder, and a link to
  // that link.
  std::filesystem::create_symlink("sub/target.ply", d.file("link.ply"));
  std::filesystem::create_symlink("link.ply", d.file("link2.ply"));
  for (const char* name : {"link.ply", "link2.ply"}) {
    CliResult r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file(name)) + " --grid 16");
    INFO(name << ": " << r.err);
    CHECK(r.exit_code == 0);
    CHECK(std::filesystem::is_symlink(d.file(name)));
    CHECK(read_file(d.file("sub/target.ply")) == ref);
    std::filesystem::remove(d.file("sub/target.ply"));
  }
  CHECK(d.entries() == std::vector<std::string>{"link.ply", "link2.ply", "ref.ply", "s.ply", "sub"});
}

TEST_CASE("output - is binary PLY on stdout, stats - the JSON, the summary goes to stderr", "[cli][outputs]") {
  ScratchDir d;
  std::string ref = reference_output(d);
  CliResult r = run_cli("simplify " + q(d.file("s.ply")) + " -o - --grid 16");
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(r.out == ref);
  CHECK(r.err.find("Mtri/s") != std::string::npos);
  r = run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --grid 16 --stats -");
  CHECK(r.exit_code == 0);
  CHECK(r.out.rfind("{\n", 0) == 0);
  CHECK(r.out.back() == '\n');
  CHECK(r.out.find("Mtri/s") == std::string::npos);
  CHECK(r.err.find("Mtri/s") != std::string::npos);
  CHECK(read_file(d.file("o.ply")) == ref);
  // Both on stdout would mix them.
  CHECK(run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o - --stats - --grid 16").exit_code == 2);
  // No file named "-" anywhere.
  CHECK(d.entries() == std::vector<std::string>{"o.ply", "ref.ply", "s.ply"});
}

TEST_CASE("an output name of 255 bytes (the longest a folder entry may have) is written", "[cli][outputs]") {
  ScratchDir d;
  std::string ref = reference_output(d);
  std::string name = std::string(251, 'n') + ".ply";
  REQUIRE(name.size() == 255);
  CliResult r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file(name)) + " --grid 16 --stats " +
                        q(d.file(std::string(250, 's') + ".json")));
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(read_file(d.file(name)) == ref);
}

TEST_CASE("generate writes to stdout with -o - and refuses names that are not PLY", "[cli][outputs]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 2000 --quiet -o " + q(d.file("g.ply"))).exit_code == 0);
  CliResult r = run_cli("generate --tris 2000 --quiet -o -");
  CHECK(r.exit_code == 0);
  CHECK(r.out == read_file(d.file("g.ply")));
  // generate writes PLY only: another extension exits 2, saying what it can write,
  // rather than writing PLY bytes under a name that promises another format.
  for (const char* name : {"x.obj", "x.stl", "x.off", "x.glb", "x.obj.zst", "x"}) {
    r = run_cli("generate --tris 2000 --quiet -o " + q(d.file(name)));
    INFO(name << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(".ply, .ply.zst or .ply.gz") != std::string::npos);
  }
  CHECK(d.entries() == std::vector<std::string>{"g.ply"});
}

// --- Same paths: an output that is the input (or another output) would destroy it.

TEST_CASE("an output or --stats that is the input, or each other, exits 2 naming both", "[cli][outputs]") {
  ScratchDir d;
  std::string ref = reference_output(d);
  const std::string input = read_file(d.file("s.ply"));
  std::filesystem::create_symlink("s.ply", d.file("s-link.ply"));
  std::filesystem::create_hard_link(d.file("s.ply"), d.file("s-hard.ply"));
  const std::string s = q(d.file("s.ply"));
  const std::string folder = std::filesystem::path(d.path()).filename().string();
  struct Case {
    std::string args, named;
  } cases[] = {
      {"-o " + s, "s.ply"},
      {"-o " + q(d.file("s-link.ply")), "s-link.ply"},
      {"-o " + q(d.file("s-hard.ply")), "s-hard.ply"},
      {"-o " + q(d.path() + "/./s.ply"), "s.ply"},
      {"-o " + q(d.file("o.ply")) + " --stats " + s, "s.ply"},
      {"-o " + q(d.file("o.ply")) + " --stats " + s + " --force", "s.ply"},  // --force is for the mesh only
      {"-o " + q(d.file("o.ply")) + " --stats " + q(d.file("o.ply")), "o.ply"},
      {"-o " + q(d.file("o.ply")) + " --stats " + q(d.path() + "/../" + folder + "/o.ply"), "o.ply"},
  };
  for (const Case& c : cases) {
    CliResult r = run_cli("simplify --quiet " + s + " " + c.args + " --grid 16");
    INFO(c.args << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.named) != std::string::npos);
    CHECK(r.err.find("same file") != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(read_file(d.file("s.ply")) == input);
    CHECK_FALSE(file_exists(d.file("o.ply")));
  }
  // --force: the input is replaced, after a successful run.
  CliResult r = run_cli("simplify --quiet " + s + " -o " + q(d.file("s-link.ply")) + " --grid 16 --force");
  CHECK(r.exit_code == 0);
  CHECK(read_file(d.file("s.ply")) == ref);
  CHECK(std::filesystem::is_symlink(d.file("s-link.ply")));
  CHECK(read_file(d.file("s-hard.ply")) == input);  // the old inode, untouched
}

TEST_CASE("a --stats that cannot be written exits 4 and leaves the output as it was", "[cli][outputs]") {
  ScratchDir d;
  reference_output(d);
  write_file(d.file("o.ply"), "the previous output");
  CliResult r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --grid 16 --stats " +
                        q(d.file("nodir/s.json")));
  INFO(r.err);
  CHECK(r.exit_code == 4);
  CHECK(r.err.find("nodir") != std::string::npos);
  CHECK(read_file(d.file("o.ply")) == "the previous output");
  r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("new.ply")) + " --grid 16 --stats " +
              q(d.file("nodir/s.json")));
  CHECK(r.exit_code == 4);
  CHECK(d.entries() == std::vector<std::string>{"o.ply", "ref.ply", "s.ply"});
}

// --- Options: every size and count is checked; a bad one exits 2
// naming the flag and the value, before any work and without any output.

TEST_CASE("every invalid size or count exits 2 naming the flag and the value", "[cli][options]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 2000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  const std::string simplify = "simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " ";
  const std::string measure = "measure --quiet " + q(d.file("s.ply")) + " " + q(d.file("s.ply")) + " ";
  struct Case {
    std::string args, flag, value;
  } cases[] = {
      {simplify + "--grid 0", "--grid", "0"},
      {simplify + "--grid -3", "--grid", "-3"},
      {simplify + "--grid 2097152", "--grid", "2097152"},
      {simplify + "--grid 1.5", "--grid", "1.5"},
      {simplify + "--cell 0", "--cell", "0"},
      {simplify + "--cell -1", "--cell", "-1"},
      {simplify + "--cell nan", "--cell", "nan"},
      {simplify + "--cell inf", "--cell", "inf"},
      {simplify + "--cell 1x", "--cell", "1x"},
      {simplify + "--ratio 0", "--ratio", "0"},
      {simplify + "--ratio -1", "--ratio", "-1"},
      {simplify + "--ratio 1.5", "--ratio", "1.5"},
      {simplify + "--ratio nan", "--ratio", "nan"},
      {simplify + "--tile -1", "--tile", "-1"},
      {simplify + "--tile nan", "--tile", "nan"},
      {simplify + "--tile 0", "--tile", "0"},
      {simplify + "--mem 0.5", "--mem", "0.5"},
      {simplify + "--mem inf", "--mem", "inf"},
      {simplify + "--mem 0", "--mem", "0"},
      {simplify + "--mem -1G", "--mem", "-1G"},
      {simplify + "--threads 0", "--threads", "0"},
      {simplify + "--threads -2", "--threads", "-2"},
      {simplify + "--threads 99999999999", "--threads", "99999999999"},
      {"generate --quiet -o " + q(d.file("g.ply")) + " --tris -5", "--tris", "-5"},
      {"generate --quiet -o " + q(d.file("g.ply")) + " --tris 0", "--tris", "0"},
      {"generate --quiet -o " + q(d.file("g.ply")) + " --tris 10 --seed -1", "--seed", "-1"},
      {measure + "--samples 0", "--samples", "0"},
      {measure + "--samples -5", "--samples", "-5"},
      {measure + "--threads 0", "--threads", "0"},
      {simplify + "--target-tris 2.5k5", "--target-tris", "2.5k5"},
      {simplify + "--target-tris 1.5k1", "--target-tris", "1.5k1"},
      {simplify + "--target-tris 1e-3", "--target-tris", "1e-3"},
      {simplify + "--target-tris 1.0005k", "--target-tris", "1.0005k"},
      {simplify + "--target-tris 1e300", "--target-tris", "1e300"},
      {simplify + "--grid 3m", "--grid", "3m"},
  };
  for (const Case& c : cases) {
    CliResult r = run_cli(c.args);
    INFO(c.args << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.flag) != std::string::npos);
    CHECK(r.err.find(c.value) != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  }
  // --method takes its names only (not CLI11's integer fallback).
  for (const char* m : {"0", "1", "Uniform"}) {
    CliResult r = run_cli(simplify + "--grid 4 --method " + m);
    INFO(m << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("--method") != std::string::npos);
  }
  CHECK(d.entries() == std::vector<std::string>{"s.ply"});
}

TEST_CASE("counts take a decimal suffix or an exponent, and --help names each value's kind", "[cli][options]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 2e4 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("digits.ply"))).exit_code == 0);
  CHECK(read_file(d.file("s.ply")) == read_file(d.file("digits.ply")));
  for (const char* count : {"1500", "1.5k", "1.5K", "15e2", "0.0015M"}) {
    CAPTURE(count);
    REQUIRE(run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --target-tris " + count)
                .exit_code == 0);
    CHECK(load_mesh(d.file("o.ply")).triangle_count() == 1500);
  }
  const CliResult help = run_cli("simplify --help");
  CHECK(help.out.find("TEXT") == std::string::npos);
  for (const char* shown : {"input PATH", "--grid INT", "--cell FLOAT", "--mem SIZE", "--tmp PATH", "--method NAME:{"})
    CHECK(help.out.find(shown) != std::string::npos);
}

TEST_CASE("the documented maximum grid, 2097151, is accepted", "[cli][options]") {
  ScratchDir d;
  // Two triangles 20 cells wide a unit apart: at the finest grid every corner is its own
  // cluster. (Triangles a million cells wide overflow the floating method's fixed-point
  // quadric sums, which are kept in cell units: exit 4.)
  write_file(d.file("t.obj"), "v 0 0 0\nv 1e-5 0 0\nv 0 1e-5 0\nv 1 0 0\nv 1 1e-5 0\nv 1 0 1e-5\nf 1 2 3\nf 4 5 6\n");
  for (const char* method : {"uniform", "floating"}) {
    CliResult r = run_cli(std::string("simplify --quiet --grid 2097151 --method ") + method + " " + q(d.file("t.obj")) +
                          " -o " + q(d.file("o.ply")));
    INFO(method << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    LoadedMesh m = load_mesh(d.file("o.ply"));
    CHECK(m.triangle_count() == 2);
    CHECK(m.vertex_count() == 6);
  }
}

TEST_CASE("floating-only flags with --method uniform exit 2 naming the flag and the method", "[cli][options]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 2000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  for (const char* flag : {"--cell-shape sphere", "--assign heaviest", "--rep mean", "--tile 0.5", "--keep-tmp",
                           "--spill-compress none", "--cell-shape cube"}) {
    CliResult r = run_cli("simplify --quiet --method uniform --grid 8 " + q(d.file("s.ply")) + " -o " +
                          q(d.file("o.ply")) + " " + flag);
    INFO(flag << ": " << r.err);
    CHECK(r.exit_code == 2);
    std::string name = std::string(flag).substr(0, std::string(flag).find(' '));
    CHECK(r.err.find(name) != std::string::npos);
    CHECK(r.err.find("uniform") != std::string::npos);
    // The same flag is taken with the floating method.
    CHECK(run_cli("simplify --quiet --method floating --grid 8 " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) +
                  " --tmp " + q(d.path()) + " " + flag)
              .exit_code == 0);
  }
}

TEST_CASE("without --cell, --grid or --ratio, simplify keeps about a tenth of the triangles", "[cli][options]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 200000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  for (const char* method : {"uniform", "floating"}) {
    CliResult r = run_cli(std::string("simplify --method ") + method + " " + q(d.file("s.ply")) + " -o " +
                          q(d.file("o.ply")) + " --stats " + q(d.file("st.json")));
    INFO(method << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    LoadedMesh m = load_mesh(d.file("o.ply"));
    // --ratio is an estimate (within a factor of two, see the uniform tests); the old
    // default grid of 256 kept more than half of these triangles.
    CHECK(double(m.triangle_count()) > 0.1 * 200000 / 2);
    CHECK(double(m.triangle_count()) < 0.1 * 200000 * 2);
    CHECK(read_file(d.file("st.json")).find("\"ratio\": 0.1") != std::string::npos);
  }
  CliResult help = run_cli("simplify --help");
  CHECK(help.out.find("--ratio 0.1") != std::string::npos);
}

// --- Reporting: the summary and --stats must describe the phases the method ran.

TEST_CASE("the summary and --stats name each method's own phases", "[cli][report]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  struct Method {
    const char* name;
    std::vector<std::string> phases;
  } methods[] = {{"uniform", {"open", "vertices", "faces", "solve", "write"}},
                 {"floating", {"open", "bin", "grade", "rounds", "cluster", "stitch", "assemble", "write"}}};
  for (const Method& m : methods) {
    CliResult r = run_cli(std::string("simplify --grid 16 --method ") + m.name + " " + q(d.file("s.ply")) + " -o " +
                          q(d.file("o.ply")) + " --stats " + q(d.file("st.json")) + " --tmp " + q(d.path()));
    INFO(m.name << ": " << r.out << r.err);
    REQUIRE(r.exit_code == 0);
    std::string js = read_file(d.file("st.json"));
    INFO(js);
    std::size_t seconds = js.find("\"seconds\": {");
    REQUIRE(seconds != std::string::npos);
    std::string seconds_line = js.substr(seconds, js.find('\n', seconds) - seconds);
    std::size_t time_at = r.out.find("time ");
    REQUIRE(time_at != std::string::npos);
    std::string time_line = r.out.substr(time_at, r.out.find('\n', time_at) - time_at);
    std::size_t last_json = 0, last_summary = 0;
    for (const std::string& p : m.phases) {
      std::size_t at = seconds_line.find("\"" + p + "\": ");
      CHECK(at != std::string::npos);
      CHECK(at >= last_json);  // in order
      last_json = at;
      at = time_line.find(p + " ");
      CHECK(at != std::string::npos);
      CHECK(at >= last_summary);
      last_summary = at;
    }
    CHECK(seconds_line.find("\"total\": ") != std::string::npos);
    if (std::string(m.name) == "floating") CHECK(seconds_line.find("\"solve\"") == std::string::npos);
  }
}

TEST_CASE("the stats JSON records the version, the paths, the method and every option", "[cli][report]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  std::string version = run_cli("--version").out;
  REQUIRE(version.rfind("oocsimp ", 0) == 0);
  version = version.substr(8, version.find('\n') - 8);
  CHECK(std::count(version.begin(), version.end(), '.') == 2);  // the CMake project version, MAJOR.MINOR.PATCH
  REQUIRE(run_cli("simplify --quiet --method floating --cell 0.25 --cell-shape sphere --assign heaviest --rep mean "
                  "--tile 1.5 --mem 64M --threads 2 --spill-compress zstd --ascii --tmp " +
                  q(d.path()) + " " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --stats " +
                  q(d.file("st.json")))
              .exit_code == 0);
  std::string js = read_file(d.file("st.json"));
  INFO(js);
  for (const std::string& field :
       {"\"version\": \"" + version + "\"", "\"input\": \"" + d.file("s.ply") + "\"",
        "\"output\": \"" + d.file("o.ply") + "\"", "\"stats\": \"" + d.file("st.json") + "\"",
        std::string("\"method\": \"floating\""), std::string("\"cell\": 0.25"),
        std::string("\"cell_shape\": \"sphere\""), std::string("\"assign\": \"heaviest\""),
        std::string("\"rep\": \"mean\""), std::string("\"tile\": 1.5"), std::string("\"mem_bytes\": 67108864"),
        std::string("\"threads\": 2"), std::string("\"spill_compress\": \"zstd\""), std::string("\"keep_tmp\": false"),
        std::string("\"ascii\": true"), std::string("\"force\": false"), "\"tmp\": \"" + d.path() + "\""})
    CHECK(js.find(field) != std::string::npos);
  REQUIRE(run_cli("simplify --quiet --method uniform --grid 8 " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) +
                  " --stats " + q(d.file("st.json")))
              .exit_code == 0);
  js = read_file(d.file("st.json"));
  CHECK(js.find("\"method\": \"uniform\"") != std::string::npos);
  CHECK(js.find("\"grid\": 8") != std::string::npos);
  CHECK(js.find("cell_shape") == std::string::npos);  // floating-only options are not reported for uniform
}

namespace {
// The simplify arguments of the progress-line tests: a run of `method` on d's s.ply.
std::string progress_run_args(const ScratchDir& d, const char* method) {
  return std::string("simplify --grid 16 --method ") + method + " " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) +
         " --tmp " + q(d.path());
}
}  // namespace

TEST_CASE("progress lines of phases without counts show the elapsed time only", "[cli][report]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  for (const char* method : {"uniform", "floating"}) {
    CliResult r = run_cli(progress_run_args(d, method));  // stderr a file: batch lines
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(r.err.find("oocsimp: write done in ") != std::string::npos);
    CHECK(r.err.find(" 0.0 ") == std::string::npos);  // no rate of nothing
    CHECK(r.err.find("ETA 0s") == std::string::npos);
    CHECK(r.err.find(" 0% ") == std::string::npos);
  }
}

TEST_CASE("progress lines of phases without counts show the elapsed time only, on a terminal", "[cli][report]") {
  // On a terminal (script(1) gives the run one): bars only for phases with a total.
  if (std::system("command -v script >/dev/null 2>&1") != 0) {
    skip_test("script(1) not found: the terminal output is not checked");
    return;
  }
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  for (const char* method : {"uniform", "floating"}) {
    const std::string args = progress_run_args(d, method);
    std::string cmd =
        "script -qfec " + q(std::string(OOCSIMP_CLI) + " " + args) + " /dev/null >" + q(d.file("tty.txt"));
    REQUIRE(std::system(cmd.c_str()) == 0);
    std::string tty = read_file(d.file("tty.txt"));
    INFO(tty);
    std::size_t write_at = tty.rfind("\033[Kwrite ");  // the progress line, not the summary's
    REQUIRE(write_at != std::string::npos);
    std::string write_line = tty.substr(write_at, tty.find('\n', write_at) - write_at);
    CHECK(write_line.find('%') == std::string::npos);
    CHECK(write_line.find("/s") == std::string::npos);
    CHECK(tty.find(" 0.0 ") == std::string::npos);
  }
}

TEST_CASE("help is grouped with plain value lists, mistyped flags get a suggestion on one line", "[cli][report]") {
  CliResult r = run_cli("simplify --help");
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("Floating method only") != std::string::npos);
  CHECK(r.out.find("{auto,floating,uniform,curvature,qem}") != std::string::npos);
  CHECK(r.out.find("->") == std::string::npos);  // no enum internals
  CHECK(r.out.find(" OR ") == std::string::npos);
  r = run_cli("--version");
  CHECK(r.exit_code == 0);
  CHECK(r.out.rfind("oocsimp ", 0) == 0);
  ScratchDir d;
  struct Case {
    const char* args;
    const char* hint;
  } cases[] = {{"simplify in.ply -o out.ply --gird 4", "did you mean --grid?"},
               {"simplify in.ply -o out.ply --ratoi 0.1", "did you mean --ratio?"},
               {"simplfy in.ply -o out.ply", "did you mean simplify?"},
               {"generate --tris 10 -o x.ply --shpe sphere", "did you mean --shape?"}};
  for (const Case& c : cases) {
    r = run_cli(c.args);
    INFO(c.args << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.hint) != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  }
  r = run_cli("simplify in.ply");  // -o missing
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--output") != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
}

TEST_CASE("oocsimp --version prints oocsimp and the library's version, and exits 0", "[cli][report]") {
  CliResult r = run_cli("--version");
  CHECK(r.exit_code == 0);
  CHECK(r.out == std::string("oocsimp ") + oocsimp::version() + "\n");
  CHECK(r.err.empty());
}

TEST_CASE("messages show the flag of each option field they name, and leave paths as they are", "[cli][options]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --tris 1000 --quiet -o " + q(d.file("s.ply"))).exit_code == 0);
  // The option at fault first, then advice naming another field.
  CliResult r = run_cli("simplify --quiet --lods 2 --method qem " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")));
  CHECK(r.exit_code == 2);
  CHECK(r.err ==
        "oocsimp: --lods with --method qem needs a target to halve per level (--target-tris or --target-ratio)\n");
  // A file whose name spells a field keeps its name.
  const std::string odd = d.file("outputs.mesh.ply");
  r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(odd) + " --stats " + q(odd));
  CHECK(r.exit_code == 2);
  CHECK(r.err == "oocsimp: --stats " + odd + " and output " + odd + " are the same file\n");
  CHECK(d.entries() == std::vector<std::string>{"s.ply"});
}
