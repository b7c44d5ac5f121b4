#include "cluster/vertex_grading.hpp"

#include <algorithm>
#include <cmath>

namespace oocsimp {

double vertex_weight(const Vec3d* edges, std::size_t count) {
  double longest = 0;
  double min_dot = 1;  // cos of the largest angle found so far
  // Unit directions first; k is small (about 6 on a regular mesh), so all pairs.
  constexpr std::size_t kStack = 32;
  Vec3d stack_dirs[kStack];
  std::vector<Vec3d> heap_dirs;
  Vec3d* dirs = stack_dirs;
  if (count > kStack) {
    heap_dirs.resize(count);
    dirs = heap_dirs.data();
  }
  std::size_t n = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3d& e = edges[i];
    double len = std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
    longest = std::max(longest, len);
    if (len > 0) dirs[n++] = {e.x / len, e.y / len, e.z / len};
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      min_dot = std::min(min_dot, dirs[i].x * dirs[j].x + dirs[i].y * dirs[j].y + dirs[i].z * dirs[j].z);
  // cos(theta / 2) = sqrt((1 + cos theta) / 2)
  double factor1 = std::sqrt(std::max(0.0, (1 + std::max(-1.0, min_dot)) / 2));
  return factor1 * longest;
}

std::vector<GradedVertex> grade_vertices(const std::vector<std::uint64_t>& owned, const std::uint64_t* triangles,
                                         std::size_t triangle_count, const PositionArray& positions) {
  std::vector<std::int64_t> corner_local(3 * triangle_count);
  for (std::size_t t = 0; t < 3 * triangle_count; ++t) {
    auto it = std::lower_bound(owned.begin(), owned.end(), triangles[t]);
    corner_local[t] = (it != owned.end() && *it == triangles[t]) ? std::int64_t(it - owned.begin()) : -1;
  }
  return grade_vertices(owned, corner_local.data(), triangles, triangle_count, positions);
}

std::vector<GradedVertex> grade_vertices(const std::vector<std::uint64_t>& owned, const std::int64_t* corner_local,
                                         const std::uint64_t* triangles, std::size_t triangle_count,
                                         const PositionArray& positions) {
  // Incident edges in compressed rows: count, prefix-sum, fill.
  std::vector<std::uint32_t> start(owned.size() + 1, 0);
  for (std::size_t t = 0; t < 3 * triangle_count; ++t)
    if (corner_local[t] >= 0) start[std::size_t(corner_local[t]) + 1] += 2;
  for (std::size_t i = 0; i < owned.size(); ++i) start[i + 1] += start[i];
  // Each edge once: in a manifold fan every spoke comes from two triangles, and the
  // copies (bit-identical differences of the same positions) change neither factor
  // but double the directions and quadruple the pairs vertex_weight compares.
  std::vector<Vec3d> edges(start.back());
  std::vector<std::uint64_t> edge_to(start.back());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    Vec3d p[3];
    bool loaded = false;
    for (int k = 0; k < 3; ++k) {
      std::int64_t l = corner_local[3 * t + std::size_t(k)];
      if (l < 0) continue;
      if (!loaded) {
        for (int m = 0; m < 3; ++m) p[m] = positions.get(triangles[3 * t + std::size_t(m)]);
        loaded = true;
      }
      for (int m : {(k + 1) % 3, (k + 2) % 3}) {
        const std::uint64_t to = triangles[3 * t + std::size_t(m)];
        std::uint32_t& f = fill[std::size_t(l)];
        if (std::find(edge_to.begin() + start[std::size_t(l)], edge_to.begin() + f, to) != edge_to.begin() + f)
          continue;
        edge_to[f] = to;
        edges[f++] = {p[m].x - p[k].x, p[m].y - p[k].y, p[m].z - p[k].z};
      }
    }
  }
  std::vector<GradedVertex> out(owned.size());
  for (std::size_t i = 0; i < owned.size(); ++i) {
    out[i].index = owned[i];
    out[i].p = positions.get(owned[i]);
    out[i].weight = vertex_weight(edges.data() + start[i], fill[i] - start[i]);
  }
  return out;
}

}  // namespace oocsimp
