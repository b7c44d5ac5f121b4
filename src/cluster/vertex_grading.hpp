// Vertex grading, Low & Tan 1997 §3.1.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "io/mesh_input.hpp"

namespace oocsimp {

/// A vertex with its position and its grading weight.
struct GradedVertex {
  std::uint64_t index = 0;  ///< input index: the stable key that breaks weight ties
  Vec3d p;
  double weight = 0;
};

/// The weight of a locked vertex (SimplifyOptions::locked_vertices): above every
/// graded one, so it is visited first and always becomes a centre, whose cell holds
/// only the points where it is (FloatingCellShape::holds). Graded weights are finite:
/// coordinates are within the float range (api/simplify.cpp, check_float_range), so
/// no edge length overflows a double.
constexpr double kLockedWeight = std::numeric_limits<double>::infinity();
inline bool is_locked(const GradedVertex& v) { return v.weight == kLockedWeight; }

/// Gives the vertices of `sorted` (in `precedes` order, floating_cells.hpp) whose
/// input index is in `locked` (sorted) kLockedWeight, keeping the order: the locked
/// ones (with any locked before) first, by index, then the others as they were.
void lock_graded(std::vector<GradedVertex>* sorted, const std::vector<std::uint64_t>& locked);

/// The weight of a vertex whose incident edges (from the vertex to its neighbours,
/// one per triangle side, duplicates allowed) are `edges`:
///   w = cos(theta / 2) * L
/// with theta the largest angle between two incident edges (Factor 1, the chance
/// that the vertex lies on a silhouette: cos(theta/2), §3.1) and L the longest
/// incident edge (Factor 2, the size of the faces it bounds). The product is the
/// expected size of the silhouette feature the vertex carries: it is scale-covariant
/// (scaling the model scales every weight alike, so the order, and hence the
/// clustering, does not change) and neither factor can swamp the other as 1/theta
/// could. Zero-length edges count for L but have no direction. No edges: 0.
double vertex_weight(const Vec3d* edges, std::size_t count);

/// Weights for the vertices `owned` (sorted input indices) from the triangles that
/// use them: `triangles` holds 3 input indices per triangle and must contain every
/// triangle with a corner in `owned` (it may hold others). Positions come from
/// `positions`. Returns one GradedVertex per owned vertex, in the order of `owned`.
std::vector<GradedVertex> grade_vertices(const std::vector<std::uint64_t>& owned, const std::uint64_t* triangles,
                                         std::size_t triangle_count, const PositionArray& positions);

/// A tile's triangles over tile-local vertex ids, for grade_local_vertices:
/// `corners` holds 3 local ids per triangle; local vertex i has input index
/// `index[i]` and position `positions[i]`.
struct LocalMesh {
  const std::uint32_t* corners = nullptr;
  std::size_t triangle_count = 0;
  const std::uint64_t* index = nullptr;
  const Vec3d* positions = nullptr;
  std::size_t vertex_count = 0;
};

/// grade_vertices over a LocalMesh: weights of the local vertices `owned` (local
/// ids), whose incident triangles must all be in `mesh`. Returns one GradedVertex
/// per owned vertex, in the order of `owned`. Positions are read once per local
/// vertex, edges are kept as neighbour ids (each neighbour once), so a tile's
/// working set stays in cache. With `boundary`, it also gets the input indices of
/// the owned vertices on the mesh's boundary (an edge of one face), ascending.
std::vector<GradedVertex> grade_local_vertices(const LocalMesh& mesh, const std::vector<std::uint32_t>& owned,
                                               std::vector<std::uint64_t>* boundary = nullptr);

}  // namespace oocsimp
