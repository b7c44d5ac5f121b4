#include "cluster/vertex_grading.hpp"

#include <algorithm>
#include <cmath>

#include "common/vec3_math.hpp"

namespace oocsimp {

namespace {

// vertex_weight over `edges`, where repeated[i] (when given) says that edge i stands
// for several copies of itself: the pair of two copies compares a direction with
// itself, whose dot product rounds to 1 - 2^-52 now and then, and that can be the
// minimum where all directions nearly coincide (needle fans). Counting it keeps the
// weight of deduplicated edges bit for bit that of the edges with their copies.
double weight_of(const Vec3d* edges, std::size_t count, const unsigned char* repeated) {
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
    double len = length(e);
    longest = std::max(longest, len);
    if (len <= 0) continue;
    const Vec3d d = e / len;
    if (repeated && repeated[i]) min_dot = std::min(min_dot, dot(d, d));
    dirs[n++] = d;
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) min_dot = std::min(min_dot, dot(dirs[i], dirs[j]));
  // cos(theta / 2) = sqrt((1 + cos theta) / 2)
  double factor1 = std::sqrt(std::max(0.0, (1 + std::max(-1.0, min_dot)) / 2));
  return factor1 * longest;
}

}  // namespace

double vertex_weight(const Vec3d* edges, std::size_t count) { return weight_of(edges, count, nullptr); }

void lock_graded(std::vector<GradedVertex>* sorted, const std::vector<std::uint64_t>& locked) {
  if (locked.empty()) return;
  for (GradedVertex& v : *sorted)
    if (std::binary_search(locked.begin(), locked.end(), v.index)) v.weight = kLockedWeight;
  // The others keep their relative order; the locked ones (these and any locked
  // before) go before them by index, which is `precedes` among equal weights.
  const auto first_other = std::stable_partition(sorted->begin(), sorted->end(), is_locked);
  std::sort(sorted->begin(), first_other,
            [](const GradedVertex& a, const GradedVertex& b) { return a.index < b.index; });
}

std::vector<GradedVertex> grade_vertices(const std::vector<std::uint64_t>& owned, const std::uint64_t* triangles,
                                         std::size_t triangle_count, const PositionArray& positions) {
  // Local ids: the owned vertices first, in their order, then the other corners.
  std::vector<std::uint64_t> index(owned.begin(), owned.end());
  std::vector<std::uint64_t> others(triangles, triangles + 3 * triangle_count);
  std::sort(others.begin(), others.end());
  others.erase(std::unique(others.begin(), others.end()), others.end());
  std::vector<std::uint64_t> sorted_owned(owned.begin(), owned.end());
  std::sort(sorted_owned.begin(), sorted_owned.end());
  for (std::uint64_t v : others)
    if (!std::binary_search(sorted_owned.begin(), sorted_owned.end(), v)) index.push_back(v);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> id_of(index.size());
  for (std::size_t i = 0; i < index.size(); ++i) id_of[i] = {index[i], std::uint32_t(i)};
  std::sort(id_of.begin(), id_of.end());
  std::vector<std::uint32_t> corners(3 * triangle_count);
  for (std::size_t c = 0; c < corners.size(); ++c)
    corners[c] = std::lower_bound(id_of.begin(), id_of.end(), std::make_pair(triangles[c], std::uint32_t(0)))->second;
  std::vector<Vec3d> p(index.size());
  for (std::size_t i = 0; i < index.size(); ++i) p[i] = positions.get(index[i]);
  std::vector<std::uint32_t> local(owned.size());
  for (std::size_t i = 0; i < owned.size(); ++i) local[i] = std::uint32_t(i);
  LocalMesh m{corners.data(), triangle_count, index.data(), p.data(), index.size()};
  return grade_local_vertices(m, local);
}

std::vector<GradedVertex> grade_local_vertices(const LocalMesh& mesh, const std::vector<std::uint32_t>& owned,
                                               std::vector<std::uint64_t>* boundary) {
  // Per local vertex, its position among the owned (or kNone).
  constexpr std::uint32_t kNone = ~std::uint32_t(0);
  std::vector<std::uint32_t> slot(mesh.vertex_count, kNone);
  for (std::size_t i = 0; i < owned.size(); ++i) slot[owned[i]] = std::uint32_t(i);
  // Neighbours in compressed rows: count (2 per corner), prefix-sum, fill.
  std::vector<std::uint32_t> start(owned.size() + 1, 0);
  const std::uint32_t* corners = mesh.corners;
  for (std::size_t c = 0; c < 3 * mesh.triangle_count; ++c)
    if (slot[corners[c]] != kNone) start[slot[corners[c]] + 1] += 2;
  for (std::size_t i = 0; i < owned.size(); ++i) start[i + 1] += start[i];
  std::vector<std::uint32_t> neighbour(start.back());
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < mesh.triangle_count; ++t)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t s = slot[corners[3 * t + std::size_t(k)]];
      if (s == kNone) continue;
      neighbour[fill[s]++] = corners[3 * t + std::size_t((k + 1) % 3)];
      neighbour[fill[s]++] = corners[3 * t + std::size_t((k + 2) % 3)];
    }
  // Each edge once: in a manifold fan every spoke comes from two triangles; the
  // copies (bit-identical differences of the same positions) double the directions
  // and quadruple the pairs to compare, and all they add is the dot of a direction
  // with itself, which weight_of counts for the edges marked repeated. The weight
  // is bit for bit vertex_weight over every copy. (A neighbour seen for vertex i
  // carries the stamp i + 1 and remembers its edge.)
  std::vector<GradedVertex> out(owned.size());
  std::vector<Vec3d> edges;
  std::vector<unsigned char> repeated;
  std::vector<std::uint32_t> seen(mesh.vertex_count, 0), edge_of(mesh.vertex_count, 0);
  for (std::size_t i = 0; i < owned.size(); ++i) {
    const Vec3d& p = mesh.positions[owned[i]];
    edges.clear();
    repeated.clear();
    for (std::uint32_t e = start[i]; e < start[i + 1]; ++e) {
      const std::uint32_t n = neighbour[e];
      if (seen[n] == i + 1) {
        repeated[edge_of[n]] = 1;
        continue;
      }
      seen[n] = std::uint32_t(i + 1);
      edge_of[n] = std::uint32_t(edges.size());
      const Vec3d& q = mesh.positions[n];
      edges.push_back(q - p);
      repeated.push_back(0);
    }
    out[i].index = mesh.index[owned[i]];
    out[i].p = p;
    // A neighbour met once shares one face with the vertex: their edge is on the
    // boundary (every face of an owned vertex is in the mesh).
    if (boundary && std::find(repeated.begin(), repeated.end(), 0) != repeated.end()) boundary->push_back(out[i].index);
    out[i].weight = weight_of(edges.data(), edges.size(), repeated.data());
  }
  if (boundary) std::sort(boundary->begin(), boundary->end());
  return out;
}

}  // namespace oocsimp
