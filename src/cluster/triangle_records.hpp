// What a tile's accumulation reports of the triangles it sees: the triangles over
// three distinct clusters it decided itself, and the corners of the triangles that
// cross tiles, for the stitch (stitch/kept_triangles.hpp) to join
// (docs/design.md, "Sums that do not depend on the partition",
// last paragraph).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace oocsimp {

// One corner of a cross-tile triangle, with the cluster its owner tile gave it.
struct CornerRecord {
  std::uint64_t t_and_slot;  // t << 2 | corner slot
  std::uint64_t cluster;     // input index of the cluster's centre
  std::uint64_t vertex;      // input index of the corner (thick edges' moments)
};

// A triangle over three clusters: its clusters sorted (the key that finds the same
// triangle from other tiles and faces), where each of its corners went in that
// order, and its input index (the first occurrence wins: its corners' order and its
// place set the output).
struct KeptTriangle {
  std::uint64_t t_and_order;  // t | (3 * rank of corner 0 + rank of corner 1) << 60
  std::uint64_t c[3];         // cluster centres' input indices, ascending

  static constexpr int kOrderShift = 60;
  static KeptTriangle of(std::uint64_t t, std::uint64_t c0, std::uint64_t c1, std::uint64_t c2) {
    // rank of each corner among the three (the clusters are distinct)
    std::uint64_t r0 = std::uint64_t(c0 > c1) + std::uint64_t(c0 > c2);
    std::uint64_t r1 = std::uint64_t(c1 > c0) + std::uint64_t(c1 > c2);
    KeptTriangle k{t | (3 * r0 + r1) << kOrderShift, {c0, c1, c2}};
    std::sort(k.c, k.c + 3);
    return k;
  }
  std::uint64_t index() const { return t_and_order & ((std::uint64_t(1) << kOrderShift) - 1); }
  /// The clusters in file order.
  std::array<std::uint64_t, 3> corners() const {
    std::uint64_t code = t_and_order >> kOrderShift, r0 = code / 3, r1 = code % 3;
    return {c[r0], c[r1], c[3 - r0 - r1]};
  }
  bool same_clusters(const KeptTriangle& o) const { return c[0] == o.c[0] && c[1] == o.c[1] && c[2] == o.c[2]; }
};

/// Each cluster triple once, the occurrence with the smallest input index (its
/// orientation and its place in the output order): a minimum, so it does not
/// depend on the order in which tiles report. In place on [first, last): the kept
/// ones end sorted by triple at the front; returns how many they are.
std::size_t dedupe_kept_triangles(KeptTriangle* first, KeptTriangle* last);
/// The same on a vector, resized to the kept ones.
inline void dedupe_kept_triangles(std::vector<KeptTriangle>& kept) {
  kept.resize(dedupe_kept_triangles(kept.data(), kept.data() + kept.size()));
}

}  // namespace oocsimp
