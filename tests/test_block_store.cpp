#include <catch2/catch.hpp>

#include <tbb/parallel_for.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "spill/block_store.hpp"
#include "spill/memory_slabs.hpp"
#include "test_support.hpp"

using namespace oocsimp;

namespace {

std::vector<unsigned char> pattern(std::uint32_t tile) {
  std::vector<unsigned char> b(tile % 5 == 0 ? 0 : 37 * tile + 3);  // odd sizes, some empty
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<unsigned char>(tile * 31 + i);
  return b;
}

std::size_t files_named(const oocsimp_test::ScratchDir& dir, const std::string& prefix) {
  std::size_t n = 0;
  for (const std::string& e : dir.entries()) n += e.rfind(prefix, 0) == 0;
  return n;
}

}  // namespace

TEST_CASE("tile blocks written from many threads read back in place, aligned and writable", "[tiles]") {
  oocsimp_test::ScratchDir scratch;
  const std::string& dir = scratch.path();
  constexpr std::uint32_t kTiles = 200;
  {
    BlockStore f(dir, "blocks-test", kTiles);
    tbb::parallel_for(std::uint32_t(0), kTiles, [&](std::uint32_t t) {
      std::vector<unsigned char> b = pattern(t);
      f.put(t, b.data(), b.size());
    });
    f.map();
    for (std::uint32_t t = 0; t < kTiles; ++t) {
      std::vector<unsigned char> b = pattern(t);
      REQUIRE(f.block_size(t) == b.size());
      if (b.empty()) {
        CHECK(f.block(t) == nullptr);
        continue;
      }
      REQUIRE(f.block(t) != nullptr);
      CHECK(reinterpret_cast<std::uintptr_t>(f.block(t)) % 8 == 0);
      CHECK(std::memcmp(f.block(t), b.data(), b.size()) == 0);
    }
    // Blocks are updated in place and do not overlap.
    for (std::uint32_t t = 0; t < kTiles; ++t)
      if (f.block_size(t)) std::memset(f.block(t), int(t & 0xff), f.block_size(t));
    for (std::uint32_t t = 0; t < kTiles; ++t)
      for (std::size_t i = 0; i < f.block_size(t); ++i) REQUIRE(f.block(t)[i] == static_cast<unsigned char>(t));
    CHECK(files_named(scratch, "oocsimp-blocks-test-") == 1);
  }
  CHECK(files_named(scratch, "oocsimp-blocks-test-") == 0);  // the file goes with its owner
}

TEST_CASE("tile blocks stay in memory within the allowance and go to the file beyond it", "[tiles][memory]") {
  constexpr std::uint32_t kTiles = 200;
  std::uint64_t all = 0;
  for (std::uint32_t t = 0; t < kTiles; ++t) all += (pattern(t).size() + 7) / 8 * 8;
  for (std::uint64_t allowance : {std::uint64_t(0), all / 2, all}) {
    INFO("allowance " << allowance << " of " << all);
    oocsimp_test::ScratchDir scratch;
    BlockStore f(scratch.path(), "blocks-test", kTiles, allowance);
    tbb::parallel_for(std::uint32_t(0), kTiles, [&](std::uint32_t t) {
      std::vector<unsigned char> b = pattern(t);
      f.put(t, b.data(), b.size());
    });
    f.map();
    CHECK(f.bytes_in_memory() <= allowance);
    CHECK(f.bytes_in_memory() + f.bytes_on_disk() == all);
    if (allowance == all) CHECK(scratch.entries().empty());  // no file at all
    if (allowance == all / 2) CHECK(f.bytes_on_disk() > 0);
    bool same = true, aligned = true;
    for (std::uint32_t t = 0; t < kTiles; ++t) {
      std::vector<unsigned char> b = pattern(t);
      if (b.empty()) {
        same = same && f.block(t) == nullptr;
        continue;
      }
      aligned = aligned && reinterpret_cast<std::uintptr_t>(f.block(t)) % 8 == 0;
      same = same && f.block_size(t) == b.size() && std::memcmp(f.block(t), b.data(), b.size()) == 0;
      std::memset(f.block(t), int(t & 0xff), b.size());  // writable in place
    }
    CHECK(same);
    CHECK(aligned);
    for (std::uint32_t t = 0; t < kTiles; ++t)
      for (std::size_t i = 0; i < f.block_size(t); ++i) REQUIRE(f.block(t)[i] == static_cast<unsigned char>(t));
    f.discard();
    CHECK(f.block(1) == nullptr);
  }
}

TEST_CASE("memory slabs give aligned, disjoint, writable blocks, also larger than a slab", "[tiles][memory]") {
  MemorySlabs slabs;
  std::vector<std::pair<unsigned char*, std::size_t>> got;
  for (std::size_t bytes : {std::size_t(1), std::size_t(13), MemorySlabs::kSlabBytes - 5, std::size_t(4096),
                            MemorySlabs::kSlabBytes * 2 + 3, std::size_t(0), std::size_t(40)}) {
    unsigned char* p = slabs.allocate(bytes);
    CHECK(reinterpret_cast<std::uintptr_t>(p) % 8 == 0);
    std::memset(p, int(got.size() + 1), bytes);
    got.emplace_back(p, bytes);
  }
  bool intact = true;
  for (std::size_t k = 0; k < got.size(); ++k)
    for (std::size_t i = 0; i < got[k].second; ++i)
      intact = intact && got[k].first[i] == static_cast<unsigned char>(k + 1);
  CHECK(intact);  // no block overwrote another
  slabs.release();
  CHECK(slabs.allocate(8) != nullptr);  // usable again after a release
}
