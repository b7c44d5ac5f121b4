#include <algorithm>
#include <utility>
#include <vector>

#include "common/vec3_math.hpp"
#include "refine/collapse_state.hpp"

namespace oocsimp {

void CollapseState::collapse(const Candidate& c) {
  Candidate other;
  const bool pair = mirrored(c, &other);
  collapse_one(c);
  if (pair) {
    std::vector<std::uint32_t> anchored = std::move(newly_anchored_);
    collapse_one(other);
    anchored.insert(anchored.end(), newly_anchored_.begin(), newly_anchored_.end());
    anchored.push_back(other.a);
    newly_anchored_ = std::move(anchored);
    // The survivors, both at the placement, are the seam's vertex there now.
    mirror_[c.b] = mirror_[other.b] = kNoMirror;
    mirror_[c.a] = other.a;
    mirror_[other.a] = c.a;
  } else if (!mirror_.empty() && mirror_[c.b] != kNoMirror) {
    // b was on a seam and stayed in place (evaluate): a, there now, takes its mirror.
    const std::uint32_t m = mirror_[c.b];
    mirror_[c.b] = kNoMirror;
    mirror_[c.a] = m;
    mirror_[m] = c.a;
  }
}

void CollapseState::collapse_one(const Candidate& c) {
  const std::uint32_t a = c.a, b = c.b;
  // Attributes follow the placement's position along the edge.
  const Vec3d pa = mesh_.positions[a], d = mesh_.positions[b] - pa;
  const double dd = squared_length(d);
  const double t = dd > 0 ? std::clamp(dot(c.placement - pa, d) / dd, 0.0, 1.0) : 0.0;
  const std::size_t k = mesh_.attribute_count;
  for (std::size_t j = 0; j < k; ++j) {
    double& va = mesh_.attributes[a * k + j];
    va = (1 - t) * va + t * mesh_.attributes[b * k + j];
  }
  // The faces of the edge go; b's other faces become a's. The merged list is
  // gathered apart first: appending to faces_ while reading it could move it.
  std::vector<std::uint32_t>& merged = scratch_a_;
  merged.clear();
  int removed = 0;
  for_each_face(a, [&](std::uint32_t f) {
    const std::uint32_t* tr = &mesh_.triangles[3 * f];
    if (tr[0] == b || tr[1] == b || tr[2] == b) {
      face_dead_[f] = 1;
      --live_faces_;
      ++removed;
    } else {
      merged.push_back(f);
    }
  });
  for_each_face(b, [&](std::uint32_t f) {
    std::uint32_t* tr = &mesh_.triangles[3 * f];
    for (int j = 0; j < 3; ++j)
      if (tr[j] == b) tr[j] = a;
    merged.push_back(f);
  });
  face_count_[b] = 0;
  set_face_list(a, merged);
  alive_[b] = 0;
  mesh_.positions[a] = c.placement;
  mesh_.quadrics[a].add(mesh_.quadrics[b]);
  // A valid collapse makes no boundary, and closes one only where it closes a hole of
  // three edges (closes_hole), collapsing an edge of one face between two of its
  // corners: then a and the hole's third corner are inner vertices now, free to move,
  // and the costs of the third corner's edges change.
  const bool may_close = removed == 1 && boundary_[a] && boundary_[b];
  boundary_[a] = boundary_[a] | boundary_[b];
  hub_[a] = hub_[a] | (merged.size() > kStillHub);
  newly_anchored_.clear();
  if (may_close && !complex_[a]) {
    const FanShape shape = fan_shape(a, &scratch_);
    if (shape.manifold && !shape.outline) {
      boundary_[a] = 0;
      std::vector<std::uint32_t> ring;
      neighbours(a, &ring);
      for (const std::uint32_t u : ring)
        if (boundary_[u] && !complex_[u] && !fan_shape(u, &scratch_).outline) {
          boundary_[u] = 0;
          newly_anchored_.push_back(u);
        }
    }
  }
  if (complex_[a] || complex_[b]) {
    // Around a tangle the link condition was not checked: its neighbours may have
    // become tangled too.
    complex_[a] = 1;
    std::vector<std::uint32_t> ring;
    neighbours(a, &ring);
    for (std::uint32_t u : ring)
      if (!complex_[u] && !fan_shape(u, &scratch_).manifold) {
        complex_[u] = 1;
        newly_anchored_.push_back(u);
      }
  }
}

bool CollapseState::longest_edge(int faces, std::pair<std::uint32_t, std::uint32_t>* edge) const {
  double longest = -1;
  std::pair<std::uint32_t, std::uint32_t> best{0, 0};
  for (std::uint32_t f = 0; f < face_dead_.size(); ++f) {
    if (face_dead_[f]) continue;
    const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(f)];
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t u = t[k], w = t[(k + 1) % 3];
      if (faces_on_edge(u, w) != faces || (faces == 1 && touches_seam(u, w))) continue;
      const double l = squared_distance(mesh_.positions[u], mesh_.positions[w]);
      const std::pair<std::uint32_t, std::uint32_t> key{std::min(u, w), std::max(u, w)};
      if (l > longest || (l == longest && key < best)) longest = l, best = key;
    }
  }
  if (edge) *edge = best;
  return longest >= 0;
}

bool CollapseState::split_longest_edge(int faces) {
  std::pair<std::uint32_t, std::uint32_t> edge;
  if (!longest_edge(faces, &edge)) return false;
  split_edge(edge.first, edge.second, faces);
  return true;
}

void CollapseState::split_edge(std::uint32_t u, std::uint32_t w, int faces) {
  std::vector<std::uint32_t> around;  // the faces on (u, w)
  for_each_face(u, [&](std::uint32_t f) {
    const std::uint32_t* t = &mesh_.triangles[3 * f];
    if (t[0] == w || t[1] == w || t[2] == w) around.push_back(f);
  });
  const std::uint32_t m = std::uint32_t(mesh_.positions.size());
  mesh_.positions.push_back((mesh_.positions[u] + mesh_.positions[w]) * 0.5);
  mesh_.quadrics.push_back(Quadric());
  const std::size_t k = mesh_.attribute_count;
  for (std::size_t j = 0; j < k; ++j)
    mesh_.attributes.push_back(0.5 * (mesh_.attributes[u * k + j] + mesh_.attributes[w * k + j]));
  alive_.push_back(1);
  locked_.push_back(0);
  if (!mirror_.empty()) mirror_.push_back(kNoMirror);
  complex_.push_back(faces > 2);  // on an edge of three or more faces
  boundary_.push_back(faces == 1);
  hub_.push_back(0);
  face_start_.push_back(std::uint32_t(faces_.size()));
  face_count_.push_back(0);
  // Each face (p, q, r) on the edge, p q its side along it, becomes (p, m, r) and
  // (m, q, r): the same orientation, the same plane. q trades the face for the new
  // one; r and m gain faces.
  auto replace_list = [&](std::uint32_t v, std::uint32_t from, std::uint32_t to, bool add) {
    std::vector<std::uint32_t>& list = scratch_a_;
    list.clear();
    for_each_face(v, [&](std::uint32_t f) { list.push_back(f == from ? to : f); });
    if (add) list.push_back(to);
    set_face_list(v, list);
  };
  for (std::uint32_t f : around) {
    int side = 0;
    for (int j = 0; j < 3; ++j) {
      const std::uint32_t x = mesh_.triangles[3 * f + std::size_t(j)];
      const std::uint32_t y = mesh_.triangles[3 * f + std::size_t(j + 1) % 3];
      if ((x == u && y == w) || (x == w && y == u)) side = j;
    }
    const std::uint32_t q = mesh_.triangles[3 * f + std::size_t(side + 1) % 3];
    const std::uint32_t r = mesh_.triangles[3 * f + std::size_t(side + 2) % 3];
    const std::uint32_t added = std::uint32_t(face_dead_.size());
    mesh_.triangles[3 * f + std::size_t(side + 1) % 3] = m;
    mesh_.triangles.insert(mesh_.triangles.end(), {m, q, r});
    face_dead_.push_back(0);
    first_normal_.push_back(first_normal_[f]);
    ++live_faces_;
    replace_list(q, f, added, false);
    replace_list(r, kNoFace, added, true);
    replace_list(m, kNoFace, f, true);
    replace_list(m, kNoFace, added, true);
  }
}

bool CollapseState::split_up_to(std::uint64_t target) {
  // The live edges of one and of two faces in heaps, longest first (ties: the lowest
  // vertices), so that each split takes the edge split_longest_edge() would find,
  // without a search of the whole mesh. Lengths never change; an entry whose edge has
  // been split since (it has no face left) is passed over.
  struct Edge {
    double length;
    std::uint32_t u, w;
  };
  auto shorter = [](const Edge& x, const Edge& y) {
    return x.length < y.length || (x.length == y.length && (x.u > y.u || (x.u == y.u && x.w > y.w)));
  };
  std::vector<Edge> heaps[2];
  auto push = [&](std::uint32_t u, std::uint32_t w, int faces) {
    if (faces != 1 && faces != 2) return;
    if (faces == 1 && touches_seam(u, w)) return;  // one side of a seam alone would open it
    if (u > w) std::swap(u, w);
    heaps[faces - 1].push_back({squared_distance(mesh_.positions[u], mesh_.positions[w]), u, w});
    std::push_heap(heaps[faces - 1].begin(), heaps[faces - 1].end(), shorter);
  };
  if (live_faces_ < target)
    for (std::uint32_t f = 0; f < face_dead_.size(); ++f) {
      if (face_dead_[f]) continue;
      const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(f)];
      for (std::uint32_t k = 0; k < 3; ++k) push(t[k], t[(k + 1) % 3], faces_on_edge(t[k], t[(k + 1) % 3]));
    }
  auto split_longest = [&](int faces) {
    std::vector<Edge>& heap = heaps[faces - 1];
    while (!heap.empty()) {
      const Edge e = heap.front();
      std::pop_heap(heap.begin(), heap.end(), shorter);
      heap.pop_back();
      if (faces_on_edge(e.u, e.w) != faces) continue;
      split_edge(e.u, e.w, faces);
      const std::uint32_t m = std::uint32_t(mesh_.positions.size() - 1);
      push(e.u, m, faces);
      push(m, e.w, faces);
      for_each_face(m, [&](std::uint32_t f) {
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t r = mesh_.triangles[3 * f + std::size_t(k)];
          if (r != m && r != e.u && r != e.w) push(m, r, 2);
        }
      });
      return true;
    }
    return false;
  };
  while (live_faces_ < target) {
    const std::uint64_t missing = target - live_faces_;
    if (missing % 2 == 1 && split_longest(1)) continue;
    // Without an edge of one face an odd count stays one short: edges of two faces
    // take it there.
    if (missing >= 2 && split_longest(2)) continue;
    if (!split_longest(1)) return false;
  }
  return live_faces_ == target;
}

}  // namespace oocsimp
