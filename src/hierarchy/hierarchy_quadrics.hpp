// The quadrics of a 4-k hierarchy (Velho 1999 eq. 5, 7 and 9): where each vertex's
// starts, what removing a vertex into a neighbour costs, and how a removed vertex's
// quadric passes on. The builder uses them as it makes the records; extraction
// replays them over the records it applies, to place each vertex at the minimum of
// the quadric it holds there (vertex_placement.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "cluster/quadric.hpp"
#include "oocsimp/geometry.hpp"

namespace oocsimp {

/// Eq. 5: each vertex's quadric, the area-weighted planes of its faces (`corners`, 3
/// per face, every edge of at most two faces wound oppositely), plus the line of each
/// boundary edge (an edge whose reverse no face has; Garland & Heckbert 1997 §6.1)
/// weighted by `boundary_weight` per squared length, to both its ends.
std::vector<Quadric> finest_vertex_quadrics(const std::vector<Vec3d>& positions,
                                            const std::vector<std::uint32_t>& corners, double boundary_weight);

/// Eq. 7: C_u = (Q_v + Q_u)(p_u), the half-edge collapse of v into its neighbour u,
/// clamped at 0 (a quadric's error is never negative but for rounding).
double half_edge_collapse_cost(const Quadric& qv, const Quadric& qu, const Vec3d& pu);

/// The ring vertices a removal passes its quadric to: the ends of the new edge (the
/// diagonal, or the new boundary edge), or all three corners of the face a valence-3
/// removal leaves. `ring_count` ring vertices, counter-clockwise from the one the new
/// faces fan from; `closed` inside.
struct RemovalHeirs {
  int index[3] = {0, 0, 0};  ///< positions in the ring
  int count = 0;
};
RemovalHeirs removal_heirs(int ring_count, bool closed);

/// Eq. 9: Q_i += delta_i Q_v for each heir i, delta_i = (sum C - C_i) / ((n - 1) sum C)
/// (1 - C_i / (C_a + C_b) for two; even shares when every C is 0), `ring_cost[k]` the
/// C of ring vertex k.
void pass_on_quadric(std::vector<Quadric>* quadrics, std::uint32_t v, const std::uint32_t* ring,
                     const double* ring_cost, const RemovalHeirs& heirs);

}  // namespace oocsimp
