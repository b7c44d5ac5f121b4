#include "hierarchy/manifold_input.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <numeric>

#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// The first edge that two faces wind the same way (which also covers any edge of three
// or more faces), as from << 32 | to; none: false.
bool find_bad_edge(const std::vector<std::uint32_t>& triangles, std::uint64_t* edge) {
  std::vector<std::uint64_t> edges;
  edges.reserve(triangles.size());
  for (std::size_t f = 0; f < triangles.size(); f += 3)
    for (int k = 0; k < 3; ++k)
      edges.push_back(std::uint64_t(triangles[f + std::size_t(k)]) << 32 | triangles[f + std::size_t((k + 1) % 3)]);
  tbb::parallel_sort(edges.begin(), edges.end());
  const auto twice = std::adjacent_find(edges.begin(), edges.end());
  if (twice == edges.end()) return false;
  *edge = *twice;
  return true;
}

[[noreturn]] void refuse(std::uint64_t edge, const std::string& name) {
  throw InputError(name + ": the edge from vertex " + std::to_string(edge >> 32) + " to vertex " +
                   std::to_string(edge & 0xffffffffu) +
                   " has two faces that wind it the same way, or more than two faces: not a manifold surface "
                   "wound consistently, which the hierarchy needs (--repair splits and orients it)");
}

// A face's side of an undirected edge: the edge's key min << 32 | max, the face, and
// whether the face winds it from min to max.
struct EdgeSide {
  std::uint64_t key;
  std::uint32_t face;
  bool forward;
  bool operator<(const EdgeSide& o) const { return key < o.key || (key == o.key && face < o.face); }
};

// Step 1 of the repair: flips faces so that faces joined by an edge of exactly two
// faces wind it oppositely. Returns the count flipped; adds the edges that cannot agree
// to *cut.
std::uint64_t orient(std::vector<std::uint32_t>& triangles, std::uint64_t* cut) {
  const std::size_t faces = triangles.size() / 3;
  std::vector<EdgeSide> sides;
  sides.reserve(triangles.size());
  for (std::size_t f = 0; f < faces; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles[3 * f + std::size_t(k)], b = triangles[3 * f + std::size_t((k + 1) % 3)];
      sides.push_back({std::uint64_t(std::min(a, b)) << 32 | std::max(a, b), std::uint32_t(f), a < b});
    }
  tbb::parallel_sort(sides.begin(), sides.end());
  // The faces' links across edges of exactly two faces: the other face, and whether the
  // two wind the edge the same way (then one of them must turn).
  struct Link {
    std::uint32_t face, other;
    bool same;
  };
  std::vector<Link> links;
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && sides[j].key == sides[i].key) ++j;
    if (j - i == 2) {
      const bool same = sides[i].forward == sides[i + 1].forward;
      links.push_back({sides[i].face, sides[i + 1].face, same});
      links.push_back({sides[i + 1].face, sides[i].face, same});
    } else if (j - i > 2) {
      ++*cut;
    }
    i = j;
  }
  std::vector<EdgeSide>().swap(sides);
  std::sort(links.begin(), links.end(),
            [](const Link& a, const Link& b) { return a.face < b.face || (a.face == b.face && a.other < b.other); });
  std::vector<std::uint32_t> first(faces + 1, 0);
  for (const Link& l : links) ++first[l.face + 1];
  for (std::size_t f = 0; f < faces; ++f) first[f + 1] += first[f];

  // Breadth first from each component's first face: flip[f] says whether f turns.
  constexpr std::uint8_t kUnseen = 2;
  std::vector<std::uint8_t> flip(faces, kUnseen);
  std::vector<std::uint32_t> component;
  std::uint64_t flipped = 0, conflicts = 0;
  for (std::size_t seed = 0; seed < faces; ++seed) {
    if (flip[seed] != kUnseen) continue;
    component.assign(1, std::uint32_t(seed));
    flip[seed] = 0;
    std::size_t turned = 0;
    for (std::size_t at = 0; at < component.size(); ++at) {
      const std::uint32_t f = component[at];
      for (std::uint32_t i = first[f]; i < first[f + 1]; ++i) {
        const Link& l = links[i];
        const std::uint8_t want = std::uint8_t(flip[f] ^ std::uint8_t(l.same));
        if (flip[l.other] == kUnseen) {
          flip[l.other] = want;
          turned += want;
          component.push_back(l.other);
        } else if (flip[l.other] != want && l.face < l.other) {
          ++conflicts;  // counted once, from its lower face
        }
      }
    }
    // Keep the winding most of the component's faces had.
    const bool invert = 2 * turned > component.size();
    for (const std::uint32_t f : component) {
      if (invert) flip[f] ^= 1;
      if (!flip[f]) continue;
      std::swap(triangles[3 * std::size_t(f) + 1], triangles[3 * std::size_t(f) + 2]);
      ++flipped;
    }
  }
  *cut += conflicts;
  return flipped;
}

// Step 3 of the repair: gives every face of an edge that is still wound twice the same
// way three vertices of its own. Returns the count of such faces.
std::uint64_t detach_faces_of_bad_edges(std::vector<Vec3d>& positions, std::vector<std::uint32_t>& triangles,
                                        std::vector<std::uint32_t>& copied_from) {
  std::vector<EdgeSide> sides;
  for (std::size_t f = 0; f < triangles.size() / 3; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles[3 * f + std::size_t(k)], b = triangles[3 * f + std::size_t((k + 1) % 3)];
      sides.push_back({std::uint64_t(a) << 32 | b, std::uint32_t(f), true});
    }
  tbb::parallel_sort(sides.begin(), sides.end());
  std::vector<std::uint32_t> detach;
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && sides[j].key == sides[i].key) ++j;
    if (j - i > 1)
      for (std::size_t k = i; k < j; ++k) detach.push_back(sides[k].face);
    i = j;
  }
  std::sort(detach.begin(), detach.end());
  detach.erase(std::unique(detach.begin(), detach.end()), detach.end());
  for (const std::uint32_t f : detach)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& v = triangles[3 * std::size_t(f) + std::size_t(k)];
      const std::uint32_t original =
          v < positions.size() - copied_from.size() ? v : copied_from[v - (positions.size() - copied_from.size())];
      copied_from.push_back(original);
      positions.push_back(positions[v]);
      v = std::uint32_t(positions.size() - 1);
    }
  return detach.size();
}

}  // namespace

ManifoldMesh make_manifold(std::vector<Vec3d> positions, std::vector<std::uint32_t> triangles, const std::string& name,
                           bool repair) {
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
  std::uint64_t bad_edge = 0;
  const bool bad = find_bad_edge(triangles, &bad_edge);
  if (bad && !repair) refuse(bad_edge, name);
  if (bad) out.flipped_faces = orient(triangles, &out.cut_edges);

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
    // Only across an edge of exactly two faces wound oppositely: where more faces share
    // it, or two wind it alike, a repaired mesh's faces stay apart there.
    for (std::size_t i = 0; i + 1 < spokes.size(); ++i)
      if (spokes[i].end == spokes[i + 1].end && spokes[i].out != spokes[i + 1].out &&
          (i == 0 || spokes[i - 1].end != spokes[i].end) &&
          (i + 2 == spokes.size() || spokes[i + 2].end != spokes[i].end)) {
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
  if (bad) {
    out.detached_faces = detach_faces_of_bad_edges(positions, triangles, out.copied_from);
    out.split_vertices = out.copied_from.size();
    if (find_bad_edge(triangles, &bad_edge)) refuse(bad_edge, name);  // not reached: every bad edge's faces detached
  }
  out.positions = std::move(positions);
  out.triangles = std::move(triangles);
  return out;
}

}  // namespace oocsimp
