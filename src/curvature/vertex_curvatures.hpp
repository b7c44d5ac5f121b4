// The principal curvatures of every vertex of a mesh in memory, by integral invariants
// (curvature/integral_invariants.hpp) over the surface within the radius.
#pragma once

#include <cstdint>
#include <vector>

#include "curvature/integral_invariants.hpp"
#include "oocsimp/geometry.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

struct VertexCurvatureSettings {
  double radius = 0;  ///< of the ball or sphere (model units, > 0)
  CurvatureNeighbourhood neighbourhood = CurvatureNeighbourhood::ball;
  ProgressPhase* progress = nullptr;  ///< advanced by the vertices estimated (any thread), when given
};

/// How each vertex's curvatures were found.
struct VertexCurvatureCounts {
  std::uint64_t invariant = 0;  ///< by the integral invariants
  std::uint64_t fitted = 0;     ///< by the quadratic fit: the surface did not cover the disk
  std::uint64_t none = 0;       ///< neither (no face, no area, or too few neighbours): 0 and 0
};

/// k1 and k2 (k1 >= k2) of each vertex of the mesh (3 indices per triangle, wound
/// counter-clockwise seen from outside), in parallel; the same for any thread count.
/// The surface around a vertex is the faces reached from it through shared vertices
/// whose bounding spheres meet the ball: sheets that pass near it without joining
/// it (the other side of a thin plate) are not part of it.
VertexCurvatureCounts vertex_curvatures(const std::vector<Vec3d>& positions,
                                        const std::vector<std::uint32_t>& triangles,
                                        const VertexCurvatureSettings& settings, std::vector<float>* k1,
                                        std::vector<float>* k2);

/// The same for the vertices in `which` only: k1[i] and k2[i] (resized to
/// which.size()) for vertex which[i]. A vertex's values depend only on the faces
/// within the radius (and on the faces around their corners): a tile of the mesh that
/// holds them gives the values the whole mesh gives.
VertexCurvatureCounts vertex_curvatures_of(const std::vector<Vec3d>& positions,
                                           const std::vector<std::uint32_t>& triangles,
                                           const VertexCurvatureSettings& settings,
                                           const std::vector<std::uint32_t>& which, std::vector<float>* k1,
                                           std::vector<float>* k2);

}  // namespace oocsimp
