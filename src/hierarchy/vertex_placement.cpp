#include "hierarchy/vertex_placement.hpp"

#include <algorithm>
#include <cmath>

#include "common/triangle_geometry.hpp"
#include "common/vec3_math.hpp"
#include "hierarchy/four_face_simplifier.hpp"
#include "hierarchy/hierarchy_quadrics.hpp"
#include "hierarchy/record_faces.hpp"

namespace oocsimp {

namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3d point(const std::vector<double>& xyz, std::uint32_t v) {
  return {xyz[3 * std::size_t(v)], xyz[3 * std::size_t(v) + 1], xyz[3 * std::size_t(v) + 2]};
}

// The faces around each vertex of a mesh (3 corners per face), as lists in one array.
struct VertexFaces {
  std::vector<std::uint32_t> start, faces;
  VertexFaces(std::size_t vertices, const std::vector<std::uint32_t>& corners) : start(vertices + 1, 0) {
    for (std::uint32_t v : corners) ++start[std::size_t(v) + 1];
    for (std::size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
    faces.resize(corners.size());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < corners.size(); ++i) faces[fill[corners[i]]++] = std::uint32_t(i / 3);
  }
};

// A face as extracted: its normal (a cross product) and compactness, what a move is
// held to.
struct FaceShape {
  Vec3d normal;
  double compactness = 0;
};

FaceShape shape_of(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  return {cross(b - a, c - a), metrics::compactness(a, b, c)};
}

// Whether the face, as it was extracted (`before`) and now (a, b, c), still keeps its
// area, its facing within kMaxTurnDegrees and the builder's needle guard.
bool keeps_shape(const FaceShape& before, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const FaceShape now = shape_of(a, b, c);
  const double nn = squared_length(now.normal), bb = squared_length(before.normal);
  if (!(nn > 0)) return false;
  const double cos_max = std::cos(kMaxTurnDegrees * kPi / 180);
  if (!(dot(now.normal, before.normal) >= cos_max * std::sqrt(nn * bb))) return false;
  return now.compactness >= FourFaceSimplifier::kMinCompactness ||
         now.compactness >= FourFaceSimplifier::kNeedleSlack * before.compactness;
}

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
  std::vector<double>& xyz = mesh->positions;
  const std::vector<std::uint32_t>& corners = mesh->triangles;
  const VertexFaces around(source.size(), corners);
  std::vector<FaceShape> extracted(corners.size() / 3);
  for (std::size_t f = 0; f < extracted.size(); ++f)
    extracted[f] = shape_of(point(xyz, corners[3 * f]), point(xyz, corners[3 * f + 1]), point(xyz, corners[3 * f + 2]));
  for (std::uint32_t v = 0; v < source.size(); ++v) {
    if (!heir[source[v]] || (!pinned.empty() && pinned[v])) continue;
    const Quadric& q = quadrics[source[v]];
    const Vec3d p = point(xyz, v);
    Box3d box;
    for (std::uint32_t i = around.start[v]; i < around.start[v + 1]; ++i)
      for (int k = 0; k < 3; ++k) box.add(point(xyz, corners[3 * std::size_t(around.faces[i]) + std::size_t(k)]));
    // The box of its neighbours, grown by its size each way: as far as an edge
    // collapse looks (two edge lengths from the edge's middle). Clamped to the
    // neighbours' box itself, the terrain's level 7 came out 1.27x the edge
    // collapse's RMS; grown, 1.16x (docs/hierarchy.md).
    const Vec3d size = box.max - box.min;
    const Vec3d x = minimize_quadric(q, p, box.min - size, box.max + size);
    if (!(q.error(x) < q.error(p))) continue;
    bool keeps = true;
    for (std::uint32_t i = around.start[v]; i < around.start[v + 1] && keeps; ++i) {
      const std::uint32_t f = around.faces[i];
      Vec3d c[3];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t u = corners[3 * std::size_t(f) + std::size_t(k)];
        c[k] = u == v ? x : point(xyz, u);
      }
      keeps = keeps_shape(extracted[f], c[0], c[1], c[2]);
    }
    if (!keeps) continue;
    xyz[3 * std::size_t(v)] = x.x;
    xyz[3 * std::size_t(v) + 1] = x.y;
    xyz[3 * std::size_t(v) + 2] = x.z;
  }
}

}  // namespace oocsimp
