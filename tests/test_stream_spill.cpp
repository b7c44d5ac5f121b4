// Tests of the per-tile record streams on disk (src/spill/stream_spill.hpp) and of
// the content checksum that guards kept ones (src/io/content_hash.hpp).
#include <catch2/catch.hpp>

#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "spill/stream_spill.hpp"
#include "io/content_hash.hpp"
#include "oocsimp/error.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {
struct Record {
  std::uint64_t tile, serial, payload[2];
};
}  // namespace

TEST_CASE("tile spills give back every tile's records in append order", "[spill]") {
  for (bool compress : {false, true}) {
    ScratchDir d;
    StreamSpill spill(d.path(), "t", sizeof(Record), 7, compress);  // small blocks: many per tile
    const std::uint32_t tiles = 5;
    for (std::uint32_t t = 0; t < tiles; ++t) spill.add_stream();
    std::mt19937 rng(3);
    std::vector<std::vector<Record>> expected(tiles);
    for (int round = 0; round < 300; ++round) {
      std::uint32_t t = rng() % tiles;
      std::vector<Record> run(1 + rng() % 11);
      for (Record& r : run) {
        r = {t, expected[t].size(), {std::uint64_t(rng() % 4), std::uint64_t(rng())}};  // compressible and not
        expected[t].push_back(r);
      }
      spill.append(t, run.data(), run.size());
    }
    // Before and after the flush: unflushed buffers are read too.
    for (int pass = 0; pass < 2; ++pass) {
      for (std::uint32_t t = 0; t < tiles; ++t) {
        INFO("compress " << compress << " pass " << pass << " tile " << t);
        std::vector<Record> got;
        spill.read(t, &got);
        REQUIRE(got.size() == expected[t].size());
        CHECK(spill.record_count(t) == expected[t].size());
        for (std::size_t i = 0; i < got.size(); ++i) {
          CHECK(got[i].tile == t);
          CHECK(got[i].serial == i);
          CHECK(got[i].payload[1] == expected[t][i].payload[1]);
        }
        std::vector<unsigned char> bytes;
        spill.read(t, &bytes);
        CHECK(bytes.size() == got.size() * sizeof(Record));
      }
      spill.flush();
    }
    std::uint64_t raw = 0;
    for (const auto& e : expected) raw += e.size() * sizeof(Record);
    CHECK(spill.bytes_appended() == raw);
    if (!compress) CHECK(spill.bytes_on_disk() >= raw);
  }
}

namespace {
// 300 runs of 1-11 records appended to 5 streams at random, in blocks of 7 records:
// the streams' blocks interleave, and the last block of each is partial.
std::vector<std::vector<Record>> append_random_runs(StreamSpill& spill, std::uint32_t streams) {
  for (std::uint32_t t = 0; t < streams; ++t) spill.add_stream();
  std::mt19937 rng(3);
  std::vector<std::vector<Record>> expected(streams);
  for (int round = 0; round < 300; ++round) {
    std::uint32_t t = rng() % streams;
    std::vector<Record> run(1 + rng() % 11);
    for (Record& r : run) {
      r = {t, expected[t].size(), {std::uint64_t(rng() % 4), std::uint64_t(rng())}};
      expected[t].push_back(r);
    }
    spill.append(t, run.data(), run.size());
  }
  return expected;
}

bool same_records(const std::vector<Record>& a, const std::vector<Record>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Record)) == 0);
}
}  // namespace

TEST_CASE("spill streams come back in append order from memory, disk or both, whatever the allowance",
          "[spill][memory]") {
  // The records of all streams: 300 runs of 6 records on average, 32 bytes each.
  const std::uint64_t all = 300 * 6 * sizeof(Record);
  for (bool compress : {false, true})
    for (std::uint64_t allowance : {std::uint64_t(0), all / 3, ~std::uint64_t(0)}) {
      INFO("compress " << compress << " allowance " << allowance);
      ScratchDir d;
      StreamSpill spill(d.path(), "t", sizeof(Record), 7, compress, allowance);
      std::vector<std::vector<Record>> expected = append_random_runs(spill, 5);
      for (int pass = 0; pass < 2; ++pass) {  // before and after the flush
        for (std::uint32_t t = 0; t < 5; ++t) {
          std::vector<Record> got;
          spill.read(t, &got);
          CHECK(same_records(got, expected[t]));
          // The same records a block at a time, memory blocks without a copy.
          std::vector<Record> blocks;
          spill.for_each_block(t, [&](const void* p, std::size_t n) {
            const Record* r = static_cast<const Record*>(p);
            blocks.insert(blocks.end(), r, r + n);
          });
          CHECK(same_records(blocks, expected[t]));
        }
        spill.flush();
      }
      const std::uint64_t appended = spill.bytes_appended();
      CHECK(spill.bytes_kept_in_memory() + spill.bytes_spilled() == appended);
      if (allowance == 0) {
        CHECK(spill.bytes_kept_in_memory() == 0);
      } else if (allowance == all / 3) {
        CHECK(spill.bytes_kept_in_memory() > 0);
        CHECK(spill.bytes_kept_in_memory() <= allowance);
        CHECK(spill.bytes_spilled() > 0);
      } else {
        // Everything fits: no file was ever created, nothing written.
        CHECK(spill.bytes_kept_in_memory() == appended);
        CHECK(spill.bytes_on_disk() == 0);
        CHECK(d.entries().empty());
      }
      spill.discard();
      std::vector<Record> after;
      CHECK_THROWS_AS(spill.read(0, &after), std::logic_error);
    }
}

TEST_CASE("spill streams appended from many threads at once keep every thread's order", "[spill][memory]") {
  constexpr std::uint32_t kStreams = 3, kProducers = 8, kPerProducer = 2000;
  for (std::uint64_t allowance : {std::uint64_t(0), std::uint64_t(64) << 10, ~std::uint64_t(0)}) {
    INFO("allowance " << allowance);
    ScratchDir d;
    StreamSpill spill(d.path(), "t", sizeof(Record), 16, true, allowance);
    for (std::uint32_t t = 0; t < kStreams; ++t) spill.add_stream();
    tbb::parallel_for(std::uint32_t(0), kProducers, [&](std::uint32_t p) {
      for (std::uint64_t i = 0; i < kPerProducer; ++i) {
        Record r{p, i, {i % 5, p * 1000003 + i}};
        spill.append(std::uint32_t((p + i) % kStreams), &r, 1);
      }
    });
    spill.flush();
    std::uint64_t total = 0;
    for (std::uint32_t t = 0; t < kStreams; ++t) {
      std::vector<Record> got;
      spill.read(t, &got);
      total += got.size();
      std::vector<std::int64_t> last(kProducers, -1);
      bool ordered = true;
      for (const Record& r : got) {
        ordered = ordered && r.tile < kProducers && std::int64_t(r.serial) > last[r.tile] &&
                  (r.tile + r.serial) % kStreams == t && r.payload[1] == r.tile * 1000003 + r.serial;
        if (r.tile < kProducers) last[r.tile] = std::int64_t(r.serial);
      }
      CHECK(ordered);
    }
    CHECK(total == std::uint64_t(kProducers) * kPerProducer);
  }
}

TEST_CASE("a spill with blocks in memory is kept whole: keep_as writes them out, open_kept reads them back",
          "[spill][memory]") {
  const std::uint64_t all = 300 * 6 * sizeof(Record);
  for (bool compress : {false, true})
    for (std::uint64_t allowance : {all / 3, ~std::uint64_t(0)}) {
      INFO("compress " << compress << " allowance " << allowance);
      ScratchDir d;
      std::vector<StreamSpill::Chain> chains;
      std::vector<std::vector<Record>> expected;
      {
        StreamSpill spill(d.path(), "t", sizeof(Record), 7, compress, allowance);
        expected = append_random_runs(spill, 5);
        spill.keep_as(d.file("kept.tiles"));
        for (std::uint32_t t = 0; t < 5; ++t) chains.push_back(spill.chain(t));
        // Still readable, now from the kept file.
        std::vector<Record> got;
        spill.read(4, &got);
        CHECK(same_records(got, expected[4]));
      }
      CHECK(d.entries() == std::vector<std::string>{"kept.tiles"});  // the first file, if any, is gone
      auto kept = StreamSpill::open_kept(d.file("kept.tiles"), sizeof(Record), chains);
      for (std::uint32_t t = 0; t < 5; ++t) {
        std::vector<Record> got;
        kept->read(t, &got);
        CHECK(same_records(got, expected[t]));
      }
    }
}

TEST_CASE("a tile spill refuses a read into a buffer of the wrong size", "[spill]") {
  ScratchDir d;
  StreamSpill spill(d.path(), "t", sizeof(Record), 4, false);
  spill.add_stream();
  Record r{0, 0, {1, 2}};
  spill.append(0, &r, 1);
  Record out[2];
  CHECK_THROWS_AS(spill.read_into(0, out, sizeof out), std::logic_error);
  spill.read_into(0, out, sizeof(Record));
  CHECK(out[0].payload[1] == 2);
}

TEST_CASE("a kept spill whose block chain loops or leaves the file is an error, not a hang", "[spill]") {
  ScratchDir d;
  // Three tiles of 4 records in blocks of 2: tile 0's chain is two blocks long.
  std::vector<StreamSpill::Chain> chains;
  std::uint64_t size = 0;
  {
    StreamSpill spill(d.path(), "t", sizeof(Record), 2, false);
    for (std::uint32_t t = 0; t < 3; ++t) spill.add_stream();
    for (std::uint64_t i = 0; i < 12; ++i) {
      Record r{i % 3, i, {i, i}};
      spill.append(std::uint32_t(i % 3), &r, 1);
    }
    spill.keep_as(d.file("kept.tiles"));
    for (std::uint32_t t = 0; t < 3; ++t) chains.push_back(spill.chain(t));
    size = spill.bytes_on_disk();
  }
  std::vector<Record> out;
  {
    auto intact = StreamSpill::open_kept(d.file("kept.tiles"), sizeof(Record), chains);
    intact->read(0, &out);
    REQUIRE(out.size() == 4);
    CHECK(out[3].serial == 9);
  }
  SECTION("zero-filled: the last block's header points to offset 0, the first block to itself") {
    write_file(d.file("kept.tiles"), std::string(std::size_t(size), '\0'));
    auto zeroed = StreamSpill::open_kept(d.file("kept.tiles"), sizeof(Record), chains);
    CHECK_THROWS_AS(zeroed->read(0, &out), IoError);
    // A chain that starts at 0 meets the zeroed header there (which points to itself).
    auto at_zero = StreamSpill::open_kept(d.file("kept.tiles"), sizeof(Record), {{0, 4}});
    CHECK_THROWS_AS(at_zero->read(0, &out), IoError);
  }
  SECTION("a chain that starts beyond the end of a truncated file") {
    REQUIRE(truncate(d.file("kept.tiles").c_str(), off_t(chains[0].last_block)) == 0);
    auto truncated = StreamSpill::open_kept(d.file("kept.tiles"), sizeof(Record), chains);
    CHECK_THROWS_AS(truncated->read(0, &out), IoError);
  }
}

namespace {
// 256 bytes 0..255 four times, then "xyz": every code path (stripes, 8-, 4- and
// 1-byte tails).
std::string sample() {
  std::string s;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 256; ++i) s.push_back(char(i));
  return s + "xyz";
}
}  // namespace

TEST_CASE("the content hash is XXH64", "[hash]") {
  // Values from the reference implementation (libxxhash 0.8.1, XXH64 with seed 0).
  CHECK(content_hash("", 0) == 0xEF46DB3751D8E999ull);
  CHECK(content_hash("a", 1) == 0xD24EC4F1A98C6E5Bull);
  CHECK(content_hash("abc", 3) == 0x44BC2CF5AD770999ull);
  std::string s = sample();
  CHECK(content_hash(s.data(), s.size()) == 0xE146CB31B65BC21Aull);
}

TEST_CASE("the content hash does not depend on how the bytes are split", "[hash]") {
  const std::string s = sample();
  const std::uint64_t whole = content_hash(s.data(), s.size());
  for (std::size_t piece : {1u, 3u, 7u, 31u, 32u, 33u, 100u}) {
    CAPTURE(piece);
    ContentHash h;
    for (std::size_t at = 0; at < s.size(); at += piece) h.add(s.data() + at, std::min(piece, s.size() - at));
    CHECK(h.digest() == whole);
  }
  ScratchDir d;
  write_file(d.file("f"), s);
  FileDigest f = file_digest(d.file("f"));
  CHECK(f.size == s.size());
  CHECK(f.hash == whole);
}
