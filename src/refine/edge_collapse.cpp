#include "refine/edge_collapse.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "cluster/plane_quadric.hpp"
#include "common/coincident_runs.hpp"
#include "common/flat_hash_map.hpp"
#include "common/huge_pages.hpp"
#include "common/vec3_math.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

constexpr double kPi = 3.14159265358979323846;
// A face already below the needle guard may become at most this much thinner: with
// "no thinner at all" the lat-long poles of the generated sphere (needles already
// below the guard) froze, the collapse spent its count elsewhere and its error grew
// by orders of magnitude over the result without the freeze.
constexpr double kNeedleSlack = 0.5;
// A pass takes no collapse dearer than this times the cost of the edge at which the
// passes would end were the cheapest edges all valid and apart (meshoptimizer's
// factor; see PassDriver).
constexpr double kPassCostSlack = 1.5;
// A pass that takes less than 1 / this of the collapses it wanted hands the rest to the
// lazy queue: each pass lists and sorts every edge again, the queue only those a
// collapse moved.
constexpr std::uint64_t kPassLeastShare = 16;
// A pass works out its collapses ahead (PassDriver::work_ahead) in batches of this
// many entries, when it looks at this many or more.
constexpr std::size_t kAheadBatch = 256;
constexpr std::size_t kAheadLeast = 1024;
// A texture seam's line quadric against an outline's (add_boundary_planes): the
// outline's weight, 1000 per squared edge length, is about 2000 times a face plane's
// (area-weighted); a seam's is about twice a face's.
constexpr double kSeamShare = 1e-3;

// The lists around a vertex hold a dozen or so entries: insertion sort beats
// std::sort's setup there; long lists (a high-valence vertex) take std::sort.
template <class T>
void sort_small(std::vector<T>* v) {
  T* a = v->data();
  const std::size_t n = v->size();
  if (n > 32) {
    std::sort(a, a + n);
    return;
  }
  for (std::size_t i = 1; i < n; ++i) {
    const T x = a[i];
    std::size_t j = i;
    for (; j > 0 && a[j - 1] > x; --j) a[j] = a[j - 1];
    a[j] = x;
  }
}

// A list of up to this many vertices (a ring around a vertex: a dozen or so) is
// scanned, without early exit, where a sort or a binary search would mispredict; a
// longer one (a hub's hundreds or thousands) is sorted (keep_distinct, fan_shape).
constexpr std::size_t kScannedList = 32;
// A hub of more faces than this (the centre of a finely cut fan: a cylinder's cap, a
// cone's apex) stays where it is, as an outline vertex does: moving it would check
// every one of its faces for each collapse tried there, which made the collapse
// quadratic in its valence (a 64000-triangle cone took 31 s). Its edges collapse
// onto it. No generated shape nor scan of the benchmarks has a vertex of more than
// 168 faces.
constexpr std::size_t kStillHub = 1024;

// Drops repeats from a short list, keeping each value's first place, by scans without
// early exit (a dozen or so values: no branch to mispredict); a long one (a hub's
// hundreds) is sorted instead. Returns whether it was sorted.
bool keep_distinct(std::vector<std::uint32_t>* list) {
  if (list->size() > kScannedList) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
    return true;
  }
  std::uint32_t* x = list->data();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < list->size(); ++i) {
    bool seen = false;
    for (std::size_t j = 0; j < kept; ++j) seen |= x[j] == x[i];
    x[kept] = x[i];
    kept += !seen;
  }
  list->resize(kept);
  return false;
}

// Velho 1999 eq. 4: compactness 4 sqrt(3) a / (l1^2 + l2^2 + l3^2), with |n| = 2a, is
// 2 sqrt(3) |n| / s for s the sum of the squared sides. The checks compare it without
// a square root: 12 |n|^2 / s^2 is its square.
double sum_of_squared_sides(const Vec3d& p, const Vec3d& q, const Vec3d& r) {
  return squared_distance(p, q) + squared_distance(q, r) + squared_distance(r, p);
}

// Whether normal n turned to m by more than the angle whose cosine is `cos_max`:
// dot(n, m) <= cos_max |n| |m|, from the squared lengths, without a square root.
bool turned_too_far(const Vec3d& n, double nn, const Vec3d& m, double mm, double cos_max) {
  const double d = dot(n, m);
  const double bound = cos_max * cos_max * nn * mm;  // (cos_max |n| |m|)^2
  return cos_max >= 0 ? d <= 0 || d * d <= bound : d < 0 && d * d >= bound;
}

Quadric sum(const Quadric& x, const Quadric& y) {
  Quadric q = x;
  q.add(y);
  return q;
}

// A cost as the queue and the passes order it: rounding below the minimum of a sum of
// squares is 0, and a NaN (a quadric overflowed) the last of all, so that the order
// stays a strict one.
double clean_cost(double cost) {
  if (cost >= 0) return cost;
  return cost < 0 ? 0.0 : std::numeric_limits<double>::infinity();
}

// A x = b by Cramer's rule when A is well conditioned (its determinant is not small
// against the cube of its scale); false for the flat and linear cases, whose minimum
// is not a point.
bool solve(const Quadric& q, Vec3d* x) {
  const double c00 = q.a11 * q.a22 - q.a12 * q.a12;
  const double c01 = q.a02 * q.a12 - q.a01 * q.a22;
  const double c02 = q.a01 * q.a12 - q.a02 * q.a11;
  const double det = q.a00 * c00 + q.a01 * c01 + q.a02 * c02;
  const double scale = (q.a00 + q.a11 + q.a22) / 3;
  if (!(std::fabs(det) > 1e-6 * scale * scale * scale)) return false;
  const double c11 = q.a00 * q.a22 - q.a02 * q.a02;
  const double c12 = q.a01 * q.a02 - q.a00 * q.a12;
  const double c22 = q.a00 * q.a11 - q.a01 * q.a01;
  *x = Vec3d{c00 * q.b0 + c01 * q.b1 + c02 * q.b2, c01 * q.b0 + c11 * q.b1 + c12 * q.b2,
             c02 * q.b0 + c12 * q.b1 + c22 * q.b2} /
       det;
  return is_finite(*x);
}

// A times v.
Vec3d times(const Quadric& q, const Vec3d& v) {
  return {q.a00 * v.x + q.a01 * v.y + q.a02 * v.z, q.a01 * v.x + q.a11 * v.y + q.a12 * v.z,
          q.a02 * v.x + q.a12 * v.y + q.a22 * v.z};
}

}  // namespace

UnitNormal unit_normal(const Vec3d& normal) {
  const double l = length(normal);
  if (!(l > 0)) return {};
  return {float(normal.x / l), float(normal.y / l), float(normal.z / l)};
}

std::vector<Quadric> face_quadrics(const std::vector<Vec3d>& positions, const std::vector<std::uint32_t>& triangles) {
  std::vector<Quadric> q;
  reserve_huge(&q, positions.size());
  q.resize(positions.size());
  for (std::size_t f = 0; f + 2 < triangles.size(); f += 3) {
    const Vec3d& p = positions[triangles[f]];
    const TrianglePlane plane = triangle_plane(positions[triangles[f + 1]] - p, positions[triangles[f + 2]] - p);
    if (plane.degenerate()) continue;
    Quadric t;
    add_plane_quadric(&t, plane, dot(plane.m, p));
    for (int k = 0; k < 3; ++k) q[triangles[f + std::size_t(k)]].add(t);
  }
  return q;
}

// --- The state -------------------------------------------------------------------

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
    reserve_huge(&first_normal_, face_dead_.size());
    first_normal_.resize(face_dead_.size());
    for (std::size_t f = 0; f < face_dead_.size(); ++f) {
      const std::uint32_t* t = &mesh_.triangles[3 * f];
      const Vec3d& p = mesh_.positions[t[0]];
      first_normal_[f] = unit_normal(cross(mesh_.positions[t[1]] - p, mesh_.positions[t[2]] - p));
    }
  }
  locked_ = std::move(mesh_.locked);
  mesh_.locked.clear();
  locked_.resize(n, 0);
  build_adjacency();
  classify_vertices();
  if (settings.lock_boundary)
    for (std::size_t v = 0; v < n; ++v)
      if (boundary_[v]) locked_[v] = 1;
  if (settings.lock_coincident) pair_coincident_vertices();
  add_boundary_planes(settings.boundary_weight);
}

void CollapseState::build_adjacency() {
  const std::size_t n = mesh_.positions.size();
  face_count_.assign(n, 0);
  for (std::uint32_t v : mesh_.triangles) ++face_count_[v];
  face_start_.assign(n, 0);
  std::uint32_t at = 0;
  for (std::size_t v = 0; v < n; ++v) {
    face_start_[v] = at;
    at += face_count_[v];
  }
  reserve_huge(&faces_, at);
  faces_.assign(at, 0);
  std::vector<std::uint32_t> fill(n, 0);
  for (std::size_t f = 0; f < face_dead_.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh_.triangles[3 * f + std::size_t(k)];
      faces_[face_start_[v] + fill[v]++] = std::uint32_t(f);
    }
  compact_at_ = 2 * std::size_t(at) + 1024;
  // A vertex used by no face takes no part (and is not in the result).
  for (std::size_t v = 0; v < n; ++v)
    if (face_count_[v] == 0) alive_[v] = 0;
}

void CollapseState::neighbours(std::uint32_t v, std::vector<std::uint32_t>* out) const {
  if (!distinct_neighbours(v, out)) sort_small(out);
}

bool CollapseState::distinct_neighbours(std::uint32_t v, std::vector<std::uint32_t>* out) const {
  out->clear();
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

// The other corners of v's faces, each once in `ring` with the number of faces on its
// edge with v; the corners of one face are joined (union-find over the ring's slots).
// A ring holds a dozen or so: a scan without early exit finds a slot faster than a
// sort or a binary search, whose branches the processor cannot predict.
CollapseState::FanShape CollapseState::fan_shape(std::uint32_t v, VertexScratch* scratch) const {
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
  // A hub's ring (a fan of thousands) is sorted once and searched: scanning it for
  // each corner would be quadratic in its valence.
  const bool hub = face_count_[v] > kScannedList;
  if (hub) {
    for_each_corner(v, [&](std::uint32_t u) {
      if (u != v) ring[size++] = u;
    });
    std::sort(ring, ring + size);
    size = std::uint32_t(std::unique(ring, ring + size) - ring);
    for (std::uint32_t i = 0; i < size; ++i) count[i] = 0, parent[i] = i;
  }
  auto slot = [&](std::uint32_t u) {
    std::uint32_t at = size;
    if (hub) {
      at = std::uint32_t(std::lower_bound(ring, ring + size, u) - ring);
    } else {
      for (std::uint32_t i = 0; i < size; ++i) at = ring[i] == u ? i : at;
      if (at == size) {
        ring[size] = u;
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

// Garland & Heckbert 1997 §6.1: each boundary edge adds, to both its ends, the
// quadric of its line (boundary_edge_quadric). A texture seam's edge (both ends
// mirrored) is a boundary of its side only: its line is held kSeamShare as hard, about
// as hard as a face's plane, so that a chart's outline keeps its shape as the surface
// does, where the surface's own outline is held a thousand times harder.
void CollapseState::add_boundary_planes(double weight) {
  if (!(weight > 0)) return;
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
      const Quadric line = boundary_edge_quadric(mesh_.positions[u], mesh_.positions[w], normal / normal_length,
                                                 seam ? kSeamShare * weight : weight);
      mesh_.quadrics[u].add(line);
      mesh_.quadrics[w].add(line);
    }
  }
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

// The placement of Theoharis et al. 2008, "Graphics & Visualization: Principles and
// Algorithms", ch. 6 ("Model Representation and Simplification"): the minimum of
// Q = Q_a + Q_b where A is invertible; where it is not (flat and linear
// neighbourhoods), or the minimum lies far off the edge, the best point of the edge;
// of those and the two ends, the one with the least cost.
// The outline keeps its own vertices: a boundary vertex does not move for an inner
// one, and two boundary vertices merge into one of them, so the outline loses
// vertices but never leaves its polyline.
CollapseState::Candidate CollapseState::evaluate(std::uint32_t a, std::uint32_t b) const {
  const Quadric q = sum(mesh_.quadrics[a], mesh_.quadrics[b]);
  const Vec3d& pa = mesh_.positions[a];
  const Vec3d& pb = mesh_.positions[b];
  if (!mirror_.empty() && (mirror_[a] != kNoMirror || mirror_[b] != kNoMirror)) {
    if (mirror_[a] != kNoMirror && mirror_[b] != kNoMirror) {
      // Along a seam: both sides onto one end, costed with both sides' quadrics.
      const Quadric both = sum(q, sum(mesh_.quadrics[mirror_[a]], mesh_.quadrics[mirror_[b]]));
      const double ea = both.error(pa), eb = both.error(pb);
      return eb < ea ? Candidate{clean_cost(eb), a, b, pb} : Candidate{clean_cost(ea), a, b, pa};
    }
    // One end on a seam: it stays, so that the seam stays closed.
    const Vec3d& fixed = mirror_[a] != kNoMirror ? pa : pb;
    return {clean_cost(q.error(fixed)), a, b, fixed};
  }
  const bool anchored_a = boundary_[a] || complex_[a] || hub_[a], anchored_b = boundary_[b] || complex_[b] || hub_[b];
  if (anchored_a != anchored_b) {
    const Vec3d& fixed = anchored_a ? pa : pb;
    return {clean_cost(q.error(fixed)), a, b, fixed};
  }
  Candidate best{q.error(pa), a, b, pa};
  auto consider = [&](const Vec3d& x) {
    const double e = q.error(x);
    if (e < best.cost) best.cost = e, best.placement = x;
  };
  consider(pb);
  if (anchored_a) {
    best.cost = clean_cost(best.cost);
    return best;
  }
  const Vec3d d = pb - pa;
  const double dad = dot(d, times(q, d));
  if (dad > 0) {
    // E(pa + t d) = E(pa) + 2 t (d.A pa - d.b) + t^2 d.A d
    const double t = (dot(d, Vec3d{q.b0, q.b1, q.b2}) - dot(d, times(q, pa))) / dad;
    if (t > 0 && t < 1) consider(pa + d * t);
  }
  Vec3d x;
  const Vec3d mid = (pa + pb) * 0.5;
  if (solve(q, &x) && squared_distance(x, mid) <= 4 * squared_length(d)) consider(x);
  best.cost = clean_cost(best.cost);
  return best;
}

double CollapseState::error(const Candidate& c) const {
  const Quadric& qa = mesh_.quadrics[c.a];
  const Quadric& qb = mesh_.quadrics[c.b];
  // trace(A) is the total weight: each plane adds w n n^T with |n| = 1.
  const auto trace = [](const Quadric& q) { return q.a00 + q.a11 + q.a22; };
  double weight = trace(qa) + trace(qb);
  Candidate other;
  if (mirrored(c, &other)) weight += trace(mesh_.quadrics[other.a]) + trace(mesh_.quadrics[other.b]);
  return weight > 0 ? std::sqrt(c.cost / weight) : 0;
}

bool CollapseState::mirrored(const Candidate& c, Candidate* other) const {
  if (mirror_.empty()) return false;
  const std::uint32_t ma = mirror_[c.a], mb = mirror_[c.b];
  if (ma == kNoMirror || mb == kNoMirror) return false;
  *other = {c.cost, std::min(ma, mb), std::max(ma, mb), c.placement};
  return true;
}

int CollapseState::faces_removed(const Candidate& c) const {
  Candidate other;
  return faces_on_edge(c.a, c.b) + (mirrored(c, &other) ? faces_on_edge(other.a, other.b) : 0);
}

bool CollapseState::valid(const Candidate& c, std::uint32_t* blamed) const {
  Candidate other;
  if (!mirrored(c, &other)) return valid_one(c, blamed);
  // A seam edge (one face) whose mirrors make one too, on the other side, apart from
  // it; both collapses valid there.
  if (blamed) *blamed = kNoFace;
  if (c.b == mirror_[c.a] || other.a == c.a || other.a == c.b || other.b == c.a || other.b == c.b) return false;
  if (!alive_[other.a] || !alive_[other.b] || locked_[other.a] || locked_[other.b]) return false;
  if (faces_on_edge(c.a, c.b) != 1 || faces_on_edge(other.a, other.b) != 1) return false;
  // Welded, the seam's edge is inside the surface: between two vertices of the
  // surface's own outline it would pinch it, as an inner edge between two boundary
  // vertices would (valid_one), e.g. join the two rims of a band.
  if (on_outline(c.a) && on_outline(c.b)) return false;
  return valid_one(c, blamed) && valid_one(other, nullptr);
}

bool CollapseState::on_outline(std::uint32_t v) const {
  bool outline = false;
  for_each_face(v, [&](std::uint32_t f) {
    const std::uint32_t* t = &mesh_.triangles[3 * f];
    for (int k = 0; k < 3 && !outline; ++k) {
      const std::uint32_t w = t[k];
      if (w != v && faces_on_edge(v, w) == 1 && !seam_edge(v, w)) outline = true;
    }
  });
  return outline;
}

bool CollapseState::valid_one(const Candidate& c, std::uint32_t* blamed) const {
  const std::uint32_t a = c.a, b = c.b;
  std::uint32_t no_face = kNoFace;
  if (!blamed) blamed = &no_face;
  *blamed = kNoFace;
  if (!alive_[a] || !alive_[b] || locked_[a] || locked_[b]) return false;
  const int on_edge = faces_on_edge(a, b);
  if (on_edge < 1) return false;
  // The cheap checks first: the faces of the end that moves (often few, where the
  // other end is a hub of hundreds), then those over both ends' faces.
  if (complex_[a] || complex_[b]) return keeps_faces(c, blamed) && !doubles_a_face(a, b);
  if (on_edge > 2) return false;
  // An inner edge between two boundary vertices would pinch the surface into two.
  if (on_edge == 2 && boundary_[a] && boundary_[b]) return false;
  if (!keeps_faces(c, blamed)) return false;
  // The link condition: the vertices next to both a and b are exactly those opposite
  // the edge in its faces, so no edge or face is doubled. The opposite ones always are
  // next to both, so counting the common neighbours is enough.
  const LinkCounts link = link_counts(a, b);
  if (int(link.common) != on_edge) return false;
  // A tetrahedron has no edge left to collapse.
  return !(link.ring_a == 3 && link.ring_b == 3 && on_edge == 2);
}

// The neighbours of a and of b, each in a list of this thread's (no per-vertex marks,
// so that valid() may run on several threads at once), made distinct, and those they
// share counted.
CollapseState::LinkCounts CollapseState::link_counts(std::uint32_t a, std::uint32_t b) const {
  thread_local std::vector<std::uint32_t> around_a, around_b;
  const bool sorted_a = distinct_neighbours(a, &around_a), sorted_b = distinct_neighbours(b, &around_b);
  // Each without the other end (removing keeps a sorted list sorted).
  around_a.erase(std::remove(around_a.begin(), around_a.end(), b), around_a.end());
  around_b.erase(std::remove(around_b.begin(), around_b.end(), a), around_b.end());
  LinkCounts link;
  if (sorted_a && sorted_b) {
    std::size_t i = 0, j = 0;
    while (i < around_a.size() && j < around_b.size()) {
      if (around_a[i] < around_b[j]) {
        ++i;
      } else if (around_b[j] < around_a[i]) {
        ++j;
      } else {
        ++link.common, ++i, ++j;
      }
    }
  } else {
    // One list is short: each of its values looked for in the other.
    const std::vector<std::uint32_t>& few = sorted_a ? around_b : around_a;
    const std::vector<std::uint32_t>& many = sorted_a ? around_a : around_b;
    if (sorted_a || sorted_b) {
      for (const std::uint32_t u : few) link.common += std::binary_search(many.begin(), many.end(), u);
    } else {
      for (const std::uint32_t u : few)
        for (const std::uint32_t w : many) link.common += u == w;
    }
  }
  // a's ring holds b when an edge joins them; b's ring holds a, then its others.
  link.ring_a = around_a.size() + 1;
  link.ring_b = around_b.size() + 1;
  return link;
}

// Whether some face of b, moved to a, would have the corners of a face a has already.
bool CollapseState::doubles_a_face(std::uint32_t a, std::uint32_t b) const {
  bool doubled = false;
  for_each_face(b, [&](std::uint32_t f) {
    if (doubled) return;
    const std::uint32_t* t = &mesh_.triangles[3 * f];
    if (t[0] == a || t[1] == a || t[2] == a) return;  // removed
    std::uint32_t x = 0, y = 0;
    int n = 0;
    for (int k = 0; k < 3; ++k)
      if (t[k] != b) (n++ == 0 ? x : y) = t[k];
    for_each_face(a, [&](std::uint32_t g) {
      const std::uint32_t* s = &mesh_.triangles[3 * g];
      const bool has_x = s[0] == x || s[1] == x || s[2] == x;
      const bool has_y = s[0] == y || s[1] == y || s[2] == y;
      doubled = doubled || (has_x && has_y);
    });
  });
  return doubled;
}

bool CollapseState::keeps_face(const Candidate& c, std::uint32_t f) const {
  if (face_dead_[f]) return true;
  const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(f)];
  int moved = -1;
  for (int k = 0; k < 3; ++k)
    if (t[k] == c.a || t[k] == c.b) moved = moved < 0 ? k : 3;
  if (moved < 0 || moved == 3) return true;  // not around the edge, or removed
  Vec3d before[3], after[3];
  for (int k = 0; k < 3; ++k) after[k] = before[k] = mesh_.positions[t[k]];
  after[moved] = c.placement;
  if (same_point(after[moved], before[moved])) return true;  // it passed when it last changed
  const Vec3d n0 = cross(before[1] - before[0], before[2] - before[0]);
  const Vec3d n1 = cross(after[1] - after[0], after[2] - after[0]);
  const double nn0 = squared_length(n0), nn1 = squared_length(n1);
  // Against the face as it is and as it was in the input: many small turns of one
  // face, each allowed, must not add up to a flip of the surface it stands for.
  const Vec3d first = first_normal_[f].vec();
  if (!(nn1 > 0) || turned_too_far(n0, nn0, n1, nn1, cos_max_turn_) ||
      turned_too_far(first, squared_length(first), n1, nn1, cos_max_turn_))
    return false;
  // A needle: compactness c1 below the guard and below kNeedleSlack times c0, the
  // face's before (c = 2 sqrt(3) |n| / s, compared squared).
  const double s1 = sum_of_squared_sides(after[0], after[1], after[2]);
  if (!(12 * nn1 < min_compactness_ * min_compactness_ * s1 * s1)) return true;
  const double s0 = sum_of_squared_sides(before[0], before[1], before[2]);
  return !(nn1 * s0 * s0 < kNeedleSlack * kNeedleSlack * nn0 * s1 * s1);
}

// The faces that stay: none may flip or become a needle. Only the faces of an end
// that moves change; the first to fail is blamed.
bool CollapseState::keeps_faces(const Candidate& c, std::uint32_t* blamed) const {
  // The ends that move, the one with fewer faces first: a collapse that fails there
  // is told so before a hub's thousands are checked.
  const bool b_first = face_count_[c.b] < face_count_[c.a];
  std::uint32_t moving[2];
  int count = 0;
  for (const std::uint32_t end : {b_first ? c.b : c.a, b_first ? c.a : c.b})
    if (!same_point(mesh_.positions[end], c.placement)) moving[count++] = end;
  // Each face's corners and input normal are fetched before the first check: they are
  // scattered over the mesh's arrays, and the checks wait on them.
  for (int e = 0; e < count; ++e) {
    const std::uint32_t* p = faces_.data() + face_start_[moving[e]];
    for (std::uint32_t i = 0; i < face_count_[moving[e]]; ++i) {
      __builtin_prefetch(&mesh_.triangles[3 * std::size_t(p[i])]);
      __builtin_prefetch(&first_normal_[p[i]]);
    }
  }
  for (int e = 0; e < count; ++e) {
    const std::uint32_t end = moving[e];
    const std::uint32_t* p = faces_.data() + face_start_[end];
    for (std::uint32_t i = 0; i < face_count_[end]; ++i)
      if (!keeps_face(c, p[i])) {
        *blamed = p[i];
        return false;
      }
  }
  return true;
}

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
  for_each_face(a, [&](std::uint32_t f) {
    const std::uint32_t* tr = &mesh_.triangles[3 * f];
    if (tr[0] == b || tr[1] == b || tr[2] == b) {
      face_dead_[f] = 1;
      --live_faces_;
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
  face_start_[a] = std::uint32_t(faces_.size());
  face_count_[a] = std::uint32_t(merged.size());
  faces_.insert(faces_.end(), merged.begin(), merged.end());
  face_count_[b] = 0;
  alive_[b] = 0;
  mesh_.positions[a] = c.placement;
  mesh_.quadrics[a].add(mesh_.quadrics[b]);
  boundary_[a] = boundary_[a] | boundary_[b];  // a valid collapse neither makes nor closes a boundary
  hub_[a] = hub_[a] | (merged.size() > kStillHub);
  newly_anchored_.clear();
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
  if (faces_.size() > compact_at_) compact_adjacency();
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
    face_start_[v] = std::uint32_t(faces_.size());
    face_count_[v] = std::uint32_t(list.size());
    faces_.insert(faces_.end(), list.begin(), list.end());
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

// The merged lists are appended; once they take twice the start, the live ones are
// copied down.
void CollapseState::compact_adjacency() {
  std::vector<std::uint32_t> packed;
  reserve_huge(&packed, faces_.size() / 2);
  for (std::size_t v = 0; v < face_start_.size(); ++v) {
    const std::uint32_t start = std::uint32_t(packed.size());
    if (alive_[v]) for_each_face(std::uint32_t(v), [&](std::uint32_t f) { packed.push_back(f); });
    face_start_[v] = start;
    face_count_[v] = std::uint32_t(packed.size() - start);
  }
  faces_ = std::move(packed);
  compact_at_ = 2 * faces_.size() + 1024;
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

// --- The queue -------------------------------------------------------------------

namespace {

struct QueueEntry {
  double cost;
  std::uint32_t a, b;
};

// std::push_heap keeps the largest on top: "larger" is the later collapse, so the
// cheapest comes first, ties by the vertices (the same order for any thread count).
// A function object, so that the heap's sifting inlines it.
struct Later {
  bool operator()(const QueueEntry& x, const QueueEntry& y) const {
    if (x.cost != y.cost) return x.cost > y.cost;
    if (x.a != y.a) return x.a > y.a;
    return x.b > y.b;
  }
};
constexpr Later later{};

bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

// A min-heap with four children per node: the queue holds millions of entries, most
// of them stale, and a pop walks its depth; four 16-byte children share a cache line,
// so a level costs one miss where a binary heap's two levels cost two. The order is
// Later's, a strict total order, so the pops are those of any other heap.
class QuadHeap {
 public:
  bool empty() const { return items_.empty(); }
  void reserve(std::size_t n) { items_.reserve(n); }
  /// Takes `items` and orders them.
  void assign(std::vector<QueueEntry> items) {
    items_ = std::move(items);
    for (std::size_t i = items_.size(); i-- > 0;) sift_down(i);
  }
  void push(const QueueEntry& e) {
    std::size_t i = items_.size();
    items_.push_back(e);
    while (i > 0) {
      const std::size_t parent = (i - 1) / 4;
      if (!later(items_[parent], e)) break;
      items_[i] = items_[parent];
      i = parent;
    }
    items_[i] = e;
  }
  QueueEntry pop() {
    const QueueEntry top = items_.front();
    items_.front() = items_.back();
    items_.pop_back();
    if (!items_.empty()) sift_down(0);
    return top;
  }

 private:
  void sift_down(std::size_t i) {
    const QueueEntry e = items_[i];
    const std::size_t n = items_.size();
    for (;;) {
      const std::size_t first = 4 * i + 1;
      if (first >= n) break;
      std::size_t best = first;
      const std::size_t last = std::min(first + 4, n);
      for (std::size_t c = first + 1; c < last; ++c)
        if (later(items_[best], items_[c])) best = c;
      if (!later(e, items_[best])) break;
      items_[i] = items_[best];
      i = best;
    }
    items_[i] = e;
  }

  std::vector<QueueEntry> items_;
};

// The driver of one run: a heap of candidates, each checked against the state when
// taken. An entry is stale when the cost of its edge has changed since it was pushed
// (an end moved); a rejected edge is pushed again when a collapse changes its
// neighbourhood, so the collapse taken is always the cheapest valid one, as if every
// edge were re-evaluated after every collapse.
class LazyQueue {
 public:
  LazyQueue(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats, ProgressPhase* progress)
      : state_(state), settings_(settings), stats_(stats), progress_(progress), unblamed_(state.vertex_count()) {}

  void run() {
    fill();
    std::vector<QueueEntry> deferred;  // inner edges when one triangle is left to remove
    while (state_.triangle_count() > settings_.target_triangles) {
      if (heap_.empty()) {
        if (settings_.exact_count && !take_deferred(deferred)) stats_->stuck = true;
        return;
      }
      const QueueEntry e = heap_.pop();
      if (!state_.alive(e.a) || !state_.alive(e.b)) continue;
      const CollapseState::Candidate c = state_.evaluate(e.a, e.b);
      if (!same_bits(c.cost, e.cost)) continue;  // stale
      std::uint32_t blamed = CollapseState::kNoFace;
      if (!state_.valid(c, &blamed)) {
        reject(e.a, e.b, blamed);
        continue;
      }
      // A collapse removes its edge's faces: 2 inside, 1 on a boundary, more in a
      // tangle. One that would go below the target waits (a closed surface's count
      // is even: with one triangle to go only a boundary edge meets it).
      if (settings_.exact_count &&
          state_.triangle_count() - settings_.target_triangles < std::uint64_t(state_.faces_removed(c))) {
        deferred.push_back(e);
        continue;
      }
      if (!take(c)) return;
    }
  }

 private:
  // Every edge, its cost computed in parallel (each independent of the others).
  // Room is kept for the pushes of the collapses to come (about a dozen each, the
  // edges around the moved vertex), so the heap seldom regrows.
  void fill() {
    const auto edges = state_.edges();
    const std::uint64_t collapses =
        (state_.triangle_count() - std::min(state_.triangle_count(), settings_.target_triangles)) / 2;
    std::vector<QueueEntry> entries;
    reserve_huge(&entries, std::size_t(std::min<std::uint64_t>(4 * edges.size(), edges.size() + 12 * collapses)));
    entries.resize(edges.size());
    tbb::parallel_for(std::size_t(0), edges.size(), [&](std::size_t i) {
      const CollapseState::Candidate c = state_.evaluate(edges[i].first, edges[i].second);
      entries[i] = {c.cost, c.a, c.b};
    });
    heap_.assign(std::move(entries));
  }

  bool take(const CollapseState::Candidate& c) {
    const double error = state_.error(c);
    if (error > settings_.max_error || c.cost > settings_.max_cost) {
      stats_->stuck = stats_->stopped_by_error = true;
      return false;
    }
    CollapseState::Candidate other;
    const bool pair = state_.mirrored(c, &other);
    // The faces the collapse removes: edges blamed on them are looked at again.
    state_.edge_faces(c.a, c.b, &removed_);
    if (pair) {
      state_.edge_faces(other.a, other.b, &faces_);
      removed_.insert(removed_.end(), faces_.begin(), faces_.end());
    }
    state_.collapse(c);
    if ((++stats_->collapses & 0xFFF) == 0 && progress_) progress_->set(2 * stats_->collapses);
    stats_->largest_cost = std::max(stats_->largest_cost, c.cost);
    stats_->largest_error = std::max(stats_->largest_error, error);
    if (stats_->cost_log) stats_->cost_log->push_back(c.cost);
    requeue_around(c.a);
    if (pair) requeue_around(other.a);  // the other side of the seam moved too
    for (const std::uint32_t f : removed_) requeue_blamed(f);
    // An anchored vertex does not move: the costs of all its edges changed, and their
    // entries are stale.
    for (std::uint32_t v : state_.newly_anchored()) {
      state_.neighbours(v, &ring_);
      for (std::uint32_t u : ring_)
        if (u != c.a) push(v, u);
    }
    return true;
  }

  // With no valid collapse left that meets the target, the cheapest valid one that
  // goes below it, then boundary edges split in two until it is met; without a
  // boundary edge (a closed surface, whose count is even) one triangle below. False
  // when there is none.
  bool take_deferred(std::vector<QueueEntry>& deferred) {
    std::sort(deferred.begin(), deferred.end(), [](const QueueEntry& x, const QueueEntry& y) { return later(y, x); });
    const bool any_boundary = state_.has_boundary_edge();
    const QueueEntry* first = nullptr;
    for (const QueueEntry& e : deferred) {
      if (!state_.alive(e.a) || !state_.alive(e.b)) continue;
      const CollapseState::Candidate c = state_.evaluate(e.a, e.b);
      if (!same_bits(c.cost, e.cost) || !state_.valid(c)) continue;
      if (!first) first = &e;
      if (!state_.split_can_make_up(c, settings_.target_triangles, any_boundary)) continue;
      return take_and_split(c);
    }
    return first && take_and_split(state_.evaluate(first->a, first->b));
  }

  bool take_and_split(const CollapseState::Candidate& c) {
    if (!take(c)) return true;
    stats_->parity = !state_.split_up_to(settings_.target_triangles);
    return true;
  }

  // A rejected edge is remembered with the face blamed, the one that would flip or
  // become a needle: it is looked at again when that face changes (a corner moves, or
  // it goes), not at every change near its ends. Around a hub (a cone's apex, a fan
  // of thousands) that keeps each collapse's work to the faces it changed; looking at
  // every edge rejected at the hub after each collapse beside it made the collapse
  // quadratic in the hub's valence. An edge blamed on no face (the link condition, a
  // doubled face) is remembered at both ends and looked at again when the faces
  // around either end change. An edge whose end moves or is anchored is costed anew
  // anyway (requeue_around, take).
  void reject(std::uint32_t a, std::uint32_t b, std::uint32_t blamed) {
    if (blamed == CollapseState::kNoFace) {
      unblamed_[a].push_back(b);
      unblamed_[b].push_back(a);
    } else {
      blamed_on_.value(blamed_on_.insert(blamed)).push_back(std::uint64_t(a) << 32 | b);
    }
  }

  // a's quadric changed: its edges get new costs. Its faces moved, so the edges blamed
  // on them may be valid now; so may the edges blamed on no face around it.
  void requeue_around(std::uint32_t a) {
    state_.neighbours(a, &ring_);
    for (std::uint32_t u : ring_) push(a, u);
    for (std::uint32_t u : ring_) requeue_unblamed(u, a);
    requeue_unblamed(a, a);
    state_.live_faces(a, &faces_);
    for (const std::uint32_t f : faces_) requeue_blamed(f);
  }

  // Each edge blamed on face f goes back into the queue, once (an edge rejected from
  // several entries must not come back as many), unless f still fails: then it is
  // still invalid, and stays until f changes again. Dead edges are dropped.
  void requeue_blamed(std::uint32_t f) {
    const std::int64_t at = blamed_on_.find(f);
    if (at < 0) return;
    std::vector<std::uint64_t>& list = blamed_on_.value(std::size_t(at));
    sort_small(&list);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (i > 0 && list[i] == list[i - 1]) continue;
      const std::uint32_t a = std::uint32_t(list[i] >> 32), b = std::uint32_t(list[i]);
      if (!state_.alive(a) || !state_.alive(b)) continue;
      const CollapseState::Candidate c = state_.evaluate(a, b);
      if (!state_.keeps_face(c, f))
        list[kept++] = list[i];
      else
        heap_.push({c.cost, c.a, c.b});
    }
    list.resize(kept);
  }

  // Each edge blamed on no face at u goes back into the queue, once. Edges with a,
  // which requeue_around pushes anyway, and dead ones are dropped.
  void requeue_unblamed(std::uint32_t u, std::uint32_t a) {
    std::vector<std::uint32_t>& list = unblamed_[u];
    sort_small(&list);
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::uint32_t x = list[i];
      if ((i > 0 && x == list[i - 1]) || x == a || !state_.alive(x) || !state_.alive(u)) continue;
      const CollapseState::Candidate c = state_.evaluate(std::min(u, x), std::max(u, x));
      heap_.push({c.cost, c.a, c.b});
    }
    list.clear();
  }

  void push(std::uint32_t u, std::uint32_t v) {
    if (state_.locked(u) || state_.locked(v)) return;
    if (u > v) std::swap(u, v);
    const CollapseState::Candidate c = state_.evaluate(u, v);
    heap_.push({c.cost, u, v});
  }

  CollapseState& state_;
  const CollapseSettings& settings_;
  CollapseStats* stats_;
  ProgressPhase* progress_;
  QuadHeap heap_;
  // Per blamed face: its rejected edges, a << 32 | b.
  FlatHashMap<std::uint32_t, std::vector<std::uint64_t>> blamed_on_;
  std::vector<std::vector<std::uint32_t>> unblamed_;  // per vertex: the other ends of edges blamed on no face
  std::vector<std::uint32_t> ring_, faces_, removed_;
};

// Garland & Heckbert's greedy order taken in passes, as meshoptimizer's simplifier
// does: each pass costs every edge (in parallel; an edge whose ends the last pass did
// not touch keeps its cost), sorts them, and takes the cheapest valid collapses in
// that order, each vertex in at most one collapse a pass, so that every cost taken is
// still the edge's cost then (a collapse changes the quadric and position of its two
// ends only, and the anchoring of neighbours it leaves non-manifold, which count as
// moved too). A pass stops when it has halved the count still to remove; the lazy
// queue then finishes in strict order. Where the lazy queue re-costs and re-checks
// the neighbourhood of every collapse, one at a time, a pass re-costs each edge at
// most once and checks only the collapses it looks at, several at once ahead of
// taking them (work_ahead).
//
// A pass also stops before a collapse dearer than kPassCostSlack times the cost of the
// edge at which the passes would end, were the cheapest edges all valid and apart
// (meshoptimizer's error limit per pass, meshopt_simplify). Edges it skips because an
// end was taken this pass may be far cheaper than the ones further down its list, and
// without the limit it went on to those: on a block of boxes tessellated into thin
// triangles, thousands of valid collapses of no error waited for the next pass while
// a pass took ones that cut boxes' corners (at 12 triangles a box, RMS 0.3% and
// Hausdorff 4% of the diagonal, where the strict order has none). The limit leaves
// them to the next pass; a pass held back to a few collapses by it hands over to the
// lazy queue (kPassLeastShare).
class PassDriver {
 public:
  PassDriver(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats, ProgressPhase* progress)
      : state_(state), settings_(settings), stats_(stats), progress_(progress), touched_(state.vertex_count(), 0) {}

  /// Passes until at most `stop_at` triangles are left, a pass takes nothing, or a
  /// collapse above settings.max_error comes up.
  void run(std::uint64_t stop_at) {
    while (state_.triangle_count() > stop_at && !at_max_error_) {
      const std::uint64_t excess = state_.triangle_count() - stop_at;
      const std::uint64_t pass_to = excess <= stop_at / 8 ? stop_at : stop_at + excess / 2;
      const std::uint64_t asked = wanted(pass_to);
      if (pass(pass_to, stop_at) * kPassLeastShare < asked) break;
    }
  }

 private:
  // Each edge (a, b), a < b, that may collapse, with its cost, into the first entries
  // of entries_; returns their count. An edge neither of whose ends the last pass
  // touched keeps its entry: its cost depends only on its ends (their quadrics,
  // positions and anchoring), unless a seam ties it to the ends' mirrors, and the
  // edges between untouched vertices are the same (a face that went had both ends of
  // its collapse). The edges of the touched vertices are listed again, each once,
  // block by block in parallel, then costed into their place in parallel.
  std::size_t cost_edges() {
    constexpr std::uint32_t kBlock = 4096;
    const std::uint32_t n = std::uint32_t(state_.vertex_count());
    const std::uint32_t last = stamp_;  // before the first pass every vertex holds it
    const bool seams = state_.has_seams();
    const auto touched = [&](std::uint32_t v) { return seams || touched_[v] == last; };
    std::size_t kept = 0;
    for (std::size_t i = 0; i < costed_; ++i) {
      const QueueEntry& e = entries_[i];
      if (!touched(e.a) && !touched(e.b)) entries_[kept++] = e;
    }
    const std::uint32_t blocks = (n + kBlock - 1) / kBlock;
    std::vector<std::size_t> start(std::size_t(blocks) + 1, 0);
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> listed(blocks);
    tbb::parallel_for(std::uint32_t(0), blocks, [&](std::uint32_t block) {
      std::vector<std::uint32_t>& ring = rings_.local();
      std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges = listed[block];
      for (std::uint32_t v = block * kBlock; v < std::min(n, (block + 1) * kBlock); ++v) {
        if (!state_.alive(v) || state_.locked(v) || !touched(v)) continue;
        state_.distinct_neighbours(v, &ring);
        for (std::uint32_t u : ring) {
          if (state_.locked(u)) continue;
          if (!touched(u)) {
            edges.emplace_back(std::min(u, v), std::max(u, v));
          } else if (u > v) {  // both touched: listed from the lower end
            edges.emplace_back(v, u);
          }
        }
      }
      start[block + 1] = edges.size();
    });
    start[0] = kept;
    for (std::uint32_t block = 0; block < blocks; ++block) start[block + 1] += start[block];
    // entries_ only grows (the first pass has the most edges), so that it is not
    // filled with zeros again each pass before the costs overwrite them.
    if (entries_.size() < start[blocks]) {
      std::vector<QueueEntry> grown;
      reserve_huge(&grown, start[blocks]);
      grown.assign(entries_.begin(), entries_.begin() + std::ptrdiff_t(kept));
      grown.resize(start[blocks]);
      entries_ = std::move(grown);
    }
    tbb::parallel_for(std::uint32_t(0), blocks, [&](std::uint32_t block) {
      QueueEntry* out = entries_.data() + start[block];
      // The far ends' quadrics are fetched a few edges ahead: each far end's is a
      // miss of the caches on a large mesh.
      const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges = listed[block];
      const Quadric* quadrics = state_.mesh().quadrics.data();
      constexpr std::size_t kAhead = 8;
      for (std::size_t i = 0; i < edges.size(); ++i) {
        if (i + kAhead < edges.size()) {
          const char* q = reinterpret_cast<const char*>(quadrics + edges[i + kAhead].second);
          __builtin_prefetch(q);
          __builtin_prefetch(q + sizeof(Quadric) - 1);
        }
        *out++ = {state_.evaluate(edges[i].first, edges[i].second).cost, edges[i].first, edges[i].second};
      }
      std::vector<std::pair<std::uint32_t, std::uint32_t>>().swap(listed[block]);
    });
    costed_ = start[blocks];
    return costed_;
  }

  // The collapses that would take the count to pass_to, each removing two faces.
  std::uint64_t wanted(std::uint64_t pass_to) const { return (state_.triangle_count() - pass_to + 1) / 2; }

  // One pass down to pass_to, the passes ending at stop_at; returns the collapses taken.
  std::uint64_t pass(std::uint64_t pass_to, std::uint64_t stop_at) {
    const std::size_t edges = cost_edges();
    // Entries past a few times the collapses wanted would not be reached: only the
    // cheapest are sorted (their set, and so the order, does not depend on the threads).
    const std::size_t look = std::size_t(std::min<std::uint64_t>(edges, look_factor_ * wanted(pass_to) + 16));
    auto earlier = [](const QueueEntry& x, const QueueEntry& y) { return later(y, x); };
    QueueEntry* const first = entries_.data();
    if (look < edges) std::nth_element(first, first + look, first + edges, earlier);
    tbb::parallel_sort(first, first + look, earlier);
    // The cost limit: past the sorted entries the goal's cost is at least the last
    // one's, which then bounds none of them.
    const std::uint64_t goal = std::max<std::uint64_t>(1, (state_.triangle_count() - stop_at) / 2);
    const double limit = goal <= look ? kPassCostSlack * first[goal - 1].cost : HUGE_VAL;
    const std::uint32_t stamp = ++stamp_;
    std::uint64_t taken = 0;
    ahead_on_ = settings_.work_ahead && look >= kAheadLeast && !state_.has_seams() &&
                tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1 &&
                tbb::this_task_arena::max_concurrency() > 1;
    const std::size_t batch = ahead_on_ ? kAheadBatch : look;
    Step step = Step::next;
    for (std::size_t begin = 0; begin < look && step == Step::next; begin += batch) {
      const std::size_t end = std::min(look, begin + batch);
      if (ahead_on_) work_ahead(first + begin, first + end, stamp, limit);
      for (std::size_t i = begin; i < end && step == Step::next; ++i)
        step = take_entry(first[i], ahead_on_ ? &ahead_[i - begin] : nullptr, pass_to, limit, stamp, &taken);
    }
    const bool limited = step == Step::limited;
    stats_->collapses += taken;
    // Short of the pass's count, the cheapest edges were refused or shared a vertex:
    // the next pass looks further down the list; one that met it, or stopped at the
    // cost limit (further down is dearer still), less far.
    look_factor_ = state_.triangle_count() > pass_to && !limited ? std::min<std::uint64_t>(2 * look_factor_, 64)
                                                                 : std::max<std::uint64_t>(look_factor_ / 2, 2);
    if (progress_) progress_->set(2 * stats_->collapses);
    return taken;
  }

  enum class Step { next, stop, limited };

  // An entry's collapse as work_ahead() found it.
  struct Ahead {
    CollapseState::Candidate candidate;
    int faces_removed = 0;
    bool ready = false;  // worked out (else take_entry() works it out itself)
    bool valid = false;
  };

  // The walk of one entry of the sorted list: its collapse taken when both ends are
  // still untouched this pass, the collapse is valid, and it keeps to the target, the
  // cost limit and the error bounds. `known` (or null) is what work_ahead() found for
  // it; it is used when neither end is near a collapse taken since.
  Step take_entry(const QueueEntry& e, const Ahead* known, std::uint64_t pass_to, double limit, std::uint32_t stamp,
                  std::uint64_t* taken) {
    const std::uint64_t left = state_.triangle_count();
    if (left <= pass_to) return Step::stop;
    if (e.cost > limit) return Step::limited;
    if (touched_[e.a] == stamp || touched_[e.b] == stamp) return Step::next;
    if (known && !(known->ready && marks_[e.a] != moved_mark_ && marks_[e.b] != moved_mark_)) known = nullptr;
    if (known) ++stats_->worked_ahead;
    const CollapseState::Candidate c = known ? known->candidate : state_.evaluate(e.a, e.b);
    CollapseState::Candidate other;
    const bool pair = state_.mirrored(c, &other);
    if (pair && (touched_[other.a] == stamp || touched_[other.b] == stamp)) return Step::next;
    if (!(known ? known->valid : state_.valid(c))) return Step::next;
    // Never below an exact target (an edge may have many faces): the lazy queue
    // settles the last ones.
    const int removed = known ? known->faces_removed : state_.faces_removed(c);
    if (settings_.exact_count && left - settings_.target_triangles < std::uint64_t(removed)) return Step::next;
    // Skipped edges may be cheaper than this one now: whether the collapse stops at
    // max_error is for the lazy queue to say, in strict order of cost.
    const double error = state_.error(c);
    if (error > settings_.max_error || c.cost > settings_.max_cost) {
      at_max_error_ = true;
      return Step::stop;
    }
    // What the collapse changes, every vertex whose faces it touches, is marked: the
    // work done ahead for edges there is stale.
    if (ahead_on_)
      for (const std::uint32_t end : {c.a, c.b})
        state_.for_each_corner(end, [&](std::uint32_t u) { marks_[u] = moved_mark_; });
    state_.collapse(c);
    ++*taken;
    stats_->largest_cost = std::max(stats_->largest_cost, c.cost);
    stats_->largest_error = std::max(stats_->largest_error, error);
    if (stats_->cost_log) stats_->cost_log->push_back(c.cost);
    touched_[e.a] = touched_[e.b] = stamp;
    if (pair) touched_[other.a] = touched_[other.b] = stamp;
    for (std::uint32_t v : state_.newly_anchored()) touched_[v] = stamp;
    return Step::next;
  }

  // What take_entry() would work out for each entry of [begin, end), found on several
  // threads before any of them is taken: the candidate, whether it is valid and the
  // faces it removes. It depends only on the faces around the edge's ends, so it
  // holds at the entry's turn unless a collapse taken before then touched a face
  // there (take_entry() marks those vertices, and works such an entry out again).
  // Entries with an end already touched this pass, or shared with an earlier entry of
  // the batch (which is most likely taken, touching it), are left out.
  void work_ahead(const QueueEntry* begin, const QueueEntry* end, std::uint32_t stamp, double limit) {
    if (marks_.empty()) marks_.assign(state_.vertex_count(), 0);
    const std::size_t n = std::size_t(end - begin);
    ahead_.resize(n);
    ahead_todo_.clear();
    const std::uint32_t claimed = next_mark();
    for (std::size_t i = 0; i < n; ++i) {
      const QueueEntry& e = begin[i];
      ahead_[i].ready = false;
      if (e.cost > limit || touched_[e.a] == stamp || touched_[e.b] == stamp) continue;
      if (marks_[e.a] == claimed || marks_[e.b] == claimed) continue;
      marks_[e.a] = marks_[e.b] = claimed;
      ahead_todo_.push_back(std::uint32_t(i));
    }
    moved_mark_ = next_mark();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ahead_todo_.size(), 8),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t j = r.begin(); j != r.end(); ++j) {
                          const std::uint32_t i = ahead_todo_[j];
                          Ahead& k = ahead_[i];
                          k.candidate = state_.evaluate(begin[i].a, begin[i].b);
                          k.valid = state_.valid(k.candidate);
                          k.faces_removed = k.valid ? state_.faces_removed(k.candidate) : 0;
                          k.ready = true;
                        }
                      });
  }

  // A new value for marks_, none of whose entries holds it yet.
  std::uint32_t next_mark() {
    if (++mark_ == 0) {
      std::fill(marks_.begin(), marks_.end(), 0);
      mark_ = 1;
    }
    return mark_;
  }

  CollapseState& state_;
  const CollapseSettings& settings_;
  CollapseStats* stats_;
  ProgressPhase* progress_;
  std::vector<std::uint32_t> touched_;  // the pass that last moved or removed each vertex
  std::vector<QueueEntry> entries_;
  std::size_t costed_ = 0;  // the entries the last pass costed (in any order after it)
  tbb::enumerable_thread_specific<std::vector<std::uint32_t>> rings_;  // a thread's neighbour list
  std::uint32_t stamp_ = 0;
  // Per vertex: claimed by an entry worked out ahead in this batch, or (moved_mark_)
  // near a collapse taken since the batch was worked out.
  std::vector<std::uint32_t> marks_;  // allocated by the first work_ahead()
  std::uint32_t mark_ = 0, moved_mark_ = 0;
  bool ahead_on_ = false;     // this pass works its collapses out ahead
  std::vector<Ahead> ahead_;  // the batch's entries, worked out ahead
  std::vector<std::uint32_t> ahead_todo_;
  std::uint64_t look_factor_ = 2;  // entries sorted per collapse wanted
  bool at_max_error_ = false;
};

}  // namespace

void collapse_in_order(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                       ProgressPhase* progress) {
  LazyQueue(state, settings, stats, progress).run();
}

void collapse_state(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                    ProgressPhase* progress) {
  const std::uint64_t passes_to =
      std::max(settings.target_triangles, std::uint64_t(settings.pass_share * double(settings.target_triangles)));
  if (settings.pass_faces && state.triangle_count() >= settings.pass_faces && state.triangle_count() > passes_to)
    PassDriver(state, settings, stats, progress).run(passes_to);
  collapse_in_order(state, settings, stats, progress);
}

// Large meshes collapse in tiles first, in parallel, in rounds of at most 4x fewer
// faces (a tile's data stays in the caches, which the whole mesh's passes miss): the
// tiles' borders stay as they were in a round, and the next round's tiles, cut from
// the fewer faces, fall elsewhere. The whole mesh then collapses, in passes and in
// order of cost, from the tiles' result (the boundary planes already in its quadrics).
// Each coarser level goes on from the state the finer one left.
void collapse_edges_to_levels(QuadricMesh mesh, const CollapseSettings& settings,
                              const std::vector<std::uint64_t>& coarser, CollapseStats* stats,
                              const CollapseLevelSink& each, ProgressPhase* progress) {
  CollapseStats local;
  CollapseStats& st = stats ? *stats : local;
  CollapseState state(std::move(mesh), settings);
  st.non_manifold_vertices = state.non_manifold_count();
  const double tiles_to = double(settings.target_triangles) * settings.tile_share;
  while (settings.tile_faces && state.triangle_count() >= std::max(settings.tile_min_faces, 4 * settings.tile_faces) &&
         tiles_to < 0.75 * double(state.triangle_count())) {
    CollapseSettings round = settings;
    round.target_triangles = std::uint64_t(std::max(tiles_to, 0.25 * double(state.triangle_count())));
    round.tile_share = 1;
    const std::uint64_t before = state.triangle_count();
    QuadricMesh tiled = collapse_tiles(state, round, &st);
    if (progress) progress->set(2 * st.collapses);
    round.boundary_weight = 0;
    state = CollapseState(std::move(tiled), round);
    // A round that took less than a quarter of what it aimed at (the tiles' borders
    // hold most collapses, as around a hub every tile shares) would be followed by
    // others like it: the passes of the whole mesh go on instead.
    if (4 * (before - state.triangle_count()) < before - round.target_triangles) break;
  }
  CollapseSettings level = settings;
  for (std::size_t k = 0; k <= coarser.size(); ++k) {
    if (k > 0) {
      level.target_triangles = coarser[k - 1];
      st.stuck = st.stopped_by_error = st.parity = false;
      state.restore_needle_guard(level.min_compactness);
    }
    // A mesh already below an exact target (the out-of-core passes took the free
    // collapses of a flat mesh past it): edges split up to it, the surface unchanged.
    if (level.exact_count && state.triangle_count() < level.target_triangles &&
        !state.split_up_to(level.target_triangles))
      st.parity = st.stuck = state.triangle_count() + 1 == level.target_triangles;
    collapse_state(state, level, &st, progress);
    // Every collapse left would make a needle: on the generated sphere to a low target
    // the collapse jammed well short of it, every edge refused, most by the needle
    // guard. The count asked wins over the guard: the rest go without it.
    if (st.stuck && !st.stopped_by_error && !st.parity && level.exact_count &&
        state.triangle_count() > level.target_triangles && level.min_compactness > 0) {
      st.stuck = false;
      state.drop_needle_guard();
      collapse_in_order(state, level, &st, progress);
    }
    each(k, state.result(nullptr, !settings.result_quadrics), st);
  }
}

QuadricMesh collapse_edges(QuadricMesh mesh, const CollapseSettings& settings, CollapseStats* stats,
                           ProgressPhase* progress) {
  QuadricMesh out;
  collapse_edges_to_levels(
      std::move(mesh), settings, {}, stats,
      [&](std::size_t, QuadricMesh level, const CollapseStats&) { out = std::move(level); }, progress);
  return out;
}

}  // namespace oocsimp
