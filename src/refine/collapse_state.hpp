// The state of a mesh being collapsed (Garland & Heckbert 1997; Theoharis et al. 2008,
// ch. 6, "Simplification using Iterative Edge Collapses"): the faces around each
// vertex, the quadrics, the locks and seams, and the checks a collapse must pass. The
// order the collapses are taken in is the drivers' (refine/edge_collapse.hpp), so that
// a test can drive the same state with a naive queue and compare.
//
// The member functions live in three files along the state's seams:
// collapse_state.cpp (building it, its queries, the result), collapse_checks.cpp (the
// cost and placement of a collapse and whether it is valid) and collapse_edits.cpp
// (taking a collapse, splitting edges).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "refine/collapse_types.hpp"

namespace oocsimp {

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
  /// edges cost anew: neighbours it left non-manifold (now anchored), the third corner
  /// of a hole it closed (now free), and the mirror collapse's survivor.
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
  // A hub of more faces than this (the centre of a finely cut fan: a cylinder's cap, a
  // cone's apex) stays where it is, as an outline vertex does: moving it would check
  // every one of its faces for each collapse tried there, which made the collapse
  // quadratic in its valence. Its edges collapse onto it. Of the generated shapes and
  // the benchmarks' scans, only the generated sphere's poles reach it (docs/design.md,
  // "The collapse in core", Hubs, has the cone's times and the largest valences).
  static constexpr std::size_t kStillHub = 1024;
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
  // Whether v's faces form one closed fan, wound consistently (fan_shape's quick case).
  bool closed_fan(std::uint32_t v) const;
  bool doubles_a_face(std::uint32_t a, std::uint32_t b) const;
  // Whether boundary edge (a, b) is on a hole of three edges that its collapse closes.
  bool closes_hole(std::uint32_t a, std::uint32_t b) const;
  // Whether merging b into a would join two edges of at most two faces into one of more.
  bool joins_into_non_manifold_edge(std::uint32_t a, std::uint32_t b) const;
  // For edge (a, b): how many distinct vertices other than a and b share a face with
  // both, and whether a and b each share a face with exactly three (the other end
  // among them), as in a tetrahedron.
  struct LinkCounts {
    std::size_t common = 0;
    bool rings_of_three = false;
  };
  LinkCounts link_counts(std::uint32_t a, std::uint32_t b) const;
  bool keeps_faces(const Candidate& c, std::uint32_t* blamed) const;
  // keeps_face() of a face not dead.
  bool keeps_live_face(const Candidate& c, std::uint32_t f) const;
  // The boundary planes (Garland & Heckbert 1997 §6.1), a hole's held as a face is;
  // `partial` (or empty) marks the vertices not all of whose faces are here.
  void add_boundary_planes(const CollapseSettings& settings, const std::vector<std::uint8_t>& partial);
  // For each edge of `edges` (u, w), whether it is on a hole: a loop of at most
  // `most_edges` edges, each of whose vertices has two edges of `edges`, none partial
  // nor anchored as non-manifold.
  std::vector<std::uint8_t> hole_edges(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                                       std::uint64_t most_edges, const std::vector<std::uint8_t>& partial) const;
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
  // Room for the face lists of `packed` entries and the lists the collapses append:
  // twice as many, and some for a small mesh.
  static std::size_t list_room(std::size_t packed) { return 2 * packed + 1024; }
  void set_face_list(std::uint32_t v, const std::vector<std::uint32_t>& list);
  void compact_adjacency(std::size_t more);

  QuadricMesh mesh_;
  double cos_max_turn_;
  double min_compactness_;
  std::vector<std::uint8_t> face_dead_, alive_, complex_, boundary_, locked_;
  std::vector<std::uint8_t> hub_;         // more faces than kStillHub: does not move (evaluate)
  std::vector<std::uint32_t> mirror_;     // per vertex: its mirror across a seam, or kNoMirror (empty: no seams)
  std::vector<UnitNormal> first_normal_;  // each face's normal in the input
  std::vector<std::uint32_t> face_start_, face_count_, faces_;  // faces around each vertex
  std::uint64_t live_faces_ = 0;
  mutable std::vector<std::uint32_t> scratch_a_;
  mutable VertexScratch scratch_;
  std::vector<std::uint32_t> newly_anchored_;
};

}  // namespace oocsimp
