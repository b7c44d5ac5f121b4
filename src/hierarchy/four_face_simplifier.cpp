#include "hierarchy/four_face_simplifier.hpp"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "cluster/plane_quadric.hpp"
#include "common/triangle_geometry.hpp"
#include "common/vec3_math.hpp"
#include "hierarchy/hierarchy_quadrics.hpp"
#include "hierarchy/record_faces.hpp"

namespace oocsimp {

namespace {

constexpr double kNoCost = std::numeric_limits<double>::infinity();
// The queue is taken in batches of this many entries, their plans worked out ahead.
constexpr std::size_t kAheadBatch = 256;

Vec3d face_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c) { return cross(b - a, c - a); }

// The face of `faces` (3 corners each) with directed edge a->b, or -1.
int face_with(const std::uint32_t* faces, int count, std::uint32_t a, std::uint32_t b) {
  for (int i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k)
      if (faces[3 * i + k] == a && faces[3 * i + (k + 1) % 3] == b) return i;
  return -1;
}

}  // namespace

FourFaceSimplifier::FourFaceSimplifier(FourKMesh* mesh, const HierarchyOptions& options)
    : mesh_(*mesh), options_(options) {}

void FourFaceSimplifier::assign_quadrics(std::vector<Quadric> given) {
  const std::size_t n = mesh_.vertex_count();
  if (!given.empty()) {
    if (given.size() != n) throw std::logic_error("FourFaceSimplifier::assign_quadrics: a quadric per vertex");
    quadrics_ = std::move(given);
    return;
  }
  quadrics_ = finest_vertex_quadrics(mesh_.positions(), mesh_.face_corners(), options_.boundary_weight);
}

// Eq. 8: the swap of edge v-mid for prev-next costs the squared volume of the
// tetrahedron (v, mid, prev, next), which Velho reads as Q_s(t) for the plane of the
// face (v, mid, s) alone. Here it is that face's area-weighted plane quadric (eq. 5's
// units, those of C(v)) at the opposite corner, read from both faces and averaged:
// area times the squared height of the tetrahedron over it. The sums of every plane
// at s that Q_s holds measured how far t lies from s's other faces too: on CAD that
// priced a swap across a flat face like one across a bend (docs/hierarchy.md).
double FourFaceSimplifier::swap_cost(std::uint32_t v, std::uint32_t prev, std::uint32_t mid, std::uint32_t next) const {
  const Vec3d pv = mesh_.position(v), pp = mesh_.position(prev), pm = mesh_.position(mid), pn = mesh_.position(next);
  const TrianglePlane before = triangle_plane(pp - pv, pm - pv);  // face (v, prev, mid)
  const TrianglePlane after = triangle_plane(pm - pv, pn - pv);   // face (v, mid, next)
  return 0.5 * (plane_quadric_error(before, pv, pn) + plane_quadric_error(after, pv, pp));
}

// The new faces cover the outline the old ones did. Along each outline edge the new
// face may not turn by 90 degrees or more from the old face it meets there (a flip),
// nor lean from the old faces' area-weighted normal by more than they do (or 75
// degrees); across an edge between two new faces the crease may not be sharper than
// the sharpest between two old faces, or than 150 degrees.
bool FourFaceSimplifier::faces_fit(const std::uint32_t* old_faces, int old_count, const std::uint32_t* new_faces,
                                   int new_count, double* least_compactness) const {
  // Normals as cross products: a flip is a sign, and only the rarer checks need
  // lengths (this runs for every swap and removal considered).
  auto normal_of = [&](const std::uint32_t* t) {
    return face_normal(mesh_.position(t[0]), mesh_.position(t[1]), mesh_.position(t[2]));
  };
  auto compactness_of = [&](const std::uint32_t* t) {
    return metrics::compactness(mesh_.position(t[0]), mesh_.position(t[1]), mesh_.position(t[2]));
  };
  auto cosine = [](const Vec3d& a, const Vec3d& b) {
    return dot(a, b) / std::sqrt(squared_length(a) * squared_length(b));
  };
  Vec3d old_normal[4], new_normal[2], old_sum;
  for (int i = 0; i < old_count; ++i) {
    old_normal[i] = normal_of(old_faces + 3 * i);
    old_sum += old_normal[i];
  }
  // Nor may a new face lean from the surface it replaces (the old faces'
  // area-weighted normal) by more than 75 degrees and more than every old face
  // does: where the old faces along an outline already lean, the check by edge let
  // a face stand on its edge (three outline vertices of a height field in a row, at
  // a coarse level). Most new faces lean by less than 75 degrees: the old faces'
  // leans are worked out only for the others.
  const double old_sum_length2 = squared_length(old_sum);
  double lean_limit = 2;
  auto leans_too_far = [&](const Vec3d& normal) {
    const double d = dot(normal, old_sum);
    if (d > 0 && d * d >= kLeanCosine * kLeanCosine * squared_length(normal) * old_sum_length2) return false;
    if (lean_limit > 1) {
      lean_limit = kLeanCosine;
      for (int i = 0; i < old_count; ++i)
        if (squared_length(old_normal[i]) > 0) lean_limit = std::min(lean_limit, cosine(old_normal[i], old_sum));
    }
    return !(cosine(normal, old_sum) >= lean_limit);
  };
  double least = 1;
  for (int j = 0; j < new_count; ++j) {
    new_normal[j] = normal_of(new_faces + 3 * j);
    if (!(squared_length(new_normal[j]) > 0) || leans_too_far(new_normal[j])) return false;
    least = std::min(least, compactness_of(new_faces + 3 * j));
  }
  for (int j = 0; j < new_count; ++j)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = new_faces[3 * j + k], b = new_faces[3 * j + (k + 1) % 3];
      const int old = face_with(old_faces, old_count, a, b);
      if (old >= 0) {
        if (squared_length(old_normal[old]) > 0 && !(dot(new_normal[j], old_normal[old]) > 0)) return false;
        continue;
      }
      const int other = face_with(new_faces, new_count, b, a);
      if (other <= j) continue;
      const double crease = cosine(new_normal[j], new_normal[other]);
      if (crease >= kCreaseCosine) continue;
      double old_crease = 0;
      for (int i = 0; i < old_count; ++i)
        for (int e = 0; e < 3; ++e) {
          const int o = face_with(old_faces, old_count, old_faces[3 * i + (e + 1) % 3], old_faces[3 * i + e]);
          if (o > i && squared_length(old_normal[i]) > 0 && squared_length(old_normal[o]) > 0)
            old_crease = std::min(old_crease, cosine(old_normal[i], old_normal[o]));
        }
      if (!(crease >= old_crease)) return false;
    }
  if (least < kMinCompactness) {
    // A flat patch stays flat whatever its faces' shapes: the guard is for faces
    // that carry a bend, whose normals a needle would make unstable.
    bool flat = new_count > 0;
    for (int i = 0; i < old_count && flat; ++i) flat = cosine(old_normal[i], new_normal[0]) >= kFlat;
    for (int j = 1; j < new_count && flat; ++j) flat = cosine(new_normal[j], new_normal[0]) >= kFlat;
    double old_least = 1;
    for (int i = 0; i < old_count && !flat; ++i) old_least = std::min(old_least, compactness_of(old_faces + 3 * i));
    if (!flat && least < kNeedleSlack * old_least) return false;
  }
  *least_compactness = least;
  return true;
}

bool FourFaceSimplifier::plan_removal(std::uint32_t v, Plan* plan) const {
  thread_local FourKMesh::Fan fan;
  plan->neighbours.clear();
  if (!mesh_.fan(v, &fan)) return false;
  plan->neighbours.assign(fan.ring.begin(), fan.ring.end());
  int n = int(fan.ring.size());
  const bool closed = fan.closed;
  // Inside, 3 neighbours at least; on the boundary, an ear (one face) goes only where
  // its inner edge has a face beyond, so that no vertex is left without faces.
  if (closed ? n < 3 : n < 2) return false;
  if (!closed && n == 2 && mesh_.face_with_edge(fan.ring[1], fan.ring[0]) == HierarchyRecord::kNoFace) return false;
  std::vector<std::uint32_t>& ring = fan.ring;
  const int keep = closed ? std::min(n, 4) : std::min(n, 3);
  // An edge a planned swap makes joins two vertices next to each other on the ring
  // from then on, and no later swap or diagonal joins such a pair again: the mesh's
  // edges are all a check needs.
  auto edge_exists = [&](std::uint32_t a, std::uint32_t b) { return mesh_.has_edge(a, b); };

  // Swaps, the cheapest first, until v has `keep` neighbours. Each ring position's
  // swap is costed once; taking one changes only the two beside it. Whether the new
  // edge exists already is asked only of the cheapest (it seldom does).
  struct Swap {
    bool valid = false, edge_checked = false;
    double key = 0, cost = 0;
    double compactness = 0;  // the least of the two faces it makes
  };
  thread_local std::vector<Swap> swaps;
  // The cheaper key; at equal keys (every swap on a flat patch costs 0) the rounder
  // faces, then the lower vertex.
  auto goes_first = [&](int i, int j) {
    const Swap &a = swaps[std::size_t(i)], &b = swaps[std::size_t(j)];
    if (a.key != b.key) return a.key < b.key;
    if (a.compactness != b.compactness) return a.compactness > b.compactness;
    return ring[std::size_t(i)] < ring[std::size_t(j)];
  };
  auto ends_of = [&](int i, std::uint32_t* prev, std::uint32_t* next) {
    *prev = ring[std::size_t((i + n - 1) % n)];
    *next = ring[std::size_t((i + 1) % n)];
  };
  auto cost_swap = [&](int i) {
    Swap s;
    if (!closed && (i == 0 || i == n - 1)) return s;  // the chain's ends stay
    std::uint32_t prev, next;
    ends_of(i, &prev, &next);
    const std::uint32_t mid = ring[std::size_t(i)];
    if (prev == next) return s;
    const std::uint32_t old_faces[6] = {v, prev, mid, v, mid, next};
    const std::uint32_t new_faces[6] = {v, prev, next, prev, mid, next};
    double least = 0;
    if (!faces_fit(old_faces, 2, new_faces, 2, &least)) return s;
    s.valid = true;
    s.cost = swap_cost(v, prev, mid, next);
    s.key = s.cost * (2 - least);
    s.compactness = least;
    return s;
  };
  plan->swapped.clear();
  plan->swaps = 0;
  if (n > keep) {
    swaps.resize(std::size_t(n));
    for (int i = 0; i < n; ++i) swaps[std::size_t(i)] = cost_swap(i);
  }
  while (n > keep) {
    int best = -1;
    for (;;) {
      best = -1;
      for (int i = 0; i < n; ++i)
        if (swaps[std::size_t(i)].valid && (best < 0 || goes_first(i, best))) best = i;
      if (best < 0) return false;
      Swap& b = swaps[std::size_t(best)];
      if (b.edge_checked) break;
      b.edge_checked = true;
      std::uint32_t prev, next;
      ends_of(best, &prev, &next);
      if (!edge_exists(prev, next)) break;
      b.valid = false;
    }
    plan->swapped.push_back(ring[std::size_t(best)]);
    plan->swaps += swaps[std::size_t(best)].cost;
    ring.erase(ring.begin() + best);
    swaps.erase(swaps.begin() + best);
    --n;
    if (n <= keep) break;
    // The neighbours of the one taken, now at best - 1 and best.
    const int before = (best + n - 1) % n, after = best % n;
    swaps[std::size_t(before)] = cost_swap(before);
    swaps[std::size_t(after)] = cost_swap(after);
  }

  // The removal: the fan from ring[start] of lower C_a + C_b.
  double ring_cost[4];
  for (int i = 0; i < n; ++i) ring_cost[i] = collapse_cost(v, ring[i]);
  const int faces = closed ? n : n - 1;
  std::uint32_t old_faces[12];
  for (int i = 0; i < faces; ++i) {
    old_faces[3 * i] = v;
    old_faces[3 * i + 1] = ring[i];
    old_faces[3 * i + 2] = ring[(i + 1) % n];
  }
  int chosen = -1;
  double chosen_cost = kNoCost;
  const int starts = closed && n == 4 ? 2 : 1;
  for (int start = 0; start < starts; ++start) {
    const std::uint32_t r0 = ring[start], r1 = ring[(start + 1) % n], r2 = ring[(start + 2) % n];
    // The diagonal (or the face after a valence-3 removal) must be new.
    if (n >= 3 && (closed && n == 3 ? mesh_.has_face(r0, r1, r2) : edge_exists(r0, r2))) continue;
    std::uint32_t new_faces[6] = {r0, r1, r2, r0, r2, ring[(start + 3) % n]};
    double least = 0;
    if (!faces_fit(old_faces, faces, new_faces, n - 2, &least)) continue;
    // The removal is the half-edge collapse of v into either end of the new edge
    // (Velho §3): its cost is the cheaper of the two (of all three after a valence-3
    // removal, whose new face has them all).
    double cost = std::min(ring_cost[start], ring_cost[(start + 2) % n]);
    if (n == 2 || (closed && n == 3)) cost = *std::min_element(ring_cost, ring_cost + n);
    if (chosen < 0 || cost < chosen_cost) {
      chosen = start;
      chosen_cost = cost;
    }
  }
  if (chosen < 0) return false;
  plan->closed = closed;
  plan->ring_count = n;
  plan->removal = chosen_cost;
  for (int i = 0; i < n; ++i) {
    plan->ring[i] = ring[(chosen + i) % n];
    plan->ring_cost[i] = ring_cost[(chosen + i) % n];
  }
  plan->cost = options_.removal_weight * plan->removal + options_.swap_weight * plan->swaps;
  return std::isfinite(plan->cost);
}

// E(v) = alpha C(v) + beta S(v) with S(v) >= 0 and C(v) = (Q_v + Q_a)(p_a) for a
// diagonal's end a, which is one of v's neighbours now (swaps only take neighbours
// away): alpha times the least (Q_v + Q_u)(p_u) over v's neighbours u bounds E(v)
// from below when the set begins. A vertex that gains a neighbour during the set (an
// end of a swap that a later swap of the same removal takes out, unmarked; with
// --sequential, any ring vertex) can come to cost less than its key: it is then
// taken later than its cost says, not lost. Infinite for a vertex without faces.
double FourFaceSimplifier::least_cost(std::uint32_t v) const {
  // v's neighbours, each once: the far corner of each of its faces and, on the
  // boundary, the near corner of the face its fan begins with (no face ends there).
  const FourKMesh::Incidences faces = mesh_.around(v);
  double least = kNoCost;
  for (const FourKMesh::Incidence& f : faces) {
    least = std::min(least, collapse_cost(v, f.to));
    bool begins = true;
    for (const FourKMesh::Incidence& g : faces) begins = begins && g.to != f.from;
    if (begins) least = std::min(least, collapse_cost(v, f.from));
  }
  return least < kNoCost ? options_.removal_weight * least : kNoCost;
}

// C_u, eq. 7 (half_edge_collapse_cost).
double FourFaceSimplifier::collapse_cost(std::uint32_t v, std::uint32_t u) const {
  return half_edge_collapse_cost(quadrics_[v], quadrics_[u], mesh_.position(u));
}

// The removal of v by `plan` is taken: the records and face numbers it will use are
// reserved in order, and the vertices whose faces or quadrics it will change are
// stamped and marked now, for the walk's next decisions; the mesh changes in
// apply_taken(). The swaps and the removal change the faces of v and of every
// neighbour it had, and the quadrics of some: plans made before around them are
// stale. So a removal taken while others wait, whose plan is fresh, is apart from
// theirs: no vertex of its fan is in theirs, and they may be applied at once.
void FourFaceSimplifier::take(std::uint32_t v, const Plan& plan) {
  ++removals_;
  changed_[v] = removals_;
  for (const std::uint32_t u : plan.neighbours) changed_[u] = removals_;
  if (options_.independent)
    for (int i = 0; i < plan.ring_count; ++i) marked_[plan.ring[i]] = 1;
  if (taken_count_ == taken_.size()) taken_.emplace_back();
  Taken& t = taken_[taken_count_++];
  t.vertex = v;
  t.plan = plan;
  t.first_record = records_->size();
  records_->resize(records_->size() + plan.swapped.size() + 1);
  // Each swap makes 2 faces for its 2; the removal fewer than it replaces.
  const HierarchyRecord removal = plan.removal_record();
  const int made = record_new_face_count(removal);
  t.first_face = mesh_.add_face_numbers(2 * plan.swapped.size() + std::size_t(made));
  faces_after_taken_ -= std::uint64_t(removal.face_count - made);
}

// The removals taken since the last call, applied to the mesh: on several threads,
// since they are apart (take()), each writing its own records and faces.
void FourFaceSimplifier::apply_taken() {
  auto apply = [&](std::size_t i) {
    Taken& t = taken_[i];
    t.vertex_change = apply_removal(t.vertex, t.plan, t.first_face, &(*records_)[t.first_record]);
  };
  if (taken_count_ < 8) {
    for (std::size_t i = 0; i < taken_count_; ++i) apply(i);
  } else {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, taken_count_, 4),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) apply(i);
                      });
  }
  std::int64_t vertices = 0;
  for (std::size_t i = 0; i < taken_count_; ++i) vertices += taken_[i].vertex_change;
  mesh_.count_applied(std::int64_t(faces_after_taken_) - std::int64_t(mesh_.live_faces()), vertices);
  taken_count_ = 0;
  applied_at_ = removals_;
}

// Whether planning v would read what the removals taken and not yet applied change:
// the faces or quadric of v or of a neighbour (take() stamps them all).
bool FourFaceSimplifier::reads_taken(std::uint32_t v) const {
  if (taken_count_ == 0) return false;
  if (changed_[v] > applied_at_) return true;
  for (const FourKMesh::Incidence& f : mesh_.around(v))
    if (changed_[f.from] > applied_at_ || changed_[f.to] > applied_at_) return true;
  return false;
}

// The swaps, then the removal, each a record into `records` in turn, the faces they
// make numbered from first_face; then Q_v passed on (eq. 9). Returns the change in
// live vertices.
int FourFaceSimplifier::apply_removal(std::uint32_t v, const Plan& plan, std::uint32_t first_face,
                                      HierarchyRecord* records) {
  const float error = float(plan.cost);
  int vertices = 0;
  for (const std::uint32_t mid : plan.swapped) {
    HierarchyRecord swap;
    swap.swap = true;
    swap.vertex = v;
    swap.error = error;
    swap.face_count = 2;
    swap.faces[0] = mesh_.face_with_edge(mid, v);  // (v, prev, mid)
    swap.faces[1] = mesh_.face_with_edge(v, mid);  // (v, mid, next)
    vertices += mesh_.apply_numbered(swap, first_face);
    first_face += 2;
    *records++ = swap;
  }
  HierarchyRecord removal = plan.removal_record();
  removal.vertex = v;
  removal.error = error;
  for (int i = 0; i < removal.face_count; ++i) removal.faces[i] = mesh_.face_with_edge(v, plan.ring[i]);
  vertices += mesh_.apply_numbered(removal, first_face);
  *records = removal;

  pass_on_quadric(&quadrics_, v, plan.ring, plan.ring_cost, removal_heirs(plan.ring_count, plan.closed));
  return vertices;
}

// Step 1: every vertex ranked by a bound of its cost from below (least_cost), in
// parallel (each reads the mesh only). The walk plans a vertex when it comes out, and
// one whose cost is past the next in line goes back: a set ends long before the end of
// the queue, so most vertices are never planned in it.
void FourFaceSimplifier::rank_vertices() {
  const std::size_t n = mesh_.vertex_count();
  cost_.assign(n, kNoCost);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t v = range.begin(); v != range.end(); ++v)
      if (mesh_.vertex_alive(std::uint32_t(v))) cost_[v] = least_cost(std::uint32_t(v));
  });
  const Entry::Later later;
  order_.clear();
  for (std::uint32_t v = 0; v < n; ++v)
    if (cost_[v] < kNoCost) order_.push_back({cost_[v], v});
  tbb::parallel_sort(order_.begin(), order_.end(), [&](const Entry& a, const Entry& b) { return later(b, a); });
}

std::uint64_t FourFaceSimplifier::simplify_level(std::vector<HierarchyRecord>* records) {
  const std::size_t n = mesh_.vertex_count();
  marked_.assign(n, 0);
  rank_vertices();
  next_ = 0;
  returned_.clear();
  free_slots_.clear();
  for (std::size_t i = kept_.size(); i-- > 0;) free_slots_.push_back(std::uint32_t(i));
  removals_ = 0;
  changed_.assign(n, 0);
  ahead_on_ = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1 &&
              tbb::this_task_arena::max_concurrency() > 1;
  ahead_.clear();
  ahead_first_ = 0;
  if (ahead_on_ && claimed_.size() != n) claimed_.assign(n, claim_);

  // Steps 2-3: the cheapest unmarked vertex first. Each vertex is in the queue once;
  // its plan is made when it comes out (the removals around it since may have
  // changed it), and a cost past the next in line goes back (lazy updates).
  // A plan made earlier (ahead, or when its entry went back) is taken as it is where
  // nothing it read has changed since.
  // A removal is taken at once and applied with those taken after it, when the walk
  // next reads the mesh: before it plans a vertex itself, before it works plans out
  // ahead (next_entry()), and when the set ends.
  std::uint64_t removed = 0;
  Plan own;
  const double set_ratio = std::pow(options_.level_ratio, 1.0 / double(options_.sets_per_level));
  const std::uint64_t enough = std::uint64_t(set_ratio * double(mesh_.live_faces()));
  records_ = records;
  taken_count_ = 0;
  applied_at_ = 0;
  faces_after_taken_ = mesh_.live_faces();
  Entry e;
  const KnownPlan* known = nullptr;
  while (faces_after_taken_ > enough && next_entry(&e, &known)) {
    // An entry that went back frees its slot now; its plan there is read below, before
    // go_back() can take the slot again.
    if (e.slot != kNoSlot) free_slots_.push_back(e.slot);
    if (marked_[e.vertex] || !mesh_.vertex_alive(e.vertex)) continue;
    const Plan* plan = nullptr;
    if (known && is_fresh(e.vertex, *known)) {
      ++(e.slot != kNoSlot ? walk_stats_.kept : walk_stats_.made_ahead);
      if (known->ok) plan = &known->plan;
    } else {
      if (reads_taken(e.vertex)) apply_taken();
      if (plan_removal(e.vertex, &own)) plan = &own;
    }
    if (!plan) continue;
    if (plan->cost > e.cost && has_next() && Entry::Later{}({plan->cost, e.vertex}, next_in_line())) {
      go_back(e, *plan);
      continue;
    }
    take(e.vertex, *plan);
    ++removed;
  }
  apply_taken();
  records_ = nullptr;
  return removed;
}

// The next entry in the queue's order: the next sorted one, or the heap's top where
// an entry that went back is cheaper. `known` is its plan made earlier, or null.
bool FourFaceSimplifier::next_entry(Entry* entry, const KnownPlan** known) {
  const Entry::Later later;
  *known = nullptr;
  if (next_ < order_.size() && (returned_.empty() || later(returned_.front(), order_[next_]))) {
    if (ahead_on_) {
      if (next_ == ahead_first_ + ahead_.size()) {
        apply_taken();
        work_ahead();
      }
      const KnownPlan& k = ahead_[next_ - ahead_first_];
      if (k.ready) *known = &k;
    }
    *entry = order_[next_++];
    return true;
  }
  if (returned_.empty()) return false;
  std::pop_heap(returned_.begin(), returned_.end(), later);
  *entry = returned_.back();
  returned_.pop_back();
  *known = &kept_[entry->slot];
  return true;
}

const FourFaceSimplifier::Entry& FourFaceSimplifier::next_in_line() const {
  const Entry::Later later;
  if (next_ == order_.size()) return returned_.front();
  const Entry& sorted = order_[next_];
  return !returned_.empty() && later(sorted, returned_.front()) ? returned_.front() : sorted;
}

// The entry back into the queue at the plan's cost, the plan kept for its next turn.
// (The entry's own slot, if it had one, is free again and may be the one taken.)
void FourFaceSimplifier::go_back(const Entry& e, const Plan& plan) {
  std::uint32_t slot;
  if (!free_slots_.empty()) {
    slot = free_slots_.back();
    free_slots_.pop_back();
  } else {
    slot = std::uint32_t(kept_.size());
    kept_.emplace_back();
  }
  KnownPlan& k = kept_[slot];
  if (&k.plan != &plan) k.plan = plan;
  k.ok = k.ready = true;
  k.made_at = removals_;
  returned_.push_back({plan.cost, e.vertex, slot});
  std::push_heap(returned_.begin(), returned_.end(), Entry::Later{});
}

// The plans of the next kAheadBatch sorted entries, made on several threads before
// any is taken. An entry within two edges of an earlier one of the batch is left to
// the walk: the earlier is likely removed, which marks the later or makes its plan
// stale (cheap vertices come in runs of neighbours on flat patches, whose costs tie).
void FourFaceSimplifier::work_ahead() {
  ahead_first_ = next_;
  ahead_.resize(std::min(kAheadBatch, order_.size() - next_));
  auto vertex_of = [&](std::size_t i) { return order_[ahead_first_ + i].vertex; };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ahead_.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        KnownPlan& k = ahead_[i];
                        const std::uint32_t v = vertex_of(i);
                        k.ready = !marked_[v] && mesh_.vertex_alive(v);
                        k.plan.neighbours.clear();
                        if (k.ready)
                          for (const FourKMesh::Incidence& f : mesh_.around(v)) {
                            k.plan.neighbours.insert(k.plan.neighbours.end(), {f.from, f.to});
                            prefetch_neighbour(f.to);
                          }
                      }
                    });
  const std::uint32_t claim = next_claim();
  for (std::size_t i = 0; i < ahead_.size(); ++i) {
    KnownPlan& k = ahead_[i];
    if (!k.ready) continue;
    const std::uint32_t v = vertex_of(i);
    bool near = claimed_[v] == claim;
    for (std::size_t j = 0; j < k.plan.neighbours.size() && !near; ++j) near = claimed_[k.plan.neighbours[j]] == claim;
    k.ready = !near;
    if (near) continue;
    claimed_[v] = claim;
    for (const std::uint32_t u : k.plan.neighbours) claimed_[u] = claim;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ahead_.size(), 8),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        KnownPlan& k = ahead_[i];
                        if (!k.ready) continue;
                        k.ok = plan_removal(vertex_of(i), &k.plan);
                        k.made_at = removals_;
                      }
                    });
}

// What a plan reads of a ring vertex u (its position, quadric and faces), asked of
// memory before the batch is planned: a plan reads them in an order no prefetcher
// can guess, one cache miss after another, where these requests overlap.
void FourFaceSimplifier::prefetch_neighbour(std::uint32_t u) const {
  __builtin_prefetch(&mesh_.position(u));
  const char* quadric = reinterpret_cast<const char*>(&quadrics_[u]);
  __builtin_prefetch(quadric);
  __builtin_prefetch(quadric + sizeof(Quadric) - 1);
  mesh_.prefetch_faces(u);
}

// A new value for claimed_, none of whose entries holds it yet.
std::uint32_t FourFaceSimplifier::next_claim() {
  if (++claim_ == 0) {
    std::fill(claimed_.begin(), claimed_.end(), 0);
    claim_ = 1;
  }
  return claim_;
}

// Whether no removal since the plan was made changed what it read: the faces and
// quadrics of v and of its neighbours then. That holds because plan.neighbours is the
// whole fan ring (plan_removal copies it before the swaps edit the ring), and every
// vertex whose faces or quadric a removal changes is the removed vertex or one of its
// ring, which take() stamps.
bool FourFaceSimplifier::is_fresh(std::uint32_t v, const KnownPlan& known) const {
  if (changed_[v] > known.made_at) return false;
  for (const std::uint32_t u : known.plan.neighbours)
    if (changed_[u] > known.made_at) return false;
  return true;
}

}  // namespace oocsimp
