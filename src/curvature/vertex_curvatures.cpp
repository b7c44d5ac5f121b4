#include "curvature/vertex_curvatures.hpp"

#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "common/vec3_math.hpp"
#include "common/vertex_faces.hpp"

namespace oocsimp {

namespace {

// What the estimate reads of a face, the same for every vertex near it.
struct FaceShape {
  Vec3d centroid;
  double reach = 0;  // from the centroid to the farthest corner
  Vec3d normal;      // the cross product of the edges from the first corner
};
// The budgets count it: in_memory_bytes (mesh_curvatures.cpp) and tile_bytes_per_vertex.
static_assert(sizeof(FaceShape) == 56, "the curvature budgets count 56 bytes a face for its shape");

// p's tangent frame: unit vectors t1, t2 and the normal n, right-handed.
struct TangentFrame {
  Vec3d origin, t1, t2, n;
  Vec3d local(const Vec3d& q) const {
    const Vec3d d = q - origin;
    return {dot(d, t1), dot(d, t2), dot(d, n)};
  }
};

TangentFrame frame_at(const Vec3d& origin, const Vec3d& unit_normal) {
  // t1 along the coordinate axis least aligned with n, made perpendicular.
  const Vec3d& n = unit_normal;
  const Vec3d axis = std::fabs(n.x) <= std::fabs(n.y) && std::fabs(n.x) <= std::fabs(n.z) ? Vec3d{1, 0, 0}
                     : std::fabs(n.y) <= std::fabs(n.z)                                   ? Vec3d{0, 1, 0}
                                                                                          : Vec3d{0, 0, 1};
  const Vec3d t1 = axis - n * dot(axis, n);
  const Vec3d u1 = t1 / length(t1);
  return {origin, u1, cross(n, u1), n};
}

// What one thread works in: marks of the faces and vertices reached, by stamp, and
// each reached vertex's place in the queue.
struct Scratch {
  std::vector<std::uint32_t> face_mark, vertex_mark, vertex_slot;
  std::uint32_t stamp = 0;
  std::vector<std::uint32_t> queue, faces;
  std::vector<std::uint32_t> corner_slots;  // per face of `faces`, its corners' places in `queue`
  std::vector<Vec3d> local;                 // the queue's positions in p's frame
  std::vector<Vec3d> points;
  LocalHeightField heights;

  std::uint32_t next_stamp(std::size_t faces, std::size_t vertices) {
    if (face_mark.size() < faces) face_mark.assign(faces, 0);
    if (vertex_mark.size() < vertices) vertex_mark.assign(vertices, 0), vertex_slot.assign(vertices, 0);
    if (++stamp == 0) {
      std::fill(face_mark.begin(), face_mark.end(), 0);
      std::fill(vertex_mark.begin(), vertex_mark.end(), 0);
      stamp = 1;
    }
    return stamp;
  }
};

class VertexEstimator {
 public:
  VertexEstimator(const std::vector<Vec3d>& positions, const std::vector<std::uint32_t>& triangles,
                  const VertexCurvatureSettings& settings)
      : positions_(positions), triangles_(triangles), settings_(settings), around_(positions.size(), triangles) {
    find_outline();
    shape_faces();
  }

  enum class Outcome { invariant, fitted, none };

  Outcome estimate(std::uint32_t v, Scratch* s, PrincipalCurvatures* out) const {
    *out = {};
    // The normal of the surface within the radius (the faces' normals weighted by
    // area), not of v's own faces alone: on a rough scan a vertex's faces tilt at
    // random, and faces around it would face away from their normal.
    const Vec3d normal = gather(v, s);
    const Vec3d& p = positions_[v];
    const double r2 = settings_.radius * settings_.radius;
    const double normal_length = length(normal);
    if (!(normal_length > 0)) return Outcome::none;
    const TangentFrame frame = frame_at(p, normal / normal_length);
    const bool ball = settings_.neighbourhood == CurvatureNeighbourhood::ball;
    s->heights.reset(settings_.radius, ball ? LocalHeightField::Lines::of_the_ball : LocalHeightField::Lines::any);
    s->points.clear();
    // Each vertex reached is put in the frame once; the faces share their corners.
    s->local.resize(s->queue.size());
    for (std::size_t i = 0; i < s->queue.size(); ++i) s->local[i] = frame.local(positions_[s->queue[i]]);
    const std::uint32_t* slot = s->corner_slots.data();
    for (std::size_t i = 0; i < s->faces.size(); ++i, slot += 3)
      s->heights.add_triangle(s->local[slot[0]], s->local[slot[1]], s->local[slot[2]]);
    for (std::size_t i = 1; i < s->queue.size(); ++i)  // the queue's first is v
      if (squared_length(s->local[i]) <= r2) s->points.push_back(s->local[i]);
    bool closed = true;
    for (const std::uint32_t w : s->queue) closed = closed && !on_outline_[w];
    const bool found = ball ? ball_curvatures(s->heights, closed, out) : sphere_curvatures(s->heights, out);
    if (found) return Outcome::invariant;
    if (quadratic_fit_curvatures(s->points, out)) return Outcome::fitted;
    *out = {};
    return Outcome::none;
  }

 private:
  Vec3d corner(std::uint32_t f, int k) const { return positions_[triangles_[3 * std::size_t(f) + std::size_t(k)]]; }

  // The faces reached from v through shared vertices whose bounding spheres (about
  // the centroid) meet the ball of the height field's reach, into s->faces, and their
  // corners' places in the queue into s->corner_slots; the vertices reached, v first,
  // into s->queue. Returns the sum of the normals of the faces whose centroid is
  // within the radius.
  Vec3d gather(std::uint32_t v, Scratch* s) const {
    const Vec3d& p = positions_[v];
    const double reach_of_field = LocalHeightField::kHeightFieldReach * settings_.radius;
    const double r2 = settings_.radius * settings_.radius;
    const std::uint32_t stamp = s->next_stamp(triangles_.size() / 3, positions_.size());
    Vec3d normal{0, 0, 0};
    s->faces.clear();
    s->corner_slots.clear();
    s->queue.clear();
    s->queue.push_back(v);
    s->vertex_mark[v] = stamp;
    s->vertex_slot[v] = 0;
    for (std::size_t next = 0; next < s->queue.size(); ++next) {
      const std::uint32_t u = s->queue[next];
      for (std::uint32_t i = around_.start[u]; i < around_.start[u + 1]; ++i) {
        const std::uint32_t f = around_.faces[i];
        if (s->face_mark[f] == stamp) continue;
        s->face_mark[f] = stamp;
        const FaceShape& shape = shapes_[f];
        // (Written so that a face with a non-finite corner is left out.)
        const double d2 = squared_distance(shape.centroid, p), meets = reach_of_field + shape.reach;
        if (!(d2 <= meets * meets)) continue;
        s->faces.push_back(f);
        if (d2 <= r2) normal += shape.normal;
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t w = triangles_[3 * std::size_t(f) + std::size_t(k)];
          if (s->vertex_mark[w] != stamp) {
            s->vertex_mark[w] = stamp;
            s->vertex_slot[w] = std::uint32_t(s->queue.size());
            s->queue.push_back(w);
          }
          s->corner_slots.push_back(s->vertex_slot[w]);
        }
      }
    }
    return normal;
  }

  // Each face's centroid, reach (to its farthest corner) and normal (the cross product
  // of its edges from its first corner): the hundreds of vertices near a face each
  // read them, so they are worked out once.
  void shape_faces() {
    shapes_.resize(triangles_.size() / 3);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, shapes_.size(), 4096), [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t f = range.begin(); f != range.end(); ++f) {
            const Vec3d a = corner(std::uint32_t(f), 0), b = corner(std::uint32_t(f), 1),
                        c = corner(std::uint32_t(f), 2);
            FaceShape& shape = shapes_[f];
            shape.centroid = (a + b + c) * (1.0 / 3);
            shape.reach = std::sqrt(std::max({squared_distance(a, shape.centroid), squared_distance(b, shape.centroid),
                                              squared_distance(c, shape.centroid)}));
            shape.normal = cross(b - a, c - a);
          }
        });
  }

  // Each vertex on an edge of one face: where the surface has an outline, a line of
  // the height field that meets no triangle may be past it.
  void find_outline() {
    on_outline_.assign(positions_.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(positions_.size()), 4096),
                      [&](const tbb::blocked_range<std::uint32_t>& range) {
                        std::vector<std::uint32_t> ends;
                        for (std::uint32_t v = range.begin(); v != range.end(); ++v) {
                          ends.clear();
                          for (std::uint32_t i = around_.start[v]; i < around_.start[v + 1]; ++i)
                            for (int k = 0; k < 3; ++k) {
                              const std::uint32_t w = triangles_[3 * std::size_t(around_.faces[i]) + std::size_t(k)];
                              if (w != v) ends.push_back(w);
                            }
                          std::sort(ends.begin(), ends.end());
                          for (std::size_t i = 0; i < ends.size();) {
                            std::size_t j = i;
                            while (j < ends.size() && ends[j] == ends[i]) ++j;
                            if (j - i == 1) on_outline_[v] = 1;
                            i = j;
                          }
                        }
                      });
  }

  const std::vector<Vec3d>& positions_;
  const std::vector<std::uint32_t>& triangles_;
  const VertexCurvatureSettings& settings_;
  VertexFaces around_;
  std::vector<std::uint8_t> on_outline_;
  std::vector<FaceShape> shapes_;
};

}  // namespace

namespace {

// Estimates vertex vertex_of(i) for i in [0, count), handing each result to
// store(i, k); counts the outcomes and advances `progress` (when given) by each.
template <class VertexOf, class Store>
VertexCurvatureCounts estimate_each(const VertexEstimator& estimator, std::size_t count, const VertexOf& vertex_of,
                                    const Store& store, ProgressPhase* progress) {
  tbb::enumerable_thread_specific<Scratch> scratch;
  tbb::combinable<VertexCurvatureCounts> counts;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1024), [&](const tbb::blocked_range<std::size_t>& range) {
    Scratch& s = scratch.local();
    VertexCurvatureCounts& c = counts.local();
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      PrincipalCurvatures k;
      switch (estimator.estimate(vertex_of(i), &s, &k)) {
        case VertexEstimator::Outcome::invariant:
          ++c.invariant;
          break;
        case VertexEstimator::Outcome::fitted:
          ++c.fitted;
          break;
        case VertexEstimator::Outcome::none:
          ++c.none;
          break;
      }
      store(i, k);
    }
    if (progress) progress->advance(range.size());
  });
  VertexCurvatureCounts total;
  counts.combine_each([&](const VertexCurvatureCounts& c) {
    total.invariant += c.invariant;
    total.fitted += c.fitted;
    total.none += c.none;
  });
  return total;
}

}  // namespace

VertexCurvatureCounts vertex_curvatures(const std::vector<Vec3d>& positions,
                                        const std::vector<std::uint32_t>& triangles,
                                        const VertexCurvatureSettings& settings, std::vector<float>* k1,
                                        std::vector<float>* k2) {
  const VertexEstimator estimator(positions, triangles, settings);
  k1->assign(positions.size(), 0);
  k2->assign(positions.size(), 0);
  return estimate_each(
      estimator, positions.size(), [](std::size_t i) { return std::uint32_t(i); },
      [&](std::size_t i, const PrincipalCurvatures& k) {
        (*k1)[i] = float(k.k1);
        (*k2)[i] = float(k.k2);
      },
      settings.progress);
}

VertexCurvatureCounts vertex_curvatures_of(const std::vector<Vec3d>& positions,
                                           const std::vector<std::uint32_t>& triangles,
                                           const VertexCurvatureSettings& settings,
                                           const std::vector<std::uint32_t>& which, std::vector<float>* k1,
                                           std::vector<float>* k2) {
  const VertexEstimator estimator(positions, triangles, settings);
  k1->assign(which.size(), 0);
  k2->assign(which.size(), 0);
  return estimate_each(
      estimator, which.size(), [&](std::size_t i) { return which[i]; },
      [&](std::size_t i, const PrincipalCurvatures& k) {
        (*k1)[i] = float(k.k1);
        (*k2)[i] = float(k.k2);
      },
      settings.progress);
}

}  // namespace oocsimp
