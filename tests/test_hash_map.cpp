// Tests of the library's hash table (src/common/flat_hash_map.hpp) and the sets built
// on it, against std::unordered_map as the independent reference.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "cluster/triangle_set.hpp"
#include "common/flat_hash_map.hpp"
#include "grid/grid_coord.hpp"

using namespace oocsimp;

namespace {

// Every key in one probe run: exercises collisions and the wrap-around of probing.
struct ConstantHash {
  std::uint64_t operator()(std::uint64_t) const { return 42; }
};

}  // namespace

TEST_CASE("flat hash map numbers keys in order of first insertion", "[hash_map]") {
  FlatHashMap<std::uint64_t, int> map;
  const std::vector<std::uint64_t> keys = {907, 3, 0, ~std::uint64_t(0), 1ull << 40, 17, 5};
  for (std::size_t i = 0; i < keys.size(); ++i) {
    auto r = map.try_insert(keys[i]);
    CHECK(r.first == i);
    CHECK(r.second);
    CHECK(map.value(r.first) == 0);  // value-initialised
    map.value(r.first) = int(10 * i);
  }
  // Inserting again finds the first number and keeps the value.
  for (std::size_t i = keys.size(); i-- > 0;) {
    auto r = map.try_insert(keys[i]);
    CHECK(r.first == i);
    CHECK_FALSE(r.second);
    CHECK(map.insert(keys[i]) == i);
  }
  REQUIRE(map.size() == keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    CHECK(map.key(i) == keys[i]);
    CHECK(map.value(i) == int(10 * i));
    CHECK(map.find(keys[i]) == std::int64_t(i));
  }
}

TEST_CASE("flat hash map finds no absent key", "[hash_map]") {
  FlatHashMap<std::uint64_t, int> empty;
  CHECK(empty.find(0) == -1);
  CHECK(empty.find(12345) == -1);
  FlatHashMap<std::uint64_t, int> map;
  for (std::uint64_t k = 0; k < 1000; k += 2) map.insert(k);
  for (std::uint64_t k = 1; k < 1000; k += 2) CHECK(map.find(k) == -1);
  CHECK(map.size() == 500);
  // All in one probe run: a miss walks to the run's end.
  FlatHashMap<std::uint64_t, int, ConstantHash> run;
  for (std::uint64_t k = 0; k < 7; ++k) run.insert(k * 3);  // 7 of 16 slots
  for (std::uint64_t k = 0; k < 7; ++k) CHECK(run.find(k * 3) == std::int64_t(k));
  CHECK(run.find(1) == -1);
}

TEST_CASE("flat hash map keeps numbers, values and references through many rehashes", "[hash_map]") {
  FlatHashMap<std::uint64_t, std::uint64_t> map;  // 16 slots: about 15 doublings to 200k keys
  map.value(map.insert(123456789)) = 77;
  const std::uint64_t* first = &map.value(0);
  const std::size_t n = 200000;
  for (std::uint64_t i = 1; i < n; ++i) map.value(map.insert(i * 0x10001)) = i;  // a stride that collides in low bits
  CHECK(map.size() == n);
  CHECK(&map.value(0) == first);  // entries do not move
  CHECK(*first == 77);
  for (std::uint64_t i = 1; i < n; ++i) {
    REQUIRE(map.find(i * 0x10001) == std::int64_t(i));
    REQUIRE(map.value(i) == i);
  }
  // A bad hash grows correctly too (quadratic work: keep it small).
  FlatHashMap<std::uint64_t, int, ConstantHash> run;
  for (std::uint64_t k = 0; k < 300; ++k) CHECK(run.insert(k) == k);
  for (std::uint64_t k = 0; k < 300; ++k) CHECK(run.find(k) == std::int64_t(k));
}

TEST_CASE("flat hash map agrees with std::unordered_map on random keys", "[hash_map]") {
  std::mt19937_64 rng(2026);
  for (std::uint64_t range : {std::uint64_t(50), std::uint64_t(5000), ~std::uint64_t(0)}) {
    INFO("keys below " << range);
    FlatHashMap<std::uint64_t, std::uint64_t> map(64);
    std::unordered_map<std::uint64_t, std::uint64_t> number;  // key -> insertion number
    std::vector<std::uint64_t> order;
    for (int op = 0; op < 100000; ++op) {
      std::uint64_t k = range == ~std::uint64_t(0) ? rng() : rng() % range;
      if (rng() % 3 == 0) {
        auto it = number.find(k);
        REQUIRE(map.find(k) == (it == number.end() ? -1 : std::int64_t(it->second)));
      } else {
        auto ref = number.emplace(k, order.size());
        if (ref.second) order.push_back(k);
        auto r = map.try_insert(k);
        REQUIRE(r.first == ref.first->second);
        REQUIRE(r.second == ref.second);
        map.value(r.first) += k;
      }
    }
    REQUIRE(map.size() == order.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      REQUIRE(map.key(i) == order[i]);
      REQUIRE(map.value(i) % (order[i] == 0 ? 1 : order[i]) == 0);
    }
  }
}

TEST_CASE("a reserved index numbers keys as a grown one does", "[hash_map]") {
  std::mt19937_64 rng(7);
  std::vector<std::uint64_t> keys(20000);
  for (std::uint64_t& k : keys) k = rng() % 15000;  // repeats among them
  FlatHashMap<std::uint64_t, std::uint64_t> grown(16), reserved(16);
  reserved.reserve_index(keys.size());
  for (std::uint64_t k : keys) REQUIRE(grown.insert(k) == reserved.insert(k));
  REQUIRE(grown.size() == reserved.size());
  for (std::size_t i = 0; i < grown.size(); ++i) REQUIRE(grown.key(i) == reserved.key(i));
}

TEST_CASE("flat hash map clears to empty and numbers again from 0", "[hash_map]") {
  FlatHashMap<std::uint64_t, int> map(1 << 12);
  for (std::size_t round = 0; round < 3; ++round) {
    // Few keys in a large table (the per-run clear), then many (the whole-table clear).
    const std::uint64_t n = round == 1 ? 3000 : 10;
    for (std::uint64_t k = 0; k < n; ++k) CHECK(map.insert(k * 7 + round) == k);
    CHECK(map.size() == n);
    map.clear();
    CHECK(map.size() == 0);
    for (std::uint64_t k = 0; k < n; ++k) REQUIRE(map.find(k * 7 + round) == -1);
    CHECK(map.insert(99) == 0);
    CHECK(map.value(0) == 0);
    map.clear();
  }
}

TEST_CASE("flat hash set over grid coordinates numbers distinct cubes", "[hash_map]") {
  FlatHashSet<GridCoord, GridCoordHash> set;
  std::vector<GridCoord> cubes;
  for (std::int64_t x = -3; x <= 3; ++x)
    for (std::int64_t y = -3; y <= 3; ++y)
      for (std::int64_t z = -3; z <= 3; ++z) cubes.push_back({x * 1000000007, y, z});
  for (std::size_t i = 0; i < cubes.size(); ++i) CHECK(set.insert(cubes[i]) == i);
  for (std::size_t i = 0; i < cubes.size(); ++i) CHECK(set.insert(cubes[i]) == i);
  CHECK(set.size() == cubes.size());
  CHECK(set.find(GridCoord{0, 0, 4}) == -1);
  CHECK(set.key(5) == cubes[5]);
}

TEST_CASE("triangle set keeps each cell triple once, in its first orientation", "[hash_map]") {
  TriangleSet set;
  CHECK(set.insert(1, 2, 3));
  CHECK_FALSE(set.insert(2, 3, 1));  // same orientation, rotated
  CHECK_FALSE(set.insert(3, 2, 1));  // the opposite orientation: still the same cells
  CHECK(set.insert(5, 4, 6));        // an odd permutation of its sorted triple
  CHECK_FALSE(set.insert(4, 5, 6));
  CHECK(set.insert(1, 2, 4));
  REQUIRE(set.size() == 3);
  // Each triangle comes back as a rotation of its first insertion.
  auto is_rotation = [](std::array<std::uint32_t, 3> t, std::array<std::uint32_t, 3> of) {
    for (int r = 0; r < 3; ++r)
      if (t[0] == of[r] && t[1] == of[(r + 1) % 3] && t[2] == of[(r + 2) % 3]) return true;
    return false;
  };
  CHECK(is_rotation(set[0], {1, 2, 3}));
  CHECK(is_rotation(set[1], {5, 4, 6}));
  CHECK(is_rotation(set[2], {1, 2, 4}));
  CHECK_THROWS_AS(set.insert(0x80000000u, 1, 2), std::length_error);
  // Against a reference on random triples: the same triangles survive, in the same order.
  std::mt19937 rng(5);
  TriangleSet random;
  std::unordered_map<std::uint64_t, std::size_t> seen;  // sorted triple -> number
  std::vector<std::array<std::uint32_t, 3>> first;
  for (int i = 0; i < 50000; ++i) {
    std::array<std::uint32_t, 3> t = {std::uint32_t(rng() % 40), std::uint32_t(rng() % 40), std::uint32_t(rng() % 40)};
    std::array<std::uint32_t, 3> s = t;
    std::sort(s.begin(), s.end());
    bool added = seen.emplace((std::uint64_t(s[0]) << 42) | (std::uint64_t(s[1]) << 21) | s[2], first.size()).second;
    if (added) first.push_back(t);
    REQUIRE(random.insert(t[0], t[1], t[2]) == added);
  }
  REQUIRE(random.size() == first.size());
  for (std::size_t i = 0; i < first.size(); ++i) REQUIRE(is_rotation(random[i], first[i]));
}
