// Quadric edge collapse in core (Garland & Heckbert 1997; Theoharis et al. 2008,
// "Graphics & Visualization: Principles and Algorithms", ch. 6 ("Model Representation
// and Simplification"), section "Simplification using Iterative Edge Collapses"
// (2)-(6)): the second phase of multiphase simplification (Garland & Shaffer 2002),
// and the whole of --method qem.
//
// The state of the mesh being collapsed (CollapseState) is separate from the order
// the collapses are taken in, so that a test can drive the same state with a naive
// queue and compare. collapse_edges() takes them in parallel tiles (large meshes), then
// in passes (each vertex in one collapse a pass, the cheapest first), then from a
// priority queue with lazy updates in strict order of cost.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "cluster/quadric.hpp"
#include "oocsimp/geometry.hpp"

namespace oocsimp {

class ProgressPhase;

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
  /// of open scans and terrain.
  double boundary_weight = 1000;
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
  bool stopped_by_error = false;
  bool parity = false;
  /// When given, the cost of each collapse taken is appended, in the order taken:
  /// what a sample of the mesh says of the cost a count is reached at.
  std::vector<double>* cost_log = nullptr;
};

/// The mesh being collapsed: faces around each vertex, quadrics, locks.
class CollapseState {
 public:
  /// A collapse of edge (a, b), a < b: b goes into a, which moves to `placement`.
  struct Candidate {
    double cost = 0;
    std::uint32_t a = 0, b = 0;
    Vec3d placement;
  };

  CollapseState(QuadricMesh mesh, const CollapseSettings& settings);

  /// Every edge (a, b), a < b, of the live faces, once each, in order, whose
  /// vertices may move.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges() const;
  /// The quadric cost and the placement of collapsing (a, b).
  Candidate evaluate(std::uint32_t a, std::uint32_t b) const;
  /// No face: what valid() blames when a check other than a face's failed.
  static constexpr std::uint32_t kNoFace = ~std::uint32_t(0);
  /// Whether the collapse keeps the surface manifold (the link condition), flips no
  /// face and leaves no needle. Any thread (its scratch lists are each thread's).
  /// When invalid, `blamed` (if given) gets the face that would flip or become a
  /// needle, or kNoFace: while keeps_face() fails on it the collapse stays invalid.
  bool valid(const Candidate& c, std::uint32_t* blamed = nullptr) const;
  /// Whether face f, moved by the collapse, neither flips nor becomes a needle. A
  /// dead face, one the collapse removes and one that does not move pass.
  bool keeps_face(const Candidate& c, std::uint32_t f) const;
  /// The faces the collapse removes: 2 inside, 1 on a boundary.
  int faces_on_edge(std::uint32_t a, std::uint32_t b) const;
  /// No mirror: what mirror() says of a vertex that is on no seam.
  static constexpr std::uint32_t kNoMirror = ~std::uint32_t(0);
  /// The vertex on the other side of a texture seam at v's position, or kNoMirror
  /// (CollapseSettings::lock_coincident).
  std::uint32_t mirror(std::uint32_t v) const { return mirror_.empty() ? kNoMirror : mirror_[v]; }
  /// Whether any vertex has a mirror (CollapseSettings::lock_coincident found a seam).
  bool has_seams() const { return !mirror_.empty(); }
  /// Whether `c` collapses a seam edge, both of whose ends have mirrors: then the
  /// mirrors' edge collapses with it, to the same placement, and *other gets that
  /// collapse.
  bool mirrored(const Candidate& c, Candidate* other) const;
  /// The faces collapse `c` removes, its mirror's included.
  int faces_removed(const Candidate& c) const;
  /// The live faces on edge (a, b) into *out.
  void edge_faces(std::uint32_t a, std::uint32_t b, std::vector<std::uint32_t>* out) const;
  /// The live faces around v into *out.
  void live_faces(std::uint32_t v, std::vector<std::uint32_t>* out) const;
  /// The error of `c` in model units (see CollapseSettings::max_error).
  double error(const Candidate& c) const;
  /// Collapses b into a (and the mirrors' edge, when mirrored()).
  void collapse(const Candidate& c);
  /// The vertices other than c.a whose edges the last collapse changed, all of whose
  /// edges cost anew: neighbours it left non-manifold (now anchored), and the mirror
  /// collapse's survivor.
  const std::vector<std::uint32_t>& newly_anchored() const { return newly_anchored_; }
  /// Splits the longest edge of `faces` faces (ties: the lowest vertices) at its
  /// midpoint, each of its faces into two: `faces` triangles more and the surface
  /// unchanged. False when the mesh has no such edge.
  bool split_longest_edge(int faces);
  /// Whether an edge of one face is left.
  bool has_boundary_edge() const { return longest_edge(1, nullptr); }
  /// For a target that a collapse overshot: splits edges until `target` triangles are
  /// left, one of one face for an odd number to add, else one of two faces (or of
  /// one). False when it cannot be met: an odd number to add and no edge of one face.
  bool split_up_to(std::uint64_t target);
  /// Whether split_up_to() could make up what collapse `c` would take below `target`:
  /// an even number of triangles, or `boundary` (an edge of one face is left).
  bool split_can_make_up(const Candidate& c, std::uint64_t target, bool boundary) const {
    const std::uint64_t after = live_faces_ - std::uint64_t(faces_removed(c));
    return after >= target || boundary || (target - after) % 2 == 0;
  }

  std::size_t vertex_count() const { return alive_.size(); }
  bool alive(std::uint32_t v) const { return alive_[v] != 0; }
  bool non_manifold(std::uint32_t v) const { return complex_[v] != 0; }
  std::uint64_t triangle_count() const { return live_faces_; }
  std::uint64_t non_manifold_count() const;
  bool locked(std::uint32_t v) const { return locked_[v] != 0; }
  /// Drops the needle guard (CollapseSettings::min_compactness) from here on.
  void drop_needle_guard() { min_compactness_ = 0; }
  /// Sets the needle guard again (after drop_needle_guard, for another target).
  void restore_needle_guard(double min_compactness) { min_compactness_ = min_compactness; }
  /// The mesh as it is (faces dead or alive), with the boundary planes in its quadrics.
  const QuadricMesh& mesh() const { return mesh_; }
  bool face_alive(std::uint32_t f) const { return face_dead_[f] == 0; }
  /// The distinct vertices sharing a live face with v, ascending. Any thread.
  void neighbours(std::uint32_t v, std::vector<std::uint32_t>* out) const;
  /// The distinct vertices sharing a live face with v, in no set order (ascending when
  /// it returns true: a hub's long list is sorted). Any thread.
  bool distinct_neighbours(std::uint32_t v, std::vector<std::uint32_t>* out) const;
  /// Calls f(u) for each corner u of each live face of v (v itself among them, and
  /// neighbours once per face they share with v). Any thread.
  template <class F>
  void for_each_corner(std::uint32_t v, const F& f) const {
    for_each_face(v, [&](std::uint32_t face) {
      for (int k = 0; k < 3; ++k) f(mesh_.triangles[3 * std::size_t(face) + std::size_t(k)]);
    });
  }
  /// Each face's normal in the input.
  const std::vector<UnitNormal>& first_normals() const { return first_normal_; }
  /// The live faces, their vertices numbered by first use, in face order, with their
  /// input normals; `sources` (if given) gets each result vertex's index here.
  /// With `geometry_only`, without the quadrics and input normals (an output's
  /// result, whose quadrics nobody reads).
  QuadricMesh result(std::vector<std::uint32_t>* sources = nullptr, bool geometry_only = false) const;
  /// The vertices, moved out (the state is spent): positions, quadrics and attributes
  /// of every vertex in its place; no faces.
  QuadricMesh release_vertices();

 private:
  template <class F>
  void for_each_face(std::uint32_t v, const F& f) const {
    const std::uint32_t* p = faces_.data() + face_start_[v];
    for (std::uint32_t i = 0; i < face_count_[v]; ++i)
      if (!face_dead_[p[i]]) f(p[i]);
  }
  // Calls f(face) for each live face on edge (a, b), from the list of the end with
  // fewer faces: around a hub (a cone's apex, a fan of thousands) this is asked for
  // each of its edges.
  template <class F>
  void for_each_edge_face(std::uint32_t a, std::uint32_t b, const F& f) const {
    if (face_count_[b] < face_count_[a]) std::swap(a, b);
    for_each_face(a, [&](std::uint32_t face) {
      const std::uint32_t* t = &mesh_.triangles[3 * std::size_t(face)];
      if (t[0] == b || t[1] == b || t[2] == b) f(face);
    });
  }
  void build_adjacency();
  // The lists fan_shape() works in: one per thread.
  struct VertexScratch {
    std::vector<std::uint32_t> ring, count, parent;
  };
  // What v's faces make around it: one fan with no edge of three or more faces
  // (manifold), and whether an edge of one face (the outline) is among them.
  struct FanShape {
    bool manifold = false, outline = false;
  };
  FanShape fan_shape(std::uint32_t v, VertexScratch* scratch) const;
  bool doubles_a_face(std::uint32_t a, std::uint32_t b) const;
  // For edge (a, b): how many distinct vertices share a face with a (b among them),
  // with b (a among them), and with both.
  struct LinkCounts {
    std::size_t ring_a = 0, ring_b = 0, common = 0;
  };
  LinkCounts link_counts(std::uint32_t a, std::uint32_t b) const;
  bool keeps_faces(const Candidate& c, std::uint32_t* blamed) const;
  void add_boundary_planes(double weight);
  void pair_coincident_vertices();
  // Whether edge (u, w), of one face, is a seam's: its counterpart on the other side,
  // between the mirrors of its ends (or a mirror and an end both sides share, as at a
  // pole), is an edge too. Its line quadric is a seam's.
  bool seam_edge(std::uint32_t u, std::uint32_t w) const;
  // Whether an end of edge (u, w) has a mirror. Splits (and the outline test of an odd
  // count) pass over such an edge of one face: splitting a seam's edge on one side
  // would open it. An outline edge that merely ends at a seam is passed over too, so an
  // odd target on an open textured mesh whose outline edges all touch seams gives one
  // fewer.
  bool touches_seam(std::uint32_t u, std::uint32_t w) const;
  // Whether v is on the surface's own outline: on an edge of one face that is no seam's.
  bool on_outline(std::uint32_t v) const;
  // One collapse of b into a, without its mirror.
  void collapse_one(const Candidate& c);
  // valid() for one side of a seam.
  bool valid_one(const Candidate& c, std::uint32_t* blamed) const;
  // The longest live edge of `faces` faces (ties: the lowest vertices) into *edge (if
  // given); false when there is none.
  bool longest_edge(int faces, std::pair<std::uint32_t, std::uint32_t>* edge) const;
  // Splits edge (u, w) of `faces` faces at its midpoint (see split_longest_edge); the
  // new vertex is the last.
  void split_edge(std::uint32_t u, std::uint32_t w, int faces);
  void classify_vertices();
  void compact_adjacency();

  QuadricMesh mesh_;
  double cos_max_turn_;
  double min_compactness_;
  std::vector<std::uint8_t> face_dead_, alive_, complex_, boundary_, locked_;
  std::vector<std::uint8_t> hub_;         // more faces than kStillHub: does not move (evaluate)
  std::vector<std::uint32_t> mirror_;     // per vertex: its mirror across a seam, or kNoMirror (empty: no seams)
  std::vector<UnitNormal> first_normal_;  // each face's normal in the input
  std::vector<std::uint32_t> face_start_, face_count_, faces_;  // faces around each vertex
  std::size_t compact_at_ = 0;
  std::uint64_t live_faces_ = 0;
  mutable std::vector<std::uint32_t> scratch_a_;
  mutable VertexScratch scratch_;
  std::vector<std::uint32_t> newly_anchored_;
};

/// The collapses of `state` in order of cost, from a priority queue with lazy updates,
/// down to settings.target_triangles (exactly, with settings.exact_count). The driver
/// of collapse_state() after its passes.
void collapse_in_order(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                       ProgressPhase* progress);

/// The collapses of `state` down to settings.target_triangles: in passes
/// (settings.pass_faces, pass_share), then in strict order (collapse_in_order). The
/// driver of collapse_edges() after its tiles, and of each tile.
void collapse_state(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                    ProgressPhase* progress);

/// The parallel first step of collapse_edges() (refine/tiled_collapse.cpp): the faces
/// of `state` (no collapse taken yet) are cut into tiles of about settings.tile_faces,
/// consecutive in Morton order of their centroids; each tile collapses on its own
/// (collapse_state), its border vertices locked, to settings.tile_share times its share
/// of the target. Returns the mesh with the tiles' collapses taken, vertices in their
/// places, and adds to `stats`. Spends `state`.
QuadricMesh collapse_tiles(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats);

/// QEM edge collapse until settings.target_triangles are left: large meshes in tiles
/// first (collapse_tiles), then collapse_state(): passes, then the cheapest valid
/// collapse first (ties by vertex index) from a priority queue whose entries are
/// checked when taken (lazy updates). The result is the same for any thread count.
/// Reports the collapses taken to `progress` when given (which may cancel).
QuadricMesh collapse_edges(QuadricMesh mesh, const CollapseSettings& settings, CollapseStats* stats,
                           ProgressPhase* progress = nullptr);

/// Where collapse_edges_to_levels() hands each level: its number (0 the finest), the
/// mesh as collapse_edges() returns it, and the stats so far.
using CollapseLevelSink = std::function<void(std::size_t level, QuadricMesh mesh, const CollapseStats& stats)>;

/// collapse_edges() down to settings.target_triangles, then on from there down to each
/// of `coarser` (descending) in turn, each level handed to `each` as it is reached.
/// A coarser level continues the finer one's collapse, in passes and in order of cost
/// as for one target, so that a chain of levels costs about one collapse; each starts
/// with the needle guard of `settings`. Edges a finer level split to meet its count
/// stay, and may collapse in the next. The stats count from the start (the collapses
/// taken to reach a level, the largest cost and error among them); stuck,
/// stopped_by_error and parity are each level's own.
void collapse_edges_to_levels(QuadricMesh mesh, const CollapseSettings& settings,
                              const std::vector<std::uint64_t>& coarser, CollapseStats* stats,
                              const CollapseLevelSink& each, ProgressPhase* progress = nullptr);

}  // namespace oocsimp
