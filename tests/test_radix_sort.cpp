// Tests of the radix sorts (src/common/radix_sort.hpp) against the standard library's
// sorts as the independent reference: radix_sort gives std::stable_sort's order (equal
// keys in their input order), msd_radix_sort std::sort's for a strict total order.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "common/radix_sort.hpp"
#include "refine/collapse_queue.hpp"

using namespace oocsimp;

namespace {

struct Item {
  std::uint64_t key;
  std::uint32_t place;  // where it was before the sort
};

std::vector<Item> items(std::size_t n, std::uint64_t least, std::uint64_t span, std::uint32_t seed) {
  std::mt19937_64 random(seed);
  std::vector<Item> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t r = random();
    out[i] = {least + (span == ~std::uint64_t(0) ? r : r % (span + 1)), std::uint32_t(i)};
  }
  return out;
}

bool same(const std::vector<Item>& x, const std::vector<Item>& y) {
  return x.size() == y.size() && std::equal(x.begin(), x.end(), y.begin(), [](const Item& a, const Item& b) {
           return a.key == b.key && a.place == b.place;
         });
}

}  // namespace

TEST_CASE("radix sort gives std::stable_sort's order for any size and span of keys", "[radix_sort]") {
  const auto key = [](const Item& x) { return x.key; };
  for (std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(100), std::size_t(2047), std::size_t(2048),
                        std::size_t(5000), std::size_t(100000)})
    for (const auto& [least, span] : {std::pair<std::uint64_t, std::uint64_t>{0, 0},
                                      {0, 15},
                                      {1000000007, 1 << 20},
                                      {std::uint64_t(1) << 62, (std::uint64_t(1) << 40) + 3},
                                      {0, ~std::uint64_t(0)}}) {
      INFO("n " << n << " least " << least << " span " << span);
      std::vector<Item> got = items(n, least, span, std::uint32_t(n + span % 97));
      std::vector<Item> expected = got;
      std::stable_sort(expected.begin(), expected.end(), [](const Item& a, const Item& b) { return a.key < b.key; });
      radix_sort(&got, key);
      CHECK(same(got, expected));
    }
}

TEST_CASE("radix sort orders indices by a key looked up elsewhere", "[radix_sort]") {
  // As a tile sorts its vertices: the order of ids held in another array.
  std::vector<std::uint64_t> ids = {90, 7, 7, 1u << 30, 0, 42, 7};
  for (int i = 0; i < 5000; ++i) ids.push_back(std::uint64_t(i) * 2654435761u % 100003);
  std::vector<std::uint32_t> order(ids.size()), expected(ids.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = expected[i] = i;
  radix_sort(&order, [&](std::uint32_t i) { return ids[i]; });
  std::stable_sort(expected.begin(), expected.end(), [&](std::uint32_t a, std::uint32_t b) { return ids[a] < ids[b]; });
  CHECK(order == expected);
}

TEST_CASE("msd radix sort gives std::sort's order, ties of the key broken by the comparison", "[radix_sort]") {
  // As the collapse's passes sort their edges: by cost, then by the place (a unique
  // tie-break, so that the order is a strict total one).
  const auto key = [](const Item& x) { return x.key; };
  const auto less = [](const Item& a, const Item& b) { return a.key != b.key ? a.key < b.key : a.place < b.place; };
  const auto tie = [](const Item& x) { return std::uint64_t(x.place); };
  for (std::size_t n :
       {std::size_t(0), std::size_t(1), std::size_t(255), std::size_t(256), std::size_t(5000), std::size_t(300000)})
    for (const auto& [least, span] : {std::pair<std::uint64_t, std::uint64_t>{0, 0},
                                      {0, 3},
                                      {1000000007, 1 << 20},
                                      {std::uint64_t(1) << 62, (std::uint64_t(1) << 40) + 3},
                                      {0, ~std::uint64_t(0)}}) {
      INFO("n " << n << " least " << least << " span " << span);
      std::vector<Item> got = items(n, least, span, std::uint32_t(n + span % 89));
      // Shuffled places, so that a tie is not already in order.
      for (std::size_t i = 0; i < got.size(); ++i) got[i].place = std::uint32_t((i * 2654435761u) % 1000003);
      std::vector<Item> expected = got;
      std::sort(expected.begin(), expected.end(), less);
      msd_radix_sort(got.data(), got.data() + got.size(), key, tie, less);
      CHECK(same(got, expected));
    }
}

TEST_CASE("the collapse's queue entries sort by cost_key as by Later", "[radix_sort]") {
  // The costs of the collapse: 0 (and -0, equal to it), tiny and huge values, infinity.
  std::mt19937_64 random(7);
  std::vector<QueueEntry> got;
  for (std::uint32_t i = 0; i < 50000; ++i) {
    const double cost = i % 7 == 0    ? 0.0
                        : i % 11 == 0 ? -0.0
                        : i % 13 == 0 ? HUGE_VAL
                                      : std::ldexp(double(random() % 1000), int(random() % 200) - 100);
    got.push_back({cost, std::uint32_t(random() % 1000), i});
  }
  const auto earlier = [](const QueueEntry& x, const QueueEntry& y) { return later(y, x); };
  std::vector<QueueEntry> expected = got;
  std::sort(expected.begin(), expected.end(), earlier);
  msd_radix_sort(got.data(), got.data() + got.size(), cost_key, vertices_key, earlier);
  bool equal = true;
  for (std::size_t i = 0; i < got.size(); ++i) equal = equal && got[i].a == expected[i].a && got[i].b == expected[i].b;
  CHECK(equal);
}
