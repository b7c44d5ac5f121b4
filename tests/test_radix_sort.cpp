// Tests of the radix sort (src/common/radix_sort.hpp) against std::stable_sort as the
// independent reference: the same order, equal keys in their input order.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "common/radix_sort.hpp"

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
