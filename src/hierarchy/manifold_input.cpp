#include "hierarchy/manifold_input.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <numeric>

#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// The faces with directed edge a->b, sorted: two of one key are two faces winding one
// edge the same way, which also covers any edge of three or more faces.
void check_edges(const std::vector<std::uint32_t>& triangles, const std::string& name) {
  std::vector<std::uint64_t> edges;
  edges.reserve(triangles.size());
  for (std::size_t f = 0; f < triangles.size(); f += 3)
    for (int k = 0; k < 3; ++k)
      edges.push_back(std::uint64_t(triangles[f + std::size_t(k)]) << 32 | triangles[f + std::size_t((k + 1) % 3)]);
  tbb::parallel_sort(edges.begin(), edges.end());
  const auto twice = std::adjacent_find(edges.begin(), edges.end());
  if (twice == edges.end()) return;
  throw InputError(name + ": the edge from vertex " + std::to_string(*twice >> 32) + " to vertex " +
                   std::to_string(*twice & 0xffffffffu) +
                   " has two faces that wind it the same way, or more than two faces: not a manifold surface "
                   "wound consistently, which the hierarchy needs");
}

}  // namespace

ManifoldMesh make_manifold(std::vector<Vec3d> positions, std::vector<std::uint32_t> triangles,
                           const std::string& name) {
  ManifoldMesh out;
  std::size_t kept = 0;
  for (std::size_t f = 0; f + 2 < triangles.size(); f += 3) {
    const std::uint32_t a = triangles[f], b = triangles[f + 1], c = triangles[f + 2];
    if (a == b || b == c || c == a || !is_finite(positions[a]) || !is_finite(positions[b]) ||
        !is_finite(positions[c])) {
      ++out.dropped_faces;
      continue;
    }
    triangles[kept++] = a;
    triangles[kept++] = b;
    triangles[kept++] = c;
  }
  triangles.resize(kept);
  check_edges(triangles, name);

  // The faces around each vertex, in face order.
  const std::size_t n = positions.size();
  std::vector<std::uint32_t> start(n + 1, 0), around(triangles.size());
  for (std::uint32_t v : triangles) ++start[v + 1];
  for (std::size_t v = 0; v < n; ++v) start[v + 1] += start[v];
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < triangles.size(); ++i) around[fill[triangles[i]]++] = std::uint32_t(i / 3);
  }
  // Per vertex, faces (v, x, y) and (v, y', x') meet along v-x when x' = x: a union of
  // the faces joined so, by sorting each face's two spokes by their far end.
  struct Spoke {
    std::uint32_t end, face;  // face: its place in the vertex's list
    bool out;                 // v -> end in that face
  };
  std::vector<Spoke> spokes;
  std::vector<std::uint32_t> parent;
  for (std::uint32_t v = 0; v < n; ++v) {
    const std::uint32_t first = start[v], count = start[v + 1] - first;
    if (count < 2) continue;
    spokes.clear();
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t* t = &triangles[3 * std::size_t(around[first + i])];
      const int at = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      spokes.push_back({t[(at + 1) % 3], i, true});
      spokes.push_back({t[(at + 2) % 3], i, false});
    }
    std::sort(spokes.begin(), spokes.end(),
              [](const Spoke& a, const Spoke& b) { return a.end < b.end || (a.end == b.end && a.face < b.face); });
    parent.resize(count);
    std::iota(parent.begin(), parent.end(), 0u);
    auto root = [&](std::uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (std::size_t i = 0; i + 1 < spokes.size(); ++i)
      if (spokes[i].end == spokes[i + 1].end) {
        const std::uint32_t a = root(spokes[i].face), b = root(spokes[i + 1].face);
        parent[std::max(a, b)] = std::min(a, b);  // the root is a fan's first face
      }
    // Fans other than the first face's get a copy of v each.
    std::vector<std::uint32_t> copy_of(count, v);
    for (std::uint32_t i = 1; i < count; ++i) {
      const std::uint32_t r = root(i);
      if (r == 0) continue;
      if (r == i) {
        copy_of[i] = std::uint32_t(positions.size());
        positions.push_back(positions[v]);
        out.copied_from.push_back(v);
        ++out.split_vertices;
      } else {
        copy_of[i] = copy_of[r];
      }
      std::uint32_t* t = &triangles[3 * std::size_t(around[first + i])];
      for (int k = 0; k < 3; ++k)
        if (t[k] == v) t[k] = copy_of[i];
    }
  }
  out.positions = std::move(positions);
  out.triangles = std::move(triangles);
  return out;
}

}  // namespace oocsimp
