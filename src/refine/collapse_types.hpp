// The plain data of the quadric edge collapse (refine/edge_collapse.hpp): the mesh it
// works on, with a quadric per vertex, its settings and its figures.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "cluster/quadric.hpp"
#include "oocsimp/geometry.hpp"

namespace oocsimp {

/// A face's unit normal in single precision (zero for a face of no area): the flip
/// check compares only its direction, and every face keeps one for the whole collapse.
struct UnitNormal {
  float x = 0, y = 0, z = 0;
  Vec3d vec() const { return {x, y, z}; }
};
UnitNormal unit_normal(const Vec3d& normal);

/// An indexed triangle mesh with a quadric per vertex: what phase 1 hands on (its
/// clusters' summed quadrics) or what face_quadrics() computes for a whole input.
/// Positions and quadrics are in one frame (phase 1's: relative to its grid origin).
struct QuadricMesh {
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;  ///< 3 per face
  std::vector<Quadric> quadrics;         ///< 1 per vertex
  std::size_t attribute_count = 0;       ///< values per vertex in `attributes`
  std::vector<double> attributes;        ///< attribute_count per vertex (interpolated along collapses)
  /// Each face's normal in the input, for the flip check (empty: from the positions).
  std::vector<UnitNormal> face_normals;
  /// Vertices that may neither move nor go (empty: none): a tile's border.
  std::vector<std::uint8_t> locked;
  /// Vertices not all of whose faces are here (empty: none): the other tiles' vertices
  /// in a tile of the out-of-core passes. A boundary loop through one is cut, and is
  /// held as an outline (CollapseState::add_boundary_planes).
  std::vector<std::uint8_t> partial;
};

/// What holding a mesh for the collapse takes, in bytes: per vertex its position,
/// quadric, flags, face list and attributes; per face its corners, input normal, face
/// list entries and a few queue entries.
inline std::uint64_t collapse_memory_bytes(std::uint64_t vertices, std::uint64_t triangles, std::size_t attributes) {
  constexpr std::uint64_t kPerVertex = sizeof(Vec3d) + sizeof(Quadric) + 16;
  constexpr std::uint64_t kPerTriangle = 12 + sizeof(UnitNormal) + 3 * 4 * 3 + 4 * 16;
  return vertices * (kPerVertex + sizeof(double) * attributes) + triangles * kPerTriangle;
}

/// The area-weighted plane quadrics of the faces around each vertex (Theoharis et al.
/// 2008 ch. 6: Q_v = sum of w_T Q_T, w_T the area): the start of --method qem.
std::vector<Quadric> face_quadrics(const std::vector<Vec3d>& positions, const std::vector<std::uint32_t>& triangles);

/// A boundary loop that the target leaves fewer edges than this around is a hole, not
/// outline (CollapseSettings::soften_holes): less than a hexagon, too coarse to show
/// its shape.
constexpr std::uint64_t kHoleEdges = 6;

/// The most edges of a loop that is a hole when a mesh of `faces` faces is collapsed to
/// `target`: the largest m with m^2 target < kHoleEdges^2 faces (0 for no target).
std::uint64_t most_hole_edges(std::uint64_t faces, std::uint64_t target);

struct CollapseSettings {
  /// Collapse until this many triangles are left (at least 4).
  std::uint64_t target_triangles = 4;
  /// Stop before a collapse whose error, the placement's root-mean-square distance
  /// to the planes of its quadric (sqrt(cost / area weight)), exceeds this (model units).
  double max_error = std::numeric_limits<double>::infinity();
  /// Stop before a collapse whose quadric cost exceeds this: the threshold of a pass
  /// of the out-of-core collapse, which thus takes in each tile what the strict order
  /// of cost would take in the whole mesh.
  double max_cost = std::numeric_limits<double>::infinity();
  /// A face around the collapse whose normal would turn by more than this is a flip.
  double max_normal_turn_degrees = 90;
  /// Velho's compactness 4 sqrt(3) a / (l1^2 + l2^2 + l3^2) (1 for an equilateral
  /// triangle, Velho 1999 eq. 4): a collapse may not leave a face below this unless the
  /// face was already worse.
  double min_compactness = 0.05;
  /// Weight of the constraint plane through each boundary edge, perpendicular to its
  /// face (Garland & Heckbert 1997 §6.1), per squared edge length: it keeps the outline
  /// of open scans and terrain. A hole too small for the target (see soften_holes) is
  /// held a thousand times less hard, about as hard as a face.
  double boundary_weight = 1000;
  /// Whether boundary loops too small for the target are holes rather than outline: a
  /// simple loop of m edges around which the target leaves fewer than kHoleEdges edges,
  /// at the density the target gives a mesh of hole_faces faces (m^2 hole_target <
  /// kHoleEdges^2 hole_faces; CollapseState::add_boundary_planes). Off where no count
  /// is asked (--max-error alone), whose target says nothing of the output's density.
  bool soften_holes = true;
  /// The face count and the target that size the holes (0: the mesh's own count and
  /// target_triangles). A tile of the out-of-core passes is given the input's count and
  /// the run's target, so that a hole is judged in it as in the whole mesh.
  std::uint64_t hole_faces = 0, hole_target = 0;
  /// Lock every vertex on a boundary edge (SimplifyOptions::lock_boundary). In a tile,
  /// a free vertex has all its faces there, so its boundary is the mesh's.
  bool lock_boundary = false;
  /// Input vertex ids (PassVertex::id, sorted) that are locked wherever they are
  /// (SimplifyOptions::locked_vertices), or null. A whole mesh numbered by input index
  /// is given QuadricMesh::locked instead.
  const std::vector<std::uint64_t>* locked_ids = nullptr;
  /// Keep texture seams (vertices split so that each side has its own coordinates)
  /// closed and unblended: two vertices that share a position, each on the boundary of
  /// its side, are mirrors, which collapse only together, along the seam, onto one of
  /// its vertices (CollapseState::mirrored); every other vertex that shares its
  /// position (where three charts meet, or a tangle) is locked.
  bool lock_coincident = false;
  /// Meet target_triangles exactly (collapses that overshoot wait; edges are split at
  /// the end to make up an overshoot). Off, the collapse stops at or below it, or when
  /// none is left.
  bool exact_count = true;
  /// Tiles of about this many faces collapse in parallel first (0: none); see
  /// collapse_tiles(). The tiles follow from the mesh alone, so the result is the same
  /// for any thread count.
  std::uint64_t tile_faces = 65536;
  /// Meshes of at least this many faces are cut into tiles: below it the passes alone
  /// are about as fast (README, "the collapse in passes").
  std::uint64_t tile_min_faces = std::uint64_t(1) << 22;
  /// The tiles collapse to this many times their share of the target; the collapse of
  /// the whole mesh, in passes and in order of cost, does the rest.
  double tile_share = 1.5;
  /// Meshes of at least this many faces collapse in passes first (0: never): every
  /// edge costed at once, in parallel, and the cheapest valid collapses taken, each
  /// vertex in at most one a pass and none much dearer than the edge at which the
  /// passes would end. The passes follow from the mesh alone, so the result is the
  /// same for any thread count.
  std::uint64_t pass_faces = 16384;
  /// The passes stop at this many times target_triangles; the lazy queue, in strict
  /// order of cost, takes the rest.
  double pass_share = 1.1;
  /// A pass works out the validity of its next collapses on several threads at once,
  /// then takes them in order (the same collapses as one thread takes). Off where
  /// tiles collapse side by side and already keep every thread busy.
  bool work_ahead = true;
  /// collapse_edges() returns the quadrics and input normals with the mesh (false: only
  /// its geometry and attributes, for an output).
  bool result_quadrics = true;
};

struct CollapseStats {
  std::uint64_t collapses = 0;
  double largest_cost = 0;                  ///< the largest quadric cost of a collapse taken (area x distance^2)
  double largest_error = 0;                 ///< the largest error (model units, see max_error) of a collapse taken
  std::uint64_t non_manifold_vertices = 0;  ///< on edges of 3+ faces or fans apart, at the start: anchored
  /// Pass entries taken on what PassDriver::work_ahead() found for them on other
  /// threads (the rest were worked out at their turn).
  std::uint64_t worked_ahead = 0;
  /// The target could not be met: no valid collapse was left (stuck), the next one was
  /// above max_error, or a closed surface, whose triangle count is even, was asked for an
  /// odd count (one triangle fewer is given). When every collapse left would overshoot,
  /// one is taken and edges split until the count is met (CollapseState::split_up_to).
  bool stuck = false;
  /// What was left when the collapse was stuck (not by max_error nor parity): the live
  /// edges, each counted under the first reason its collapse is not taken, and the
  /// boundary loops. Zero otherwise.
  struct StuckEdges {
    std::uint64_t edges = 0;
    std::uint64_t locked = 0;  ///< an end is locked (a tile's border, lock_boundary, locked_ids)
    std::uint64_t folds = 0;   ///< it would flip a face or leave a needle
    /// It would break the link condition, pinch the surface or make an edge of three faces.
    std::uint64_t topology = 0;
    std::uint64_t overshoot = 0;       ///< valid, but below the target by more than splits make up
    std::uint64_t loops = 0;           ///< boundary loops (pieces of edges of one face) left
    std::uint64_t loops_of_three = 0;  ///< of them, those of three edges
  } why_stuck;
  bool stopped_by_error = false;
  bool parity = false;
  /// When given, the cost of each collapse taken is appended, in the order taken:
  /// what a sample of the mesh says of the cost a count is reached at.
  std::vector<double>* cost_log = nullptr;
};

}  // namespace oocsimp
