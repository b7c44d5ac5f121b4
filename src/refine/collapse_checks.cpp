#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "common/vec3_math.hpp"
#include "refine/collapse_state.hpp"
#include "refine/small_lists.hpp"

namespace oocsimp {

namespace {

// A face already below the needle guard may become at most this much thinner: with
// "no thinner at all" the lat-long poles of the generated sphere (needles already
// below the guard) froze, the collapse spent its count elsewhere and its error grew
// by orders of magnitude over the result without the freeze.
constexpr double kNeedleSlack = 0.5;

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

// Two doubles side by side (an SSE2 register): the quadric's error at two points at
// once. Each lane takes exactly the operations, in the order, of Quadric::error, so
// that the costs, and the collapses chosen by them, are those of the scalar code.
typedef double DoublePair __attribute__((vector_size(16)));

// The quadric error of q at points (x[0], y[0], z[0]) and (x[1], y[1], z[1]), and A
// times each point (ax, ay, az), lane by lane.
struct PairErrors {
  DoublePair error, ax, ay, az;
};
PairErrors pair_errors(const Quadric& q, DoublePair x, DoublePair y, DoublePair z) {
  PairErrors r;
  r.ax = q.a00 * x + q.a01 * y + q.a02 * z;
  r.ay = q.a01 * x + q.a11 * y + q.a12 * z;
  r.az = q.a02 * x + q.a12 * y + q.a22 * z;
  r.error = x * r.ax + y * r.ay + z * r.az - 2 * (q.b0 * x + q.b1 * y + q.b2 * z) + q.c;
  return r;
}

}  // namespace

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
  const Vec3d d = pb - pa;
  if (!anchored_a) {
    // Where A is well conditioned, Q is strictly convex and x = A^-1 b its minimum: no
    // end nor point of the edge costs less, so they need no cost of their own.
    Vec3d x;
    const Vec3d mid = (pa + pb) * 0.5;
    if (solve(q, &x) && squared_distance(x, mid) <= 4 * squared_length(d)) return {clean_cost(q.error(x)), a, b, x};
  }
  // The ends' errors side by side; A pa, the first lane's, serves the line's minimum.
  const PairErrors ends = pair_errors(q, DoublePair{pa.x, pb.x}, DoublePair{pa.y, pb.y}, DoublePair{pa.z, pb.z});
  Candidate best{ends.error[0], a, b, pa};
  if (ends.error[1] < best.cost) best.cost = ends.error[1], best.placement = pb;
  if (!anchored_a) {
    // The flat and linear cases, or a minimum far off the edge: the best point of the
    // edge, E(pa + t d) = E(pa) + 2 t (d.A pa - d.b) + t^2 d.A d.
    const double dad = dot(d, times(q, d));
    if (dad > 0) {
      const Vec3d a_pa{ends.ax[0], ends.ay[0], ends.az[0]};
      const double t = (dot(d, Vec3d{q.b0, q.b1, q.b2}) - dot(d, a_pa)) / dad;
      if (t > 0 && t < 1) {
        const Vec3d on_edge = pa + d * t;
        const double e = q.error(on_edge);
        if (e < best.cost) best.cost = e, best.placement = on_edge;
      }
    }
  }
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
  if (complex_[a] || complex_[b])
    return keeps_faces(c, blamed) && !doubles_a_face(a, b) && !joins_into_non_manifold_edge(a, b);
  if (on_edge > 2) return false;
  // An inner edge between two boundary vertices would pinch the surface into two.
  if (on_edge == 2 && boundary_[a] && boundary_[b]) return false;
  if (!keeps_faces(c, blamed)) return false;
  // The link condition: the vertices next to both a and b are exactly those opposite
  // the edge in its faces, so no edge or face is doubled. The opposite ones always are
  // next to both, so counting the common neighbours is enough. A hole of three edges
  // is the one exception: it closes (closes_hole).
  const LinkCounts link = link_counts(a, b);
  const bool closing = on_edge == 1 && link.common == 2 && closes_hole(a, b);
  if (int(link.common) != on_edge && !closing) return false;
  // A tetrahedron has no edge left to collapse (nor one with a hole for a face).
  return !(link.rings_of_three && (on_edge == 2 || closing));
}

// Dey et al. 1999 (Topology preserving edge contraction) check a surface with a
// boundary as if a dummy vertex capped each hole: the link condition then keeps every
// hole, and a surface with hundreds of small holes (a scan's) jams at about five
// triangles a hole, each shrunk to three edges. Closing such a hole is the collapse
// of (a, b) in the surface with the hole filled by one triangle (a, b, c): there the
// edge has two faces and the link condition holds when c and the edge's opposite
// corner are the only common neighbours (valid_one counts them). The filled triangle
// must face as the edge's face does, so that a disc whose outline has shrunk to three
// edges is not closed into a pillow.
bool CollapseState::closes_hole(std::uint32_t a, std::uint32_t b) const {
  std::uint32_t face = kNoFace;
  for_each_edge_face(a, b, [&](std::uint32_t f) { face = f; });
  if (face == kNoFace || touches_seam(a, b)) return false;
  const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(face)];
  const std::uint32_t x = t[0] ^ t[1] ^ t[2] ^ a ^ b;  // the corner opposite the edge
  thread_local std::vector<std::uint32_t> around;
  distinct_neighbours(a, &around);
  std::uint32_t hole = kNoFace;
  for (const std::uint32_t u : around)
    if (u != b && u != x && faces_on_edge(a, u) == 1 && faces_on_edge(b, u) == 1) hole = u;
  if (hole == kNoFace || mirror(hole) != kNoMirror) return false;
  // The face runs a -> b or b -> a; the filled triangle runs the other way.
  const bool forward = (t[0] == a && t[1] == b) || (t[1] == a && t[2] == b) || (t[2] == a && t[0] == b);
  const Vec3d& pa = mesh_.positions[a];
  const Vec3d& pb = mesh_.positions[b];
  const Vec3d& pc = mesh_.positions[hole];
  const Vec3d filled = forward ? cross(pa - pb, pc - pb) : cross(pb - pa, pc - pa);
  const Vec3d& p0 = mesh_.positions[t[0]];
  const Vec3d normal = cross(mesh_.positions[t[1]] - p0, mesh_.positions[t[2]] - p0);
  return dot(filled, normal) > 0;
}

// Around an anchored (non-manifold) vertex the link condition is not checked: merging
// b into a joins each edge (b, x) with (a, x), and two edges of at most two faces each
// must not become one of three or more. An edge that already had three or more may
// take more (it is no new non-manifold edge). Only a common neighbour x of a and b has
// both edges: the neighbours of the end with fewer faces are looked at, so that around
// a hub of a thousand faces each check costs what its other end's few faces do.
bool CollapseState::joins_into_non_manifold_edge(std::uint32_t a, std::uint32_t b) const {
  thread_local std::vector<std::uint32_t> around;
  distinct_neighbours(face_count_[a] < face_count_[b] ? a : b, &around);
  for (const std::uint32_t x : around) {
    if (x == a || x == b) continue;
    const int fa = faces_on_edge(a, x), fb = faces_on_edge(b, x);
    if (fa == 0 || fb == 0 || fa > 2 || fb > 2) continue;
    // The faces with a, b and x go with the edge (a, b).
    int shared = 0;
    for_each_edge_face(a, b, [&](std::uint32_t f) {
      const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(f)];
      shared += t[0] == x || t[1] == x || t[2] == x;
    });
    if (fa + fb - 2 * shared > 2) return true;
  }
  return false;
}

// The neighbours of a and of b, made distinct, and those they share counted: in small
// tables on the stack (no per-vertex marks, so that valid() may run on several threads
// at once). Around a hub (a long list) with a short other end, the short end's
// neighbours are each looked up at the hub by the faces on their edge with it, and the
// hub's own neighbours are listed only when the short end's ring is a tetrahedron's:
// listing and sorting them for each edge tried there made the collapse cubic in the
// hub's valence. Two hubs: sorted lists of this thread's.
CollapseState::LinkCounts CollapseState::link_counts(std::uint32_t a, std::uint32_t b) const {
  const auto scanned = [&](std::uint32_t v) { return 2 * std::size_t(face_count_[v]) <= kScannedList; };
  LinkCounts link;
  if (scanned(a) && scanned(b)) {
    SmallVertexSet ring_a, ring_b;
    std::size_t size_a = 1, size_b = 1;  // each ring holds the other end
    for_each_corner(a, [&](std::uint32_t u) {
      if (u != a && u != b) size_a += ring_a.insert(u);
    });
    for_each_corner(b, [&](std::uint32_t u) {
      if (u != a && u != b && ring_b.insert(u)) {
        ++size_b;
        link.common += ring_a.contains(u);
      }
    });
    link.rings_of_three = size_a == 3 && size_b == 3;
    return link;
  }
  const std::uint32_t few = face_count_[a] <= face_count_[b] ? a : b, hub = few == a ? b : a;
  if (scanned(few)) {
    SmallVertexSet ring;
    std::size_t few_size = 1;
    for_each_corner(few, [&](std::uint32_t u) {
      if (u != a && u != b && ring.insert(u)) {
        ++few_size;
        link.common += faces_on_edge(u, hub) > 0;
      }
    });
    if (few_size == 3) {
      thread_local std::vector<std::uint32_t> around;
      distinct_neighbours(hub, &around);
      const std::size_t hub_size = around.size() + (std::find(around.begin(), around.end(), few) == around.end());
      link.rings_of_three = hub_size == 3;
    }
    return link;
  }
  thread_local std::vector<std::uint32_t> around_a, around_b;
  const bool sorted_a = distinct_neighbours(a, &around_a), sorted_b = distinct_neighbours(b, &around_b);
  // Each without the other end (removing keeps a sorted list sorted).
  around_a.erase(std::remove(around_a.begin(), around_a.end(), b), around_a.end());
  around_b.erase(std::remove(around_b.begin(), around_b.end(), a), around_b.end());
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
    const std::vector<std::uint32_t>& shorter = sorted_a ? around_b : around_a;
    const std::vector<std::uint32_t>& longer = sorted_a ? around_a : around_b;
    if (sorted_a || sorted_b) {
      for (const std::uint32_t u : shorter) link.common += std::binary_search(longer.begin(), longer.end(), u);
    } else {
      for (const std::uint32_t u : shorter)
        for (const std::uint32_t w : longer) link.common += u == w;
    }
  }
  // a's ring holds b when an edge joins them; b's ring holds a, then its others.
  link.rings_of_three = around_a.size() + 1 == 3 && around_b.size() + 1 == 3;
  return link;
}

// Whether some face of b, moved to a, would have the corners of a face a has already:
// whether faces (a, x, y) and (b, x, y) both exist. That reads the same from either
// end, so the faces of the end with fewer are walked, and for each the faces on its
// edge (x, y) are looked at for the other end: around a hub, its few neighbours' faces
// rather than all of the hub's for each of theirs.
bool CollapseState::doubles_a_face(std::uint32_t a, std::uint32_t b) const {
  const std::uint32_t walked = face_count_[a] < face_count_[b] ? a : b, other = walked == a ? b : a;
  bool doubled = false;
  for_each_face(walked, [&](std::uint32_t f) {
    if (doubled) return;
    const std::uint32_t* t = &mesh_.triangles[3 * f];
    if (t[0] == other || t[1] == other || t[2] == other) return;  // removed
    std::uint32_t x = 0, y = 0;
    int n = 0;
    for (int k = 0; k < 3; ++k)
      if (t[k] != walked) (n++ == 0 ? x : y) = t[k];
    for_each_edge_face(x, y, [&](std::uint32_t g) {
      const std::uint32_t* s = &mesh_.triangles[3 * g];
      doubled = doubled || s[0] == other || s[1] == other || s[2] == other;
    });
  });
  return doubled;
}

bool CollapseState::keeps_face(const Candidate& c, std::uint32_t f) const {
  return face_dead_[f] || keeps_live_face(c, f);
}

// The face as it is and as the collapse would leave it, side by side (lane 0 before,
// lane 1 after; each lane the operations of cross() and squared_length() in their
// order): its normal, the normal's squared length and the sum s of its squared sides.
// Velho 1999 eq. 4: compactness 4 sqrt(3) a / (l1^2 + l2^2 + l3^2), with |n| = 2a, is
// 2 sqrt(3) |n| / s. The checks compare it without a square root: 12 |n|^2 / s^2 is
// its square.
namespace {
struct FaceBeforeAfter {
  DoublePair nx, ny, nz, nn, sides;
};
FaceBeforeAfter face_before_after(const Vec3d* corner[3], int moved, const Vec3d& placement) {
  DoublePair x[3], y[3], z[3];
  for (int k = 0; k < 3; ++k) {
    const Vec3d& q = k == moved ? placement : *corner[k];
    x[k] = DoublePair{corner[k]->x, q.x};
    y[k] = DoublePair{corner[k]->y, q.y};
    z[k] = DoublePair{corner[k]->z, q.z};
  }
  FaceBeforeAfter r;
  const DoublePair e1x = x[1] - x[0], e1y = y[1] - y[0], e1z = z[1] - z[0];
  const DoublePair e2x = x[2] - x[0], e2y = y[2] - y[0], e2z = z[2] - z[0];
  r.nx = e1y * e2z - e1z * e2y;
  r.ny = e1z * e2x - e1x * e2z;
  r.nz = e1x * e2y - e1y * e2x;
  r.nn = r.nx * r.nx + r.ny * r.ny + r.nz * r.nz;
  auto squared_side = [&](int i, int j) {
    const DoublePair dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
    return dx * dx + dy * dy + dz * dz;
  };
  r.sides = squared_side(0, 1) + squared_side(1, 2) + squared_side(2, 0);
  return r;
}
}  // namespace

bool CollapseState::keeps_live_face(const Candidate& c, std::uint32_t f) const {
  const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(f)];
  int moved = -1;
  for (int k = 0; k < 3; ++k)
    if (t[k] == c.a || t[k] == c.b) moved = moved < 0 ? k : 3;
  if (moved < 0 || moved == 3) return true;  // not around the edge, or removed
  const Vec3d* corner[3] = {&mesh_.positions[t[0]], &mesh_.positions[t[1]], &mesh_.positions[t[2]]};
  if (same_point(c.placement, *corner[moved])) return true;  // it passed when it last changed
  const FaceBeforeAfter face = face_before_after(corner, moved, c.placement);
  const Vec3d n0{face.nx[0], face.ny[0], face.nz[0]}, n1{face.nx[1], face.ny[1], face.nz[1]};
  const double nn0 = face.nn[0], nn1 = face.nn[1];
  // Against the face as it is and as it was in the input: many small turns of one
  // face, each allowed, must not add up to a flip of the surface it stands for.
  const Vec3d first = first_normal_[f].vec();
  if (!(nn1 > 0) || turned_too_far(n0, nn0, n1, nn1, cos_max_turn_) ||
      turned_too_far(first, squared_length(first), n1, nn1, cos_max_turn_))
    return false;
  // A needle: compactness c1 below the guard and below kNeedleSlack times c0, the
  // face's before (c = 2 sqrt(3) |n| / s, compared squared).
  const double s0 = face.sides[0], s1 = face.sides[1];
  if (!(12 * nn1 < min_compactness_ * min_compactness_ * s1 * s1)) return true;
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
  // Each face's corners and input normal are fetched before the first check: on a
  // large mesh they are scattered over arrays the caches do not hold, and the checks
  // wait on them. A small mesh (a tile, a scan) stays in the caches.
  constexpr std::size_t kCachedFaces = std::size_t(1) << 18;
  for (int e = 0; e < count && face_dead_.size() > kCachedFaces; ++e) {
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
      if (!face_dead_[p[i]] && !keeps_live_face(c, p[i])) {
        *blamed = p[i];
        return false;
      }
  }
  return true;
}

}  // namespace oocsimp
