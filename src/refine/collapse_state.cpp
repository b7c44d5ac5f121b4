#include "refine/collapse_state.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "cluster/plane_quadric.hpp"
#include "common/coincident_runs.hpp"
#include "common/huge_pages.hpp"
#include "common/math_constants.hpp"
#include "common/vec3_math.hpp"
#include "refine/small_lists.hpp"

namespace oocsimp {

namespace {

// A texture seam's line quadric against an outline's (add_boundary_planes): the
// outline's weight, 1000 per squared edge length, is about 2000 times a face plane's
// (area-weighted); a seam's is about twice a face's.
constexpr double kSeamShare = 1e-3;

}  // namespace

CollapseState::CollapseState(QuadricMesh mesh, const CollapseSettings& settings)
    : mesh_(std::move(mesh)),
      cos_max_turn_(std::cos(settings.max_normal_turn_degrees * kPi / 180)),
      min_compactness_(settings.min_compactness) {
  const std::size_t n = mesh_.positions.size();
  mesh_.quadrics.resize(n);
  alive_.assign(n, 1);
  complex_.assign(n, 0);
  face_dead_.assign(mesh_.triangles.size() / 3, 0);
  live_faces_ = face_dead_.size();
  first_normal_ = std::move(mesh_.face_normals);
  mesh_.face_normals.clear();
  if (first_normal_.size() != face_dead_.size()) {
    resize_filled(&first_normal_, face_dead_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, face_dead_.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t f = r.begin(); f != r.end(); ++f) {
                          const std::uint32_t* t = &mesh_.triangles[3 * f];
                          const Vec3d& p = mesh_.positions[t[0]];
                          first_normal_[f] = unit_normal(cross(mesh_.positions[t[1]] - p, mesh_.positions[t[2]] - p));
                        }
                      });
  }
  locked_ = std::move(mesh_.locked);
  mesh_.locked.clear();
  locked_.resize(n, 0);
  const std::vector<std::uint8_t> partial = std::move(mesh_.partial);
  mesh_.partial.clear();
  build_adjacency();
  classify_vertices();
  if (settings.lock_boundary)
    for (std::size_t v = 0; v < n; ++v)
      if (boundary_[v]) locked_[v] = 1;
  if (settings.lock_coincident) pair_coincident_vertices();
  add_boundary_planes(settings, partial);
}

void CollapseState::build_adjacency() {
  const std::size_t n = mesh_.positions.size();
  reserve_filled(&face_count_, n);
  face_count_.assign(n, 0);
  for (std::uint32_t v : mesh_.triangles) ++face_count_[v];
  reserve_filled(&face_start_, n);
  face_start_.assign(n, 0);
  std::uint32_t at = 0;
  for (std::size_t v = 0; v < n; ++v) {
    face_start_[v] = at;
    at += face_count_[v];
  }
  reserve_huge(&faces_, list_room(at));
  populate_pages(faces_.data(), at * sizeof(std::uint32_t));  // the room past them fills as collapses append
  faces_.assign(at, 0);
  std::vector<std::uint32_t> fill;
  reserve_filled(&fill, n);
  fill.assign(n, 0);
  for (std::size_t f = 0; f < face_dead_.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh_.triangles[3 * f + std::size_t(k)];
      faces_[face_start_[v] + fill[v]++] = std::uint32_t(f);
    }
  // A vertex used by no face takes no part (and is not in the result).
  for (std::size_t v = 0; v < n; ++v)
    if (face_count_[v] == 0) alive_[v] = 0;
}

void CollapseState::neighbours(std::uint32_t v, std::vector<std::uint32_t>* out) const {
  if (!distinct_neighbours(v, out)) sort_small(out);
}

bool CollapseState::distinct_neighbours(std::uint32_t v, std::vector<std::uint32_t>* out) const {
  out->clear();
  if (2 * std::size_t(face_count_[v]) <= kScannedList) {
    SmallVertexSet seen;
    for_each_corner(v, [&](std::uint32_t u) {
      if (u != v && seen.insert(u)) out->push_back(u);
    });
    return false;
  }
  for_each_face(v, [&](std::uint32_t f) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = mesh_.triangles[3 * f + std::size_t(k)];
      if (u != v) out->push_back(u);
    }
  });
  // Each neighbour comes once or twice (once per face on the edge).
  return keep_distinct(out);
}

int CollapseState::faces_on_edge(std::uint32_t a, std::uint32_t b) const {
  int m = 0;
  for_each_edge_face(a, b, [&](std::uint32_t) { ++m; });
  return m;
}

void CollapseState::edge_faces(std::uint32_t a, std::uint32_t b, std::vector<std::uint32_t>* out) const {
  out->clear();
  for_each_edge_face(a, b, [&](std::uint32_t f) { out->push_back(f); });
}

void CollapseState::live_faces(std::uint32_t v, std::vector<std::uint32_t>* out) const {
  out->clear();
  for_each_face(v, [&](std::uint32_t f) { out->push_back(f); });
}

// A vertex on an edge of three or more faces, or whose faces form more than one fan
// (two cones meeting at their apex), has no disk around it for the link condition to
// keep. Clustering leaves many (folded sheets where coarse cells cut steep slopes), so
// such a vertex is not locked but anchored: it does not move, other vertices may merge
// into it, and collapses there are checked for doubled faces instead of by the link
// condition. Each vertex is classified on its own, in parallel: anchored or not, on
// the outline or not.
void CollapseState::classify_vertices() {
  const std::size_t n = mesh_.positions.size();
  boundary_.assign(n, 0);
  hub_.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) hub_[v] = face_count_[v] > kStillHub;
  tbb::enumerable_thread_specific<VertexScratch> scratch;
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(n), 4096),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      VertexScratch& s = scratch.local();
                      for (std::uint32_t v = r.begin(); v != r.end(); ++v) {
                        if (!alive_[v]) continue;
                        const FanShape shape = fan_shape(v, &s);
                        complex_[v] = !shape.manifold;
                        boundary_[v] = shape.outline;
                      }
                    });
}

// Whether v's faces, each turned to start at v as (v, x, y), chain into one cycle
// x -> y -> ... back to the first x, each face taken once: then every neighbour is
// the x of one face and the y of another, so v has one fan, closed, with two faces on
// each of its edges (fan_shape's manifold inside, without its slots and union-find).
// The most common case by far: a vertex inside a surface wound consistently. Any
// other (an outline, a tangle, a face wound the other way) answers false and is
// classified by fan_shape's general count.
bool CollapseState::closed_fan(std::uint32_t v) const {
  constexpr std::uint32_t kMostFaces = 16;
  const std::uint32_t count = face_count_[v];
  if (count > kMostFaces) return false;
  std::uint32_t x[kMostFaces], y[kMostFaces], k = 0;
  const std::uint32_t* list = faces_.data() + face_start_[v];
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t f = list[i];
    if (face_dead_[f]) continue;
    const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(f)];
    const std::uint32_t t0 = t[0], t1 = t[1], t2 = t[2];
    // v at exactly one corner; x the corner after it, y the one before.
    if (t0 == v && t1 != v && t2 != v) {
      x[k] = t1, y[k] = t2;
    } else if (t1 == v && t0 != v && t2 != v) {
      x[k] = t2, y[k] = t0;
    } else if (t2 == v && t0 != v && t1 != v) {
      x[k] = t0, y[k] = t1;
    } else {
      return false;
    }
    ++k;
  }
  if (k < 3) return false;
  // The walk from the first face's x: each step takes the face whose x is the vertex
  // reached (the last such, should there be two), which must not be taken yet.
  std::uint32_t taken = 0, at = x[0];
  for (std::uint32_t step = 0; step < k; ++step) {
    std::uint32_t face = k;
    for (std::uint32_t i = 0; i < k; ++i) face = x[i] == at ? i : face;
    if (face == k || (taken >> face & 1)) return false;
    taken |= std::uint32_t(1) << face;
    at = y[face];
  }
  return at == x[0];
}

// The other corners of v's faces, each once in `ring` with the number of faces on its
// edge with v; the corners of one face are joined (union-find over the ring's slots).
// A ring holds a dozen or so: its slots are found in a small table on the stack
// (SmallVertexSlots); a hub's ring is sorted once and searched.
CollapseState::FanShape CollapseState::fan_shape(std::uint32_t v, VertexScratch* scratch) const {
  if (closed_fan(v)) return {true, false};
  // Room for every corner up front: the slots are then plain stores.
  const std::size_t room = 2 * std::size_t(face_count_[v]);
  if (scratch->ring.size() < room) {
    scratch->ring.resize(room);
    scratch->count.resize(room);
    scratch->parent.resize(room);
  }
  std::uint32_t* const ring = scratch->ring.data();
  std::uint32_t* const count = scratch->count.data();
  std::uint32_t* const parent = scratch->parent.data();
  std::uint32_t size = 0;
  const bool hub = room > kScannedList;
  if (hub) {
    for_each_corner(v, [&](std::uint32_t u) {
      if (u != v) ring[size++] = u;
    });
    std::sort(ring, ring + size);
    size = std::uint32_t(std::unique(ring, ring + size) - ring);
    for (std::uint32_t i = 0; i < size; ++i) count[i] = 0, parent[i] = i;
  }
  SmallVertexSlots slots;
  auto slot = [&](std::uint32_t u) {
    std::uint32_t at;
    if (hub) {
      at = std::uint32_t(std::lower_bound(ring, ring + size, u) - ring);
    } else {
      at = slots.slot(u);
      if (at == size) {
        count[size] = 0;
        parent[size] = size;
        ++size;
      }
    }
    ++count[at];
    return at;
  };
  auto root = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for_each_face(v, [&](std::uint32_t f) {
    const std::uint32_t* t = &mesh_.triangles[3 * f];
    std::uint32_t other[2], m = 0;
    for (int k = 0; k < 3; ++k)
      if (t[k] != v) {
        const std::uint32_t at = slot(t[k]);
        if (m < 2) other[m++] = at;
      }
    if (m == 2) parent[root(other[0])] = root(other[1]);
  });
  FanShape shape;
  std::uint32_t pieces = 0;
  bool thin = true;  // no edge of three or more faces
  for (std::uint32_t i = 0; i < size; ++i) {
    pieces += root(i) == i;
    thin = thin && count[i] <= 2;
    shape.outline = shape.outline || count[i] == 1;
  }
  // One fan: the neighbours, joined where a face joins them, form one piece (a cycle
  // inside, a path on the boundary); two cones meeting at v make two.
  shape.manifold = thin && pieces == 1;
  return shape;
}

std::uint64_t most_hole_edges(std::uint64_t faces, std::uint64_t target) {
  if (target == 0) return 0;
  const std::uint64_t bound = kHoleEdges * kHoleEdges * faces;
  std::uint64_t m = std::uint64_t(std::sqrt(double(bound) / double(target)));
  while (m > 0 && m * m * target >= bound) --m;
  while ((m + 1) * (m + 1) * target < bound) ++m;
  return m;
}

// Garland & Heckbert 1997 §6.1: each boundary edge adds, to both its ends, the
// quadric of its line (boundary_edge_quadric), weighted heavily so that the outline of
// an open surface (a terrain's rim, an open part's) keeps its course and relief. A
// texture seam's edge (both ends mirrored) is a boundary of its side only: its line is
// held kSeamShare as hard, about as hard as a face's plane, so that a chart's outline
// keeps its shape as the surface does. So is a hole's: a simple loop of the outline
// around which the target leaves fewer than kHoleEdges edges (a scan's gaps) has no
// shape the output could show, and held as an outline it keeps its rim's vertices at
// the cost of the rest of the surface (docs/design.md, "Holes"). The edges are added
// in face order whatever their weights, so that a mesh with no hole gets the quadrics
// it got before holes were told apart.
void CollapseState::add_boundary_planes(const CollapseSettings& settings, const std::vector<std::uint8_t>& partial) {
  const double weight = settings.boundary_weight;
  if (!(weight > 0)) return;
  struct BoundaryEdge {
    std::uint32_t u, w;
    bool seam;
    Vec3d normal;  // its face's, unit
  };
  std::vector<BoundaryEdge> found;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> outline;  // the edges not a seam's
  for (std::size_t f = 0; f < face_dead_.size(); ++f) {
    const std::uint32_t* t = &mesh_.triangles[3 * f];
    // Most faces have no two corners on the outline: nothing to add.
    if (int(boundary_[t[0]]) + boundary_[t[1]] + boundary_[t[2]] < 2) continue;
    const Vec3d& p0 = mesh_.positions[t[0]];
    const Vec3d normal = cross(mesh_.positions[t[1]] - p0, mesh_.positions[t[2]] - p0);
    const double normal_length = length(normal);
    if (!(normal_length > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = t[k], w = t[(k + 1) % 3];
      if (!boundary_[u] || !boundary_[w] || faces_on_edge(u, w) != 1) continue;
      const bool seam = seam_edge(u, w);
      found.push_back({u, w, seam, normal / normal_length});
      if (!seam) outline.emplace_back(u, w);
    }
  }
  const std::uint64_t most =
      settings.soften_holes ? most_hole_edges(settings.hole_faces ? settings.hole_faces : face_dead_.size(),
                                              settings.hole_target ? settings.hole_target : settings.target_triangles)
                            : 0;
  const std::vector<std::uint8_t> hole = hole_edges(outline, most, partial);
  std::size_t at = 0;  // in `outline`
  for (const BoundaryEdge& e : found) {
    const bool soft = e.seam || hole[at];
    if (!e.seam) ++at;
    const Quadric line = boundary_edge_quadric(mesh_.positions[e.u], mesh_.positions[e.w], e.normal,
                                               soft ? kSeamShare * weight : weight);
    mesh_.quadrics[e.u].add(line);
    mesh_.quadrics[e.w].add(line);
  }
}

// The edges' connected pieces (union-find over their ends, numbered densely): a piece
// is a loop when each of its vertices has two of its edges, and a hole when it has at
// most `most_edges` edges and none of its vertices is partial or non-manifold. A loop
// through a partial vertex (one of another tile's, in the out-of-core passes) cannot be
// told whole: it is held as an outline there, in every tile that sees a piece of it,
// so that each of its vertices gets the same planes whichever tile owns it.
std::vector<std::uint8_t> CollapseState::hole_edges(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                                                    std::uint64_t most_edges,
                                                    const std::vector<std::uint8_t>& partial) const {
  std::vector<std::uint8_t> hole(edges.size(), 0);
  if (most_edges < 3 || edges.empty()) return hole;
  std::vector<std::uint32_t> ends;
  ends.reserve(2 * edges.size());
  for (const auto& e : edges) ends.push_back(e.first), ends.push_back(e.second);
  std::sort(ends.begin(), ends.end());
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  const auto index = [&](std::uint32_t v) {
    return std::uint32_t(std::lower_bound(ends.begin(), ends.end(), v) - ends.begin());
  };
  std::vector<std::uint32_t> parent(ends.size()), degree(ends.size(), 0);
  for (std::uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  const auto root = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::vector<std::uint32_t> first(edges.size());  // each edge's first end, densely
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const std::uint32_t i = index(edges[k].first), j = index(edges[k].second);
    first[k] = i;
    ++degree[i];
    ++degree[j];
    parent[root(i)] = root(j);
  }
  std::vector<std::uint64_t> count(ends.size(), 0);
  std::vector<std::uint8_t> open(ends.size(), 0);  // not a hole
  for (std::size_t k = 0; k < edges.size(); ++k) ++count[root(first[k])];
  for (std::uint32_t i = 0; i < ends.size(); ++i)
    if (degree[i] != 2 || complex_[ends[i]] || (!partial.empty() && partial[ends[i]])) open[root(i)] = 1;
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const std::uint32_t r = root(first[k]);
    hole[k] = !open[r] && count[r] <= most_edges;
  }
  return hole;
}

std::uint64_t CollapseState::non_manifold_count() const {
  std::uint64_t n = 0;
  for (std::size_t v = 0; v < complex_.size(); ++v) n += alive_[v] && complex_[v];
  return n;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> CollapseState::edges() const {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  std::vector<std::uint32_t> ring;
  for (std::uint32_t a = 0; a < mesh_.positions.size(); ++a) {
    if (!alive_[a] || locked_[a]) continue;
    neighbours(a, &ring);
    for (std::uint32_t b : ring)
      if (b > a && !locked_[b]) out.emplace_back(a, b);
  }
  return out;
}

bool CollapseState::touches_seam(std::uint32_t u, std::uint32_t w) const {
  return !mirror_.empty() && (mirror_[u] != kNoMirror || mirror_[w] != kNoMirror);
}

bool CollapseState::seam_edge(std::uint32_t u, std::uint32_t w) const {
  if (mirror_.empty()) return false;
  const std::uint32_t mu = mirror_[u], mw = mirror_[w];
  if (mu == kNoMirror && mw == kNoMirror) return false;
  return faces_on_edge(mu == kNoMirror ? u : mu, mw == kNoMirror ? w : mw) > 0;
}

// A vertex's new face list is appended to the array of lists, in the room its
// building left (list_room); once the room is full, the live lists are packed into a
// new array with room again, so that the array never regrows (reallocated and copied,
// its new pages faulted in) as the collapses go on.
void CollapseState::set_face_list(std::uint32_t v, const std::vector<std::uint32_t>& list) {
  if (faces_.size() + list.size() > faces_.capacity()) compact_adjacency(list.size());
  face_start_[v] = std::uint32_t(faces_.size());
  face_count_[v] = std::uint32_t(list.size());
  faces_.insert(faces_.end(), list.begin(), list.end());
}

void CollapseState::compact_adjacency(std::size_t more) {
  std::size_t held = 0;
  for (std::size_t v = 0; v < face_start_.size(); ++v) held += alive_[v] ? face_count_[v] : 0;
  std::vector<std::uint32_t> packed;
  reserve_huge(&packed, list_room(held) + more);
  for (std::size_t v = 0; v < face_start_.size(); ++v) {
    const std::uint32_t start = std::uint32_t(packed.size());
    if (alive_[v]) for_each_face(std::uint32_t(v), [&](std::uint32_t f) { packed.push_back(f); });
    face_start_[v] = start;
    face_count_[v] = std::uint32_t(packed.size() - start);
  }
  faces_ = std::move(packed);
}

// Vertices sorted by position. A run of two at one position, both on a boundary of
// their side and manifold, are mirrors: the two sides of a texture seam. Every other
// run of two or more is locked: where three charts meet, or a tangle.
void CollapseState::pair_coincident_vertices() {
  mirror_.assign(mesh_.positions.size(), kNoMirror);
  std::vector<std::uint32_t> vertices;
  for (std::uint32_t v = 0; v < std::uint32_t(mesh_.positions.size()); ++v)
    if (alive_[v]) vertices.push_back(v);
  // Locked vertices pair too (a tile's border): a mirrored collapse needs both sides
  // free (valid()), and a seam edge's line quadric (add_boundary_planes) must not
  // depend on where the tiles' borders fall.
  const auto seam_side = [&](std::uint32_t v) { return boundary_[v] && !complex_[v]; };
  for_each_coincident_run(
      std::move(vertices), [&](std::uint32_t v) { return mesh_.positions[v]; },
      [&](const std::uint32_t* group, std::size_t count) {
        if (count == 2 && seam_side(group[0]) && seam_side(group[1])) {
          mirror_[group[0]] = group[1];
          mirror_[group[1]] = group[0];
        } else {
          for (std::size_t k = 0; k < count; ++k) locked_[group[k]] = 1;
        }
      });
  // No pair: no seam (every mirror() is kNoMirror either way), and the passes may
  // keep costs and work ahead (has_seams()).
  if (std::all_of(mirror_.begin(), mirror_.end(), [](std::uint32_t m) { return m == kNoMirror; })) mirror_.clear();
}

QuadricMesh CollapseState::release_vertices() {
  QuadricMesh out = std::move(mesh_);
  out.triangles.clear();
  out.locked = locked_;  // the caller's locks hold in the next state too
  return out;
}

QuadricMesh CollapseState::result(std::vector<std::uint32_t>* sources, bool geometry_only) const {
  constexpr std::uint32_t kUnused = ~std::uint32_t(0);
  std::vector<std::uint32_t> index(mesh_.positions.size(), kUnused);
  // The vertices numbered by first use, counted first so that every array is
  // allocated once.
  std::uint32_t used = 0;
  for (std::size_t f = 0; f < face_dead_.size(); ++f)
    if (!face_dead_[f])
      for (int j = 0; j < 3; ++j) {
        std::uint32_t& slot = index[mesh_.triangles[3 * f + std::size_t(j)]];
        if (slot == kUnused) slot = used++;
      }
  QuadricMesh out;
  const std::size_t k = mesh_.attribute_count;
  out.attribute_count = k;
  out.positions.resize(used);
  if (!geometry_only) out.quadrics.resize(used);
  out.attributes.resize(std::size_t(used) * k);
  if (sources) sources->assign(used, 0);
  for (std::size_t v = 0; v < index.size(); ++v) {
    const std::uint32_t i = index[v];
    if (i == kUnused) continue;
    if (sources) (*sources)[i] = std::uint32_t(v);
    out.positions[i] = mesh_.positions[v];
    if (!geometry_only) out.quadrics[i] = mesh_.quadrics[v];
    std::copy(mesh_.attributes.begin() + std::ptrdiff_t(v * k), mesh_.attributes.begin() + std::ptrdiff_t((v + 1) * k),
              out.attributes.begin() + std::ptrdiff_t(i * k));
  }
  out.triangles.reserve(3 * live_faces_);
  if (!geometry_only) out.face_normals.reserve(live_faces_);
  for (std::size_t f = 0; f < face_dead_.size(); ++f) {
    if (face_dead_[f]) continue;
    for (int j = 0; j < 3; ++j) out.triangles.push_back(index[mesh_.triangles[3 * f + std::size_t(j)]]);
    if (!geometry_only) out.face_normals.push_back(first_normal_[f]);
  }
  return out;
}

}  // namespace oocsimp
