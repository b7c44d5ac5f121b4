// Vertices that share a position exactly, found by one sort: a texture seam's two
// sides, the copies of a vertex split where fans met, a tangle.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

#include "oocsimp/geometry.hpp"

namespace oocsimp {

/// Calls run(group, count) for each set of two or more of `vertices` whose
/// positions (`position_of(v)`, a Vec3d) are equal, each set ascending by index, the
/// sets in order of position.
template <class PositionOf, class Run>
void for_each_coincident_run(std::vector<std::uint32_t> vertices, const PositionOf& position_of, const Run& run) {
  const auto key = [&](std::uint32_t v) {
    const Vec3d p = position_of(v);
    return std::make_tuple(p.x, p.y, p.z);
  };
  std::sort(vertices.begin(), vertices.end(),
            [&](std::uint32_t a, std::uint32_t b) { return key(a) != key(b) ? key(a) < key(b) : a < b; });
  for (std::size_t i = 0; i < vertices.size();) {
    std::size_t j = i + 1;
    while (j < vertices.size() && key(vertices[j]) == key(vertices[i])) ++j;
    if (j - i > 1) run(&vertices[i], j - i);
    i = j;
  }
}

}  // namespace oocsimp
