#include "hierarchy/vertex_placement.hpp"

#include <algorithm>
#include <cmath>

#include "common/coincident_runs.hpp"
#include "common/math_constants.hpp"
#include "common/triangle_geometry.hpp"
#include "common/vertex_faces.hpp"
#include "common/vec3_math.hpp"
#include "hierarchy/four_face_simplifier.hpp"
#include "hierarchy/hierarchy_quadrics.hpp"
#include "hierarchy/record_faces.hpp"

namespace oocsimp {

namespace {

Vec3d point(const std::vector<double>& xyz, std::uint32_t v) {
  return {xyz[3 * std::size_t(v)], xyz[3 * std::size_t(v) + 1], xyz[3 * std::size_t(v) + 2]};
}

// A face as extracted: its normal (a cross product) and compactness, what a move is
// held to.
struct FaceShape {
  Vec3d normal;
  double compactness = 0;
};

FaceShape shape_of(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  return {cross(b - a, c - a), metrics::compactness(a, b, c)};
}

// Whether the face, as it was extracted (`before`) and now (`now`), still keeps its
// area, its facing within kMaxTurnDegrees and its shape: compactness at least
// kMinCompactness or kNeedleSlack times its own, the builder's bounds for a new face.
// A face extracted with no area (a degenerate input face) has no facing to keep: its
// corners stay.
bool keeps_shape(const FaceShape& before, const FaceShape& now) {
  const double nn = squared_length(now.normal), bb = squared_length(before.normal);
  if (!(nn > 0) || !(bb > 0)) return false;
  const double cos_max = std::cos(kMaxTurnDegrees * kPi / 180);
  if (!(dot(now.normal, before.normal) >= cos_max * std::sqrt(nn * bb))) return false;
  return now.compactness >= FourFaceSimplifier::kMinCompactness ||
         now.compactness >= FourFaceSimplifier::kNeedleSlack * before.compactness;
}

double cosine(const Vec3d& a, const Vec3d& b) { return dot(a, b) / std::sqrt(squared_length(a) * squared_length(b)); }

// The vertices of the finest mesh whose position another vertex has too: the copies
// of a vertex split where several fans met (manifold_input), or the two sides of a
// texture seam. Moved apart, each to its own quadric's minimum, they would open a gap.
std::vector<std::uint8_t> coincident_vertices(const std::vector<double>& xyz) {
  const std::size_t n = xyz.size() / 3;
  std::vector<std::uint32_t> vertices(n);
  for (std::size_t v = 0; v < n; ++v) vertices[v] = std::uint32_t(v);
  std::vector<std::uint8_t> shared(n, 0);
  for_each_coincident_run(
      std::move(vertices), [&](std::uint32_t v) { return point(xyz, v); },
      [&](const std::uint32_t* group, std::size_t count) {
        for (std::size_t k = 0; k < count; ++k) shared[group[k]] = 1;
      });
  return shared;
}

// Where moving vertex v to x leaves its fan: every face keeps its shape (keeps_shape)
// and no crease between two of them, across an edge at v, becomes sharper than it was
// and than the builder allows a new one (FourFaceSimplifier::kCreaseCosine): two
// faces each turning by less than kMaxTurnDegrees could otherwise fold an edge.
class FanCheck {
 public:
  FanCheck(const VertexFaces& around, const std::vector<std::uint32_t>& corners,
           const std::vector<FaceShape>& extracted)
      : around_(around), corners_(corners), extracted_(extracted) {}

  bool fits(const std::vector<double>& xyz, std::uint32_t v, const Vec3d& x) {
    const std::uint32_t first = around_.start[v], count = around_.start[v + 1] - first;
    moved_.resize(count);
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t* t = corner_of(around_.faces[first + i]);
      Vec3d c[3];
      for (int k = 0; k < 3; ++k) c[k] = t[k] == v ? x : point(xyz, t[k]);
      moved_[i] = shape_of(c[0], c[1], c[2]);
      if (!keeps_shape(extracted_[around_.faces[first + i]], moved_[i])) return false;
    }
    for (std::uint32_t i = 0; i < count; ++i)
      for (std::uint32_t j = i + 1; j < count; ++j) {
        const std::uint32_t f = around_.faces[first + i], g = around_.faces[first + j];
        if (!share_an_edge_at(v, f, g)) continue;
        const double before = cosine(extracted_[f].normal, extracted_[g].normal);
        if (!(cosine(moved_[i].normal, moved_[j].normal) >= std::min(before, FourFaceSimplifier::kCreaseCosine)))
          return false;
      }
    return true;
  }

 private:
  const std::uint32_t* corner_of(std::uint32_t f) const { return &corners_[3 * std::size_t(f)]; }
  // Whether faces f and g, both around v, have a second corner in common: an edge at v.
  bool share_an_edge_at(std::uint32_t v, std::uint32_t f, std::uint32_t g) const {
    const std::uint32_t *a = corner_of(f), *b = corner_of(g);
    for (int k = 0; k < 3; ++k)
      if (a[k] != v && (a[k] == b[0] || a[k] == b[1] || a[k] == b[2])) return true;
    return false;
  }

  const VertexFaces& around_;
  const std::vector<std::uint32_t>& corners_;
  const std::vector<FaceShape>& extracted_;
  std::vector<FaceShape> moved_;  // the fan's faces with v moved
};

}  // namespace

std::vector<Quadric> held_quadrics(const MeshHierarchy& h, const std::vector<std::uint8_t>& applied,
                                   std::vector<std::uint8_t>* heir) {
  const std::size_t n = h.positions.size() / 3;
  std::vector<Vec3d> positions(n);
  for (std::size_t v = 0; v < n; ++v) positions[v] = point(h.positions, std::uint32_t(v));
  std::vector<Quadric> quadrics = finest_vertex_quadrics(positions, h.triangles, HierarchyOptions{}.boundary_weight);
  heir->assign(n, 0);
  const auto corners_of = [&](std::uint32_t f) { return &h.face_corners[3 * std::size_t(f)]; };
  for (std::size_t r = 0; r < h.records.size(); ++r) {
    const HierarchyRecord& record = h.records[r];
    std::uint32_t ring[5];
    int count = 0;
    bool closed = false;
    if (!applied[r] || !removal_ring(record, corners_of, ring, &count, &closed)) continue;
    const RemovalHeirs heirs = removal_heirs(count, closed);
    double ring_cost[5] = {0, 0, 0, 0, 0};
    for (int i = 0; i < heirs.count; ++i) {
      const std::uint32_t u = ring[heirs.index[i]];
      ring_cost[heirs.index[i]] = half_edge_collapse_cost(quadrics[record.vertex], quadrics[u], positions[u]);
      (*heir)[u] = 1;
    }
    pass_on_quadric(&quadrics, record.vertex, ring, ring_cost, heirs);
  }
  return quadrics;
}

void place_at_quadric_minima(const MeshHierarchy& h, const std::vector<std::uint8_t>& applied,
                             const std::vector<std::uint32_t>& source, const std::vector<std::uint8_t>& pinned,
                             SimplifiedMesh* mesh) {
  std::vector<std::uint8_t> heir;
  const std::vector<Quadric> quadrics = held_quadrics(h, applied, &heir);
  const std::vector<std::uint8_t> coincident = coincident_vertices(h.positions);
  std::vector<double>& xyz = mesh->positions;
  const std::vector<std::uint32_t>& corners = mesh->triangles;
  const VertexFaces around(source.size(), corners);
  std::vector<FaceShape> extracted(corners.size() / 3);
  for (std::size_t f = 0; f < extracted.size(); ++f)
    extracted[f] = shape_of(point(xyz, corners[3 * f]), point(xyz, corners[3 * f + 1]), point(xyz, corners[3 * f + 2]));
  FanCheck fan(around, corners, extracted);
  for (std::uint32_t v = 0; v < source.size(); ++v) {
    if (!heir[source[v]] || coincident[source[v]] || (!pinned.empty() && pinned[v])) continue;
    const Quadric& q = quadrics[source[v]];
    const Vec3d p = point(xyz, v);
    Box3d box;
    for (std::uint32_t i = around.start[v]; i < around.start[v + 1]; ++i)
      for (int k = 0; k < 3; ++k) box.add(point(xyz, corners[3 * std::size_t(around.faces[i]) + std::size_t(k)]));
    // The box of its neighbours, grown by its size each way: as far as an edge
    // collapse looks (two edge lengths from the edge's middle). The box itself held
    // the vertices of rough levels back from their minima (docs/hierarchy.md).
    const Vec3d size = box.max - box.min;
    const Vec3d x = minimize_quadric(q, p, box.min - size, box.max + size);
    if (!(q.error(x) < q.error(p)) || !fan.fits(xyz, v, x)) continue;
    xyz[3 * std::size_t(v)] = x.x;
    xyz[3 * std::size_t(v) + 1] = x.y;
    xyz[3 * std::size_t(v) + 2] = x.z;
  }
}

}  // namespace oocsimp
