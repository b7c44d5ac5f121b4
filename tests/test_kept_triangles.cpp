// Tests of the kept triangles and the cross-tile stitch (src/stitch/kept_triangles.hpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

#include "stitch/kept_triangles.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

TEST_CASE("a kept triangle keeps its corners' order and its index", "[stitch]") {
  const std::array<std::uint64_t, 3> orders[] = {{5, 9, 2}, {2, 5, 9}, {9, 2, 5}, {9, 5, 2}, {2, 9, 5}, {5, 2, 9}};
  for (const auto& o : orders) {
    KeptTriangle k = KeptTriangle::of(123456789, o[0], o[1], o[2]);
    CHECK(k.index() == 123456789);
    CHECK(k.corners() == o);
    CHECK((k.c[0] == 2 && k.c[1] == 5 && k.c[2] == 9));
  }
}

TEST_CASE("deduplication keeps each cluster triple once, at its lowest input index", "[stitch]") {
  std::vector<KeptTriangle> kept = {KeptTriangle::of(40, 1, 2, 3), KeptTriangle::of(7, 3, 2, 1),
                                    KeptTriangle::of(12, 2, 3, 1), KeptTriangle::of(3, 4, 5, 6),
                                    KeptTriangle::of(90, 6, 5, 4), KeptTriangle::of(1, 1, 2, 4)};
  dedupe_kept_triangles(kept);
  REQUIRE(kept.size() == 3);
  std::sort(kept.begin(), kept.end(),
            [](const KeptTriangle& a, const KeptTriangle& b) { return a.index() < b.index(); });
  CHECK(kept[0].index() == 1);
  CHECK(kept[1].index() == 3);
  CHECK(kept[2].index() == 7);
  CHECK(kept[2].corners() == std::array<std::uint64_t, 3>{3, 2, 1});  // the orientation of triangle 7
}

// A KeptTriangleSink appending to `kept`.
KeptTriangleSink append_to(std::vector<KeptTriangle>& kept) {
  return [&kept](const KeptTriangle* t, std::size_t n) { kept.insert(kept.end(), t, t + n); };
}

TEST_CASE("the stitch joins corners reported by different tiles into triangles", "[stitch]") {
  ScratchDir d;
  StreamSpill corners(d.path(), "stitch", sizeof(CornerRecord), 16, false);
  corners.add_stream();
  corners.add_stream();
  // Triangle 10 over clusters 7, 8, 9 (corner 1 reported first, from another tile);
  // triangle 11 collapses (two corners in cluster 7); triangle 20 in bucket 1.
  std::vector<CornerRecord> a = {{10 << 2 | 1, 8, 0}, {11 << 2 | 0, 7, 0}},
                            b = {{10 << 2 | 0, 7, 0}, {10 << 2 | 2, 9, 0}},
                            c = {{11 << 2 | 1, 7, 0}, {11 << 2 | 2, 3, 0}};
  corners.append(0, a.data(), a.size());
  corners.append(0, b.data(), b.size());
  corners.append(0, c.data(), c.size());
  std::vector<CornerRecord> e = {{20 << 2 | 2, 1, 0}, {20 << 2 | 0, 3, 0}, {20 << 2 | 1, 2, 0}};
  corners.append(1, e.data(), e.size());
  corners.flush();
  std::vector<KeptTriangle> kept;
  stitch_cross_tile_corners(corners, append_to(kept));
  REQUIRE(kept.size() == 2);
  std::sort(kept.begin(), kept.end(),
            [](const KeptTriangle& x, const KeptTriangle& y) { return x.index() < y.index(); });
  CHECK(kept[0].index() == 10);
  CHECK(kept[0].corners() == std::array<std::uint64_t, 3>{7, 8, 9});
  CHECK(kept[1].index() == 20);
  CHECK(kept[1].corners() == std::array<std::uint64_t, 3>{3, 2, 1});
}

TEST_CASE("the stitch refuses a triangle that lacks a corner", "[stitch]") {
  ScratchDir d;
  StreamSpill corners(d.path(), "stitch", sizeof(CornerRecord), 16, false);
  corners.add_stream();
  std::vector<CornerRecord> a = {
      {5 << 2 | 0, 1, 0}, {5 << 2 | 1, 2, 0}, {6 << 2 | 0, 1, 0}, {6 << 2 | 1, 2, 0}, {6 << 2 | 2, 3, 0}};
  corners.append(0, a.data(), a.size());
  corners.flush();
  std::vector<KeptTriangle> kept;
  CHECK_THROWS_AS(stitch_cross_tile_corners(corners, append_to(kept)), std::logic_error);
}
