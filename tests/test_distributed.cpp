// Distributed runs (docs/cluster.md): the parts and their merge give one process's
// bytes, and a missing, killed, damaged or stale part is named, never merged.
#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <condition_variable>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "io/content_hash.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

// Runs part I of K of a uniform run of `input` at `grid` into `dir`.
CliResult run_part(const std::string& input, const std::string& dir, int part, int parts, int threads = 1,
                   const std::string& extra = "") {
  return run_cli("simplify " + q(input) + " -o unused.ply --method uniform --quiet --threads " +
                 std::to_string(threads) + " --part " + std::to_string(part) + "/" + std::to_string(parts) +
                 " --work-dir " + q(dir) + " " + extra);
}

// Runs `parts` parts of `simplify INPUT ... OPTIONS` (1, 2, 1, ... threads) into a
// fresh work folder, each required to succeed, then merges them into `merged` with 2
// threads; returns the merge's result.
CliResult parts_then_merge(const std::string& input, const std::string& options, int parts, const std::string& merged) {
  ScratchDir work;
  for (int part = 0; part < parts; ++part) {
    const CliResult r = run_cli("simplify " + q(input) + " -o unused.ply --quiet --threads " +
                                std::to_string(1 + part % 2) + " --part " + std::to_string(part) + "/" +
                                std::to_string(parts) + " --work-dir " + q(work.path()) + " " + options);
    INFO(options << ", part " << part << " of " << parts << ": " << r.err);
    REQUIRE(r.exit_code == 0);
  }
  return run_cli("merge " + q(work.path()) + " -o " + q(merged) + " --threads 2");
}

void flip_byte(const std::string& path, std::size_t at) {
  std::string bytes = read_file(path);
  REQUIRE(at < bytes.size());
  bytes[at] = char(bytes[at] ^ 0x20);
  write_file(path, bytes);
}

}  // namespace

TEST_CASE("parts merged give one process's bytes for 1 to 4 parts and any threads", "[distributed]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --shape parts --tris 200000 --seed 3 --quiet -o " + q(d.file("parts.ply"))).exit_code == 0);
  REQUIRE(run_cli("generate --shape terrain --tris 150000 --seed 4 --attributes --quiet -o " + q(d.file("terrain.ply")))
              .exit_code == 0);
  for (const char* shape : {"parts", "terrain"}) {
    const std::string input = d.file(std::string(shape) + ".ply");
    for (const char* options : {"--grid 60", "--grid 150 --normals", "--ratio 0.05 --precision double"}) {
      const std::string o(options);
      const bool normals = o.find("--normals") != std::string::npos;
      const std::string sizing = normals ? "--grid 150" : o;
      REQUIRE(run_cli("simplify " + q(input) + " -o " + q(d.file("one.ply")) + " --method uniform --quiet " + o)
                  .exit_code == 0);
      for (int parts = 1; parts <= 4; ++parts) {
        ScratchDir work;
        for (int part = 0; part < parts; ++part)
          REQUIRE(run_part(input, work.path(), part, parts, 1 + part % 2, sizing).exit_code == 0);
        CliResult r =
            run_cli("merge " + q(work.path()) + " -o " + q(d.file("merged.ply")) + (normals ? " --normals" : ""));
        INFO(shape << " " << options << ", " << parts << " parts: " << r.err);
        REQUIRE(r.exit_code == 0);
        CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
      }
    }
  }
}

TEST_CASE("merge names a missing, killed, damaged or stale part and a changed input, and a rerun of the part completes",
          "[distributed]") {
  ScratchDir d, work;
  const std::string input = d.file("sphere.ply"), out = d.file("out.ply");
  REQUIRE(run_cli("generate --tris 1000000 --quiet -o " + q(input)).exit_code == 0);
  REQUIRE(run_cli("simplify " + q(input) + " -o " + q(d.file("one.ply")) + " --method uniform --grid 100 --quiet")
              .exit_code == 0);
  const std::string merge = "merge " + q(work.path()) + " -o " + q(out);
  const auto part_file = [&](int i) { return work.file("part-" + std::to_string(i) + "-of-3.oocpart"); };
  REQUIRE(run_part(input, work.path(), 0, 3, 1, "--grid 100").exit_code == 0);
  REQUIRE(run_part(input, work.path(), 2, 3, 1, "--grid 100").exit_code == 0);

  // Part 1 never ran, or was killed before it finished: no file of its own.
  CliResult r = run_cli(merge);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("part-1-of-3.oocpart: part 1 of 3 is missing") != std::string::npos);
  CHECK_FALSE(file_exists(out));
  // A part that dies half-way (here: the file size limit kills it while it writes)
  // leaves no part file: the file is renamed into place whole.
  r = run_cli(
      "simplify " + q(input) + " -o x.ply --method uniform --grid 100 --quiet --part 1/3 --work-dir " + q(work.path()),
      "ulimit -f 64");
  CHECK(r.exit_code != 0);
  CHECK_FALSE(file_exists(part_file(1)));
  r = run_cli(merge);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("part 1 of 3 is missing") != std::string::npos);

  // A stale part: run with other options.
  REQUIRE(run_part(input, work.path(), 1, 3, 2, "--grid 90").exit_code == 0);
  r = run_cli(merge);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("part-1-of-3.oocpart: stale") != std::string::npos);
  CHECK_FALSE(file_exists(out));

  // Rerun it: the job completes, the bytes one process makes.
  REQUIRE(run_part(input, work.path(), 1, 3, 2, "--grid 100").exit_code == 0);
  r = run_cli(merge);
  REQUIRE(r.exit_code == 0);
  CHECK(read_file(out) == read_file(d.file("one.ply")));
  std::remove(out.c_str());

  // A damaged part: one byte flipped in its middle.
  const std::string kept = read_file(part_file(2));
  flip_byte(part_file(2), kept.size() / 2);
  r = run_cli(merge);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("part-2-of-3.oocpart: byte") != std::string::npos);
  CHECK(r.err.find("checksum") != std::string::npos);
  CHECK_FALSE(file_exists(out));
  // Truncated, or of another version: named with the byte.
  write_file(part_file(2), kept.substr(0, 20));
  r = run_cli(merge);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("part-2-of-3.oocpart: byte") != std::string::npos);
  std::string other_version = kept;
  other_version[8] = 9;
  write_file(part_file(2), other_version);
  r = run_cli(merge);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("version 9; this oocsimp reads version 4") != std::string::npos);
  write_file(part_file(2), kept);
  REQUIRE(run_cli(merge).exit_code == 0);
  CHECK(read_file(out) == read_file(d.file("one.ply")));

  // The input changed since the parts read it.
  struct timeval times[2] = {{1000000000, 0}, {1000000000, 0}};
  REQUIRE(::utimes(input.c_str(), times) == 0);
  r = run_cli(merge);
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("the input changed since the parts read it") != std::string::npos);
}

TEST_CASE("parts of a run to a target give one process's bytes, its first pass spread or the run whole",
          "[distributed]") {
  ScratchDir d;
  // Above 2^20 faces the collapse runs in out-of-core passes, whose first the parts
  // share; below, the merge collapses the whole input.
  const std::string big = d.file("big.ply"), small = d.file("small.ply");
  REQUIRE(run_cli("generate --shape terrain --tris 1100000 --seed 5 --quiet -o " + q(big)).exit_code == 0);
  REQUIRE(run_cli("generate --shape parts --tris 30000 --seed 6 --quiet -o " + q(small)).exit_code == 0);
  struct Case {
    std::string input, options;
    int parts;
  };
  for (const Case& c : {Case{big, "--target-tris 6001", 2}, Case{small, "--target-ratio 0.1 --method qem", 3}}) {
    REQUIRE(run_cli("simplify " + q(c.input) + " -o " + q(d.file("one.ply")) + " --quiet --threads 2 " + c.options)
                .exit_code == 0);
    ScratchDir work;
    for (int part = 0; part < c.parts; ++part) {
      const CliResult r = run_cli("simplify " + q(c.input) + " -o unused.ply --quiet --threads " +
                                  std::to_string(1 + part % 2) + " --part " + std::to_string(part) + "/" +
                                  std::to_string(c.parts) + " --work-dir " + q(work.path()) + " " + c.options);
      INFO(r.err);
      REQUIRE(r.exit_code == 0);
    }
    const CliResult r = run_cli("merge " + q(work.path()) + " -o " + q(d.file("merged.ply")) + " --threads 1");
    INFO(c.options << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
    if (c.input == big) {
      // A part run for another target is stale, named as such.
      REQUIRE(run_cli("simplify " + q(c.input) + " -o unused.ply --quiet --part 1/2 --work-dir " + q(work.path()) +
                      " --target-tris 7000")
                  .exit_code == 0);
      const CliResult stale = run_cli("merge " + q(work.path()) + " -o " + q(d.file("merged.ply")));
      CHECK(stale.exit_code == 3);
      CHECK(stale.err.find("part-1-of-2.oocpart: stale") != std::string::npos);
      // A part written by another build (its manifest names the records' sizes), its
      // checksum made whole again: stale too, never merged.
      const std::string part0 = work.file("part-0-of-2.oocpart");
      std::string bytes = read_file(part0);
      const std::size_t at = bytes.find("build oocsimp ");
      REQUIRE(at != std::string::npos);
      bytes[bytes.find(" records ", at) + 1] = 'R';
      const std::uint64_t sum = oocsimp::content_hash(bytes.data(), bytes.size() - 8);
      std::memcpy(&bytes[bytes.size() - 8], &sum, 8);
      write_file(part0, bytes);
      const CliResult other = run_cli("merge " + q(work.path()) + " -o " + q(d.file("merged.ply")));
      CHECK(other.exit_code == 3);
      CHECK(other.err.find("part-0-of-2.oocpart: stale: it was written by another build") != std::string::npos);
    }
  }
}

TEST_CASE("parts of a target after clustering give one process's bytes: phase 1 spread, or the run whole",
          "[distributed][target]") {
  ScratchDir d;
  const std::string input = d.file("t.ply");
  REQUIRE(run_cli("generate --shape terrain --tris 80000 --seed 4 --attributes --quiet -o " + q(input)).exit_code == 0);
  // Phase 1 spread, then the collapse (or nothing more) in the merge; a target near
  // the input's count (the whole input collapsed) and one above it (the input given
  // back) leave the parts nothing to do.
  for (const char* options :
       {"--method uniform --target-tris 3000", "--method floating --target-tris 2000 --intermediate-factor 6",
        "--method curvature --target-tris 3000", "--method uniform --target-ratio 0.05 --refine none",
        "--method floating --target-ratio 0.05 --refine none", "--method uniform --max-error 0.01",
        "--method uniform --target-ratio 0.9", "--method floating --target-tris 500000"}) {
    REQUIRE(run_cli("simplify " + q(input) + " -o " + q(d.file("one.ply")) + " --quiet " + options).exit_code == 0);
    for (int parts = 1; parts <= 3; ++parts) {
      const CliResult r = parts_then_merge(input, options, parts, d.file("merged.ply"));
      INFO(options << ", " << parts << " parts: " << r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
      CHECK(r.err.find("phase 1 ran again") == std::string::npos);
    }
  }
  // A merge given another --mem than its parts chooses another phase 1 (the
  // intermediate, 4 x 60000 triangles here, is capped by the budget at 32M): it
  // clusters again itself, says so, and writes what one process with its --mem writes.
  const std::string large = d.file("large.ply");
  REQUIRE(run_cli("generate --shape terrain --tris 400000 --seed 4 --quiet -o " + q(large)).exit_code == 0);
  const std::string o = "--method uniform --target-tris 60000";
  ScratchDir work;
  for (int part = 0; part < 2; ++part)
    REQUIRE(run_cli("simplify " + q(large) + " -o unused.ply --quiet --mem 64M --part " + std::to_string(part) +
                    "/2 --work-dir " + q(work.path()) + " " + o)
                .exit_code == 0);
  REQUIRE(run_cli("simplify " + q(large) + " -o " + q(d.file("one.ply")) + " --quiet --mem 32M " + o).exit_code == 0);
  const CliResult r = run_cli("merge " + q(work.path()) + " -o " + q(d.file("merged.ply")) + " --mem 32M");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("phase 1 ran again in the merge") != std::string::npos);
  CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
}

TEST_CASE("floating parts merged give one process's bytes for 1 to 4 parts, any threads and cell options",
          "[distributed]") {
  ScratchDir d;
  const std::string input = d.file("t.ply");
  REQUIRE(run_cli("generate --shape terrain --tris 120000 --seed 8 --attributes --quiet -o " + q(input)).exit_code ==
          0);
  for (const char* options : {"--grid 70", "--grid 40 --cell-shape sphere --assign heaviest --rep mean --tile 0.2"}) {
    const std::string o = std::string("--method floating ") + options;
    REQUIRE(run_cli("simplify " + q(input) + " -o " + q(d.file("one.ply")) + " --quiet " + o).exit_code == 0);
    for (int parts = 1; parts <= 4; ++parts) {
      const CliResult r = parts_then_merge(input, o, parts, d.file("merged.ply"));
      INFO(options << ", " << parts << " parts: " << r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
    }
  }
  // A part that tiled the input otherwise (another --tile, or another --mem) is stale.
  ScratchDir work;
  for (const char* part : {"0/2 --tile 0.1", "1/2 --tile 0.2"})
    REQUIRE(run_cli("simplify " + q(input) + " -o unused.ply --quiet --method floating --grid 70 --work-dir " +
                    q(work.path()) + " --part " + part)
                .exit_code == 0);
  const CliResult stale = run_cli("merge " + q(work.path()) + " -o " + q(d.file("merged.ply")));
  CHECK(stale.exit_code == 3);
  CHECK(stale.err.find("part-1-of-2.oocpart: stale: it tiled the input otherwise") != std::string::npos);
}

TEST_CASE("curvature parts merged give one process's bytes for 1 to 4 parts, any threads and curvature options",
          "[distributed][curvature]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --shape parts --tris 60000 --seed 9 --quiet -o " + q(d.file("parts.ply"))).exit_code == 0);
  REQUIRE(run_cli("generate --shape terrain --tris 40000 --seed 2 --attributes --quiet -o " + q(d.file("terrain.ply")))
              .exit_code == 0);
  struct Case {
    const char* shape;
    const char* options;
  };
  for (const Case& c : {Case{"parts", "--grid 40"}, Case{"terrain", "--grid 30 --rep vertex --max-depth 2"},
                        Case{"parts", "--grid 30 --radius 0.02 --curvature-tolerance 0.3 --max-depth 1"},
                        Case{"parts", "--grid 30 --max-depth 0"}}) {
    const std::string input = d.file(std::string(c.shape) + ".ply");
    const std::string o = std::string("--method curvature ") + c.options;
    REQUIRE(run_cli("simplify " + q(input) + " -o " + q(d.file("one.ply")) + " --quiet " + o).exit_code == 0);
    for (int parts = 1; parts <= 4; ++parts) {
      const CliResult r = parts_then_merge(input, o, parts, d.file("merged.ply"));
      INFO(c.shape << " " << c.options << ", " << parts << " parts: " << r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
    }
  }
  // Estimated in tiles (the library's options.curvature.tile_side): the same values,
  // so one process's bytes.
  oocsimp::SimplifyOptions o;
  o.method = oocsimp::ClusterMethod::curvature;
  o.sizing.grid = 40;
  o.curvature.representative = oocsimp::RepresentativeRule::vertex;
  oocsimp::simplify_file(d.file("parts.ply"), d.file("one.ply"), o, nullptr);
  o.curvature.tile_side = 0.15;
  ScratchDir work;
  for (std::uint32_t i = 0; i < 3; ++i) {
    o.threads = 1 + i % 2;
    oocsimp::simplify_part(d.file("parts.ply"), o, {i, 3, work.path()});
  }
  oocsimp::OutputOptions out;
  out.mesh = d.file("merged.ply");
  oocsimp::merge_parts(work.path(), out, oocsimp::SimplifyOptions());
  CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
  // A part run with another radius is stale, and named.
  ScratchDir other;
  for (const char* part : {"0/2 --radius 0.02", "1/2 --radius 0.03"})
    REQUIRE(run_cli("simplify " + q(d.file("parts.ply")) + " -o unused.ply --quiet --method curvature --grid 40 " +
                    "--work-dir " + q(other.path()) + " --part " + part)
                .exit_code == 0);
  const CliResult stale = run_cli("merge " + q(other.path()) + " -o " + q(d.file("merged.ply")));
  CHECK(stale.exit_code == 3);
  CHECK(stale.err.find("part-1-of-2.oocpart: stale: its options are") != std::string::npos);
  // A part file whose plan claims more vertices than the input has, with a value for
  // a vertex past the input's and its checksum made whole again: refused, never
  // written past the curvature array. (Only the vertex representatives read the
  // vertices' curvatures, so only they write values.)
  ScratchDir one;
  REQUIRE(run_cli("simplify " + q(d.file("parts.ply")) + " -o unused.ply --quiet --method curvature --grid 40 " +
                  "--rep vertex --work-dir " + q(one.path()) + " --part 0/1")
              .exit_code == 0);
  const std::string part = one.file("part-0-of-1.oocpart");
  std::string bytes = read_file(part);
  std::uint64_t manifest = 0;
  std::memcpy(&manifest, &bytes[20], 8);
  for (std::size_t at = 28 + manifest; bytes[at] != 0;) {  // the records, to the end record
    std::uint64_t payload = 0;
    std::memcpy(&payload, &bytes[at + 9], 8);
    const std::uint64_t huge = std::uint64_t(1) << 40;
    const std::uint32_t past = 4000000000u;
    if (bytes[at] == 8) std::memcpy(&bytes[at + 17], &huge, 8);  // the plan's vertex count
    if (bytes[at] == 7) std::memcpy(&bytes[at + 17], &past, 4);  // the first value's vertex
    at += 17 + payload;
  }
  const std::uint64_t sum = oocsimp::content_hash(bytes.data(), bytes.size() - 8);
  std::memcpy(&bytes[bytes.size() - 8], &sum, 8);
  write_file(part, bytes);
  const CliResult forged = run_cli("merge " + q(one.path()) + " -o " + q(d.file("merged.ply")));
  CHECK(forged.exit_code == 3);
  CHECK(forged.err.find("part-0-of-1.oocpart: stale: its curvature values are of 1099511627776 vertices") !=
        std::string::npos);
}

namespace {

// Parts run as threads of one process, exchanging as MPI ranks do
// (PartOptions::exchange): each all_gather waits for every part's bytes.
class ThreadExchange {
 public:
  explicit ThreadExchange(std::size_t parts) : lists_(parts) {}
  std::vector<std::vector<unsigned char>> all_gather(std::size_t part, const std::vector<unsigned char>& mine) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (failed_) throw std::runtime_error("another part failed");
    const std::uint64_t round = round_;
    lists_[part] = mine;
    exchanged_ += mine.size();
    if (++arrived_ == lists_.size()) {
      result_ = lists_;
      arrived_ = 0;
      ++round_;
      changed_.notify_all();
    } else {
      changed_.wait(lock, [&] { return round_ != round || failed_; });
      if (round_ == round) throw std::runtime_error("another part failed");
    }
    ++rounds_[part];
    return result_;
  }
  void fail() {
    std::lock_guard<std::mutex> lock(mutex_);
    failed_ = true;
    changed_.notify_all();
  }
  std::uint64_t rounds(std::size_t part) { return rounds_[part]; }
  std::uint64_t bytes() const { return exchanged_; }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::vector<unsigned char>> lists_, result_;
  std::size_t arrived_ = 0;
  std::uint64_t round_ = 0, exchanged_ = 0;
  std::map<std::size_t, std::uint64_t> rounds_;
  bool failed_ = false;
};

}  // namespace

// Each part's message for each part, through all_gather (PartOptions::deliver).
std::vector<std::vector<unsigned char>> deliver_by_gather(ThreadExchange& exchange, std::size_t part,
                                                          const std::vector<std::vector<unsigned char>>& to_each) {
  std::vector<unsigned char> packed;
  for (const std::vector<unsigned char>& m : to_each) {
    const std::uint64_t size = m.size();
    packed.insert(packed.end(), reinterpret_cast<const unsigned char*>(&size),
                  reinterpret_cast<const unsigned char*>(&size) + sizeof size);
    packed.insert(packed.end(), m.begin(), m.end());
  }
  std::vector<std::vector<unsigned char>> mine;
  for (const std::vector<unsigned char>& theirs : exchange.all_gather(part, packed)) {
    std::size_t at = 0;
    for (std::size_t p = 0;; ++p) {
      std::uint64_t size = 0;
      std::memcpy(&size, theirs.data() + at, sizeof size);
      at += sizeof size;
      if (p == part) {
        mine.emplace_back(theirs.begin() + std::ptrdiff_t(at), theirs.begin() + std::ptrdiff_t(at + size));
        break;
      }
      at += std::size_t(size);
    }
  }
  return mine;
}

TEST_CASE("floating parts that exchange borders while they run give one process's bytes", "[distributed]") {
  ScratchDir d;
  const std::string input = d.file("p.ply");
  REQUIRE(run_cli("generate --shape parts --tris 150000 --seed 9 --attributes --quiet -o " + q(input)).exit_code == 0);
  // The same mesh as ascii PLY, whose faces cannot be read by range.
  const std::string ascii = d.file("p-ascii.ply");
  REQUIRE(
      run_cli("generate --shape parts --tris 150000 --seed 9 --attributes --ascii --quiet -o " + q(ascii)).exit_code ==
      0);
  oocsimp::SimplifyOptions o;
  o.method = oocsimp::ClusterMethod::floating;
  o.sizing.grid = 90;
  o.floating.tile_side = 0.15;  // many tiles, so that borders cross parts everywhere
  o.threads = 1;
  o.memory_budget = std::uint64_t(40) << 20;  // the binary ranges in several steps
  oocsimp::simplify_file(input, d.file("one.ply"), o, nullptr);
  // Ascii parts in one process convert their positions each: more memory.
  oocsimp::SimplifyOptions o_ascii = o;
  o_ascii.memory_budget = std::uint64_t(256) << 20;
  oocsimp::SimplifyStats whole;
  oocsimp::simplify_file(ascii, d.file("one-ascii.ply"), o_ascii, &whole);
  const std::uint64_t faces = whole.floating.faces_read;  // one process reads every face
  REQUIRE(faces >= whole.input_triangles);
  // Binary: each part reads its own range of the faces (with a delivery, or through
  // the exchange alone); ascii: each part reads every face.
  for (const char* form : {"binary, exchange", "binary, deliver", "ascii, exchange"}) {
    const bool binary = std::string(form).find("binary") == 0,
               deliver = std::string(form).find("deliver") != std::string::npos;
    for (std::uint32_t parts = 2; parts <= 4; ++parts) {
      ScratchDir work;
      ThreadExchange exchange(parts);
      std::vector<std::thread> threads;
      std::vector<std::string> errors(parts);
      std::vector<oocsimp::SimplifyStats> stats(parts);
      for (std::uint32_t i = 0; i < parts; ++i)
        threads.emplace_back([&, i] {
          oocsimp::PartOptions part{i, parts, work.path()};
          part.exchange = [&exchange, i](const std::vector<unsigned char>& mine) {
            return exchange.all_gather(i, mine);
          };
          if (deliver)
            part.deliver = [&exchange, i](const std::vector<std::vector<unsigned char>>& to_each) {
              return deliver_by_gather(exchange, i, to_each);
            };
          try {
            oocsimp::simplify_part(binary ? input : ascii, binary ? o : o_ascii, part, &stats[i]);
          } catch (const std::exception& e) {
            errors[i] = e.what();
            exchange.fail();
          }
        });
      for (std::thread& t : threads) t.join();
      INFO(form << ", " << parts << " parts");
      for (const std::string& e : errors) REQUIRE(e == "");
      std::uint64_t read = 0;
      for (const oocsimp::SimplifyStats& st : stats) {
        CHECK(st.input_triangles == whole.input_triangles);
        if (binary)
          CHECK(st.floating.faces_read <= faces / parts + 1);
        else
          CHECK(st.floating.faces_read == faces);
        read += st.floating.faces_read;
      }
      CHECK(read == (binary ? faces : parts * faces));
      // The tiling's check, the borders after grading, and at least one sweep of 8
      // colour classes: every part met the others at each.
      for (std::uint32_t i = 0; i < parts; ++i) CHECK(exchange.rounds(i) >= 2 + 8);
      CHECK(exchange.bytes() > 0);
      oocsimp::SimplifyOptions runtime;
      runtime.threads = 2;
      oocsimp::OutputOptions out;
      out.mesh = d.file("merged.ply");
      oocsimp::merge_parts(work.path(), out, runtime);
      CHECK(read_file(d.file("merged.ply")) == read_file(d.file(binary ? "one.ply" : "one-ascii.ply")));
    }
  }
}

namespace {

// Floating parts 0..parts-1 of `input` as threads exchanging as ranks do (with a
// delivery); their errors by part, their stats in `stats`.
std::vector<std::string> run_exchanging_parts(const std::string& input, const oocsimp::SimplifyOptions& o,
                                              std::uint32_t parts, const std::string& work,
                                              std::vector<oocsimp::SimplifyStats>* stats) {
  ThreadExchange exchange(parts);
  std::vector<std::thread> threads;
  std::vector<std::string> errors(parts);
  stats->assign(parts, oocsimp::SimplifyStats());
  for (std::uint32_t i = 0; i < parts; ++i)
    threads.emplace_back([&, i] {
      oocsimp::PartOptions part{i, parts, work};
      part.exchange = [&exchange, i](const std::vector<unsigned char>& mine) { return exchange.all_gather(i, mine); };
      part.deliver = [&exchange, i](const std::vector<std::vector<unsigned char>>& to_each) {
        return deliver_by_gather(exchange, i, to_each);
      };
      try {
        oocsimp::simplify_part(input, o, part, &(*stats)[i]);
      } catch (const std::exception& e) {
        errors[i] = e.what();
        exchange.fail();
      }
    });
  for (std::thread& t : threads) t.join();
  return errors;
}

// A binary PLY of an n x n grid of vertices on a wave, little-endian, with `faces`
// written as given (each its own corner count); vertex `nan_vertex` has z NaN.
std::string wave_grid_ply(int n, const std::vector<std::vector<std::int32_t>>& faces, int nan_vertex = -1) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(n * n) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(faces.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      put_le(s, float(x) / float(n));
      put_le(s, float(y) / float(n));
      put_le(s, y * n + x == nan_vertex ? std::nanf("") : 0.1f * std::sin(float(x) * 0.3f) * std::cos(float(y) * 0.2f));
    }
  for (const auto& f : faces) {
    s.push_back(char(f.size()));
    for (std::int32_t i : f) put_le(s, i);
  }
  return s;
}

}  // namespace

TEST_CASE("floating parts read their ranges only where every range can be read alone, and agree with one process",
          "[distributed]") {
  ScratchDir d;
  constexpr int n = 60;
  auto at = [](int x, int y) { return std::int32_t(y * n + x); };
  std::vector<std::vector<std::int32_t>> quads, triangles;
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      quads.push_back({at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)});
      triangles.push_back({at(x, y), at(x + 1, y), at(x + 1, y + 1)});
      triangles.push_back({at(x, y), at(x + 1, y + 1), at(x, y + 1)});
    }
  // As many two-corner faces (skipped) as quads: 26 bytes a pair, so the faces fill
  // 13 bytes each on average and the reader offers a FixedFaceTable; but the ranges
  // are not all triangles, and every part must read the whole stream.
  std::vector<std::vector<std::int32_t>> mixed = quads;
  for (std::size_t i = 0; i < quads.size(); ++i) mixed.push_back({at(0, 0), at(1, 1)});
  write_file(d.file("mixed.ply"), wave_grid_ply(n, mixed));
  // Triangles with one index out of range in the last part's range.
  std::vector<std::vector<std::int32_t>> bad = triangles;
  bad[bad.size() - 5][1] = n * n + 7;
  write_file(d.file("bad.ply"), wave_grid_ply(n, bad));
  // Triangles, but a non-finite vertex: the stream drops its triangles by position,
  // so no range is read alone. And the plain triangles, whose ranges are.
  write_file(d.file("nan.ply"), wave_grid_ply(n, triangles, n * n / 2 + 3));
  write_file(d.file("clean.ply"), wave_grid_ply(n, triangles));
  oocsimp::SimplifyOptions o;
  o.method = oocsimp::ClusterMethod::floating;
  o.sizing.grid = 40;
  o.floating.tile_side = 0.2;
  o.threads = 1;
  const struct {
    const char* name;
    std::uint64_t faces;
    bool by_range;
  } inputs[] = {{"mixed", mixed.size(), false}, {"nan", triangles.size(), false}, {"clean", triangles.size(), true}};
  for (const auto& in : inputs) {
    oocsimp::SimplifyStats whole;
    oocsimp::simplify_file(d.file(in.name + std::string(".ply")), d.file(in.name + std::string("-one.ply")), o, &whole);
    REQUIRE(whole.output_triangles > 0);
  }
  std::string one_error;
  try {
    oocsimp::simplify_file(d.file("bad.ply"), d.file("bad-one.ply"), o, nullptr);
  } catch (const oocsimp::InputError& e) {
    one_error = e.what();
  }
  REQUIRE_THAT(one_error, Catch::Matchers::Contains("vertex index 3607 out of range (3600 vertices)"));
  for (std::uint32_t parts = 2; parts <= 3; ++parts) {
    INFO(parts << " parts");
    ScratchDir bad_work;
    std::vector<oocsimp::SimplifyStats> stats;
    for (const auto& in : inputs) {
      INFO(in.name);
      ScratchDir part_work;
      const std::vector<std::string> errors =
          run_exchanging_parts(d.file(in.name + std::string(".ply")), o, parts, part_work.path(), &stats);
      for (std::uint32_t i = 0; i < parts; ++i) {
        REQUIRE(errors[i] == "");
        if (in.by_range)
          CHECK(stats[i].floating.faces_read <= in.faces / parts + 1);
        else
          CHECK(stats[i].floating.faces_read == in.faces);  // the whole stream
      }
      oocsimp::OutputOptions out;
      out.mesh = d.file("merged.ply");
      oocsimp::merge_parts(part_work.path(), out, o);
      CHECK(read_file(d.file("merged.ply")) == read_file(d.file(in.name + std::string("-one.ply"))));
    }
    // The bad index: every part reads the whole stream and fails as one process does
    // (or stops because another part failed first).
    const std::vector<std::string> bad_errors =
        run_exchanging_parts(d.file("bad.ply"), o, parts, bad_work.path(), &stats);
    bool named = false;
    for (const std::string& e : bad_errors) {
      CHECK((e == one_error || e == "another part failed"));
      named = named || e == one_error;
    }
    CHECK(named);
  }
}

TEST_CASE("merge_parts takes only how to run from its caller's options, the rest from the parts", "[distributed]") {
  ScratchDir d, work;
  const std::string input = d.file("p.ply");
  REQUIRE(run_cli("generate --shape parts --tris 30000 --seed 7 --quiet -o " + q(input)).exit_code == 0);
  oocsimp::SimplifyOptions o;
  o.target.triangles = 3000;
  oocsimp::simplify_file(input, d.file("one.ply"), o, nullptr);
  for (std::uint32_t i = 0; i < 2; ++i) oocsimp::simplify_part(input, o, {i, 2, work.path()});
  // Options a caller might pass along that would change the result: not taken.
  oocsimp::SimplifyOptions runtime;
  runtime.lock_boundary = true;
  runtime.target.triangles = 500;
  runtime.threads = 1;
  oocsimp::OutputOptions out;
  out.mesh = d.file("merged.ply");
  oocsimp::merge_parts(work.path(), out, runtime);
  CHECK(read_file(d.file("merged.ply")) == read_file(d.file("one.ply")));
}

TEST_CASE("a part refuses what a distributed run cannot do yet, naming the option", "[distributed]") {
  ScratchDir d;
  const std::string input = d.file("s.ply");
  REQUIRE(run_cli("generate --tris 2000 --quiet -o " + q(input)).exit_code == 0);
  const std::string part = "simplify " + q(input) + " -o x.ply --work-dir " + q(d.path());
  struct Case {
    const char* args;
    const char* says;
  };
  for (const Case& c : {Case{" --part 0/2 --method uniform --grid 20 --lods 3", "one level"},
                        Case{" --part 0/2 --target-tris 100 --lock-boundary", "boundary"},
                        Case{" --part 0/2 --method uniform --thick-edges", "thick edges"},
                        Case{" --part 2/2 --method uniform", "--part"}, Case{" --part x --method uniform", "--part"}}) {
    CliResult r = run_cli(part + c.args);
    INFO(c.args << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
  }
  CliResult r = run_cli("simplify " + q(input) + " -o x.ply --method uniform --part 0/2");
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--work-dir") != std::string::npos);
  r = run_cli("simplify " + q(input) + " -o x.ply --method uniform --part 0/2 --work-dir " + q(d.file("missing")));
  CHECK(r.exit_code == 4);
  CHECK(r.err.find("missing: the work folder does not exist") != std::string::npos);
  r = run_cli("merge " + q(d.path()) + " -o x.ply");
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("no part files") != std::string::npos);
}

namespace {

// "mpirun --oversubscribe -n K " with root allowed (CI containers run as root), or ""
// when the CLI was built without MPI or no mpirun is installed.
std::string mpirun(int ranks) {
  static const bool usable = [] {
    if (!OOCSIMP_CLI_HAS_MPI) return false;  // each rank would run the whole job alone
    if (std::system("command -v mpirun >/dev/null 2>&1") != 0) return false;
    ScratchDir d;
    const std::string probe = "mpirun --oversubscribe -n 2 " + std::string(OOCSIMP_CLI) + " simplify /nonexistent -o " +
                              d.file("x.ply") + " --quiet 2>" + d.file("err") + " >/dev/null";
    (void)std::system(("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 " + probe).c_str());
    return read_file(d.file("err")).find("built without MPI") == std::string::npos;
  }();
  if (!usable) return "";
  return "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -n " +
         std::to_string(ranks) + " ";
}

// Runs the CLI under `launcher` (a command prefix) with `args`.
CliResult run_launched(const std::string& launcher, const std::string& args) {
  ScratchDir d;
  CliResult r;
  const std::string command = launcher + OOCSIMP_CLI + " " + args + " >" + d.file("out") + " 2>" + d.file("err");
  const int status = std::system(command.c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(d.file("out"));
  r.err = read_file(d.file("err"));
  return r;
}

}  // namespace

TEST_CASE("mpirun with 1 to 4 ranks gives one process's bytes", "[distributed][mpi]") {
  if (mpirun(1).empty()) {
    skip_test("the CLI was built without MPI, or mpirun is missing");
    return;
  }
  ScratchDir d, tmp;
  const std::string input = d.file("terrain.ply");
  REQUIRE(run_cli("generate --shape terrain --tris 200000 --attributes --quiet -o " + q(input)).exit_code == 0);
  for (const char* method : {"uniform --grid 80", "floating --grid 80 --tile 0.1", "curvature --grid 60",
                             "qem --target-tris 3000", "floating --target-tris 3000 --tile 0.1"}) {
    const std::string options =
        std::string(" --quiet --threads 1 --tmp ") + q(tmp.path()) + " --method " + method + " " + q(input) + " -o ";
    REQUIRE(run_cli("simplify" + options + q(d.file("one.ply"))).exit_code == 0);
    for (int ranks = 1; ranks <= 4; ++ranks) {
      const CliResult r = run_launched(mpirun(ranks), "simplify" + options + q(d.file("mpi.ply")));
      INFO(method << ", " << ranks << " ranks: " << r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(read_file(d.file("mpi.ply")) == read_file(d.file("one.ply")));
      CHECK(r.err.find("rank 0 runs the job alone") == std::string::npos);
    }
    CHECK(tmp.entries().empty());  // the ranks' work folder is gone
  }
  // Rank 0's summary ends with the whole job's time next to the merge's figures.
  const CliResult r = run_launched(
      mpirun(2), "simplify " + q(input) + " -o " + q(d.file("mpi.ply")) + " --method uniform --grid 80 --threads 1");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("output  ") != std::string::npos);
  CHECK(r.out.find("job     2 ranks, ") != std::string::npos);
  // Floating cells: each rank reads only its range of the binary PLY's faces.
  const CliResult f = run_launched(mpirun(2), "simplify " + q(input) + " -o " + q(d.file("mpi.ply")) +
                                                  " --method floating --grid 80 --tile 0.1 --threads 1");
  INFO(f.err);
  REQUIRE(f.exit_code == 0);
  const std::size_t at = f.out.find("; rank 0 read ");
  REQUIRE(at != std::string::npos);
  const CliResult info = run_cli("info " + q(input));
  const std::size_t faces_at = info.out.find("faces     ");
  REQUIRE(faces_at != std::string::npos);
  CHECK(std::stoull(f.out.substr(at + 14)) == std::stoull(info.out.substr(faces_at + 10)) / 2);  // rank 0's half
}

TEST_CASE("under mpirun a failing rank is named and no output is written", "[distributed][mpi]") {
  if (mpirun(1).empty()) {
    skip_test("the CLI was built without MPI, or mpirun is missing");
    return;
  }
  ScratchDir d;
  const std::string input = d.file("s.ply");
  REQUIRE(run_cli("generate --tris 20000 --quiet -o " + q(input)).exit_code == 0);
  // Every rank fails to write its part into a folder that does not exist.
  const CliResult r = run_launched(mpirun(3), "simplify " + q(input) + " -o " + q(d.file("o.ply")) +
                                                  " --method uniform --quiet --work-dir " + q(d.file("missing")));
  INFO(r.err);
  CHECK(r.exit_code == 4);
  for (const char* rank : {"rank 0 of 3 failed", "rank 1 of 3 failed", "rank 2 of 3 failed"})
    CHECK(r.err.find(rank) != std::string::npos);
  CHECK_FALSE(file_exists(d.file("o.ply")));
}

TEST_CASE("under mpirun a rank that fails while the others exchange borders stops them all", "[distributed][mpi]") {
  if (mpirun(1).empty()) {
    skip_test("the CLI was built without MPI, or mpirun is missing");
    return;
  }
  ScratchDir d;
  const std::string input = d.file("s.ply");
  REQUIRE(run_cli("generate --tris 60000 --quiet -o " + q(input)).exit_code == 0);
  // Rank 1 alone is given a work folder that does not exist: it fails before it
  // reads, while ranks 0 and 2 wait to compare their tilings with it.
  ScratchDir work;
  const std::string args =
      "simplify " + q(input) + " -o " + q(d.file("o.ply")) + " --method floating --grid 50 --quiet";
  const std::string launcher = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe ";
  const std::string good = std::string(OOCSIMP_CLI) + " " + args + " --work-dir " + q(work.path());
  const std::string command = launcher + "-n 1 " + good + " : -n 1 " + OOCSIMP_CLI + " " + args + " --work-dir " +
                              q(d.file("missing")) + " : -n 1 " + good + " 2>" + q(d.file("err"));
  const int status = std::system(command.c_str());
  const std::string err = read_file(d.file("err"));
  INFO(err);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) != 0);
  CHECK(err.find("rank 1 of 3 failed") != std::string::npos);
  CHECK(err.find("the work folder does not exist") != std::string::npos);
  CHECK(err.find("rank 0 of 3 failed") == std::string::npos);
  CHECK(err.find("rank 2 of 3 failed") == std::string::npos);
  CHECK_FALSE(file_exists(d.file("o.ply")));
}

TEST_CASE("the Slurm array scripts run the parts and the merge", "[distributed][slurm]") {
  // Without Slurm here, the array's tasks are run as Slurm would start them: the same
  // script with SLURM_ARRAY_TASK_ID set.
  ScratchDir d, work;
  const std::string input = d.file("s.ply");
  REQUIRE(run_cli("generate --tris 100000 --quiet -o " + q(input)).exit_code == 0);
  REQUIRE(run_cli("simplify " + q(input) + " -o " + q(d.file("one.ply")) + " --method uniform --grid 300 --quiet")
              .exit_code == 0);
  const std::string scripts = std::string(OOCSIMP_SOURCE_DIR) + "/scripts/slurm/";
  const std::string env = "OOCSIMP=" + q(OOCSIMP_CLI) + " OPTIONS='--method uniform --grid 300' TMP=" + q(d.path());
  for (int task = 0; task < 3; ++task)
    REQUIRE(std::system(("cd " + q(d.path()) + " && SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " " + env +
                         " bash " + q(scripts + "array.sbatch") + " " + q(input) + " " + q(work.path()) + " 3")
                            .c_str()) == 0);
  REQUIRE(std::system(("cd " + q(d.path()) + " && " + env + " bash " + q(scripts + "merge.sbatch") + " " +
                       q(work.path()) + " " + q(d.file("out.ply")) + " >/dev/null")
                          .c_str()) == 0);
  CHECK(read_file(d.file("out.ply")) == read_file(d.file("one.ply")));
  CHECK(file_exists(d.file("out.ply.stats.json")));
}
