// Velho 1999 §4, Algorithm 1: simplification by four-face clusters. Each set of
// removals (a level is one or more, HierarchyOptions::sets_per_level) ranks the
// vertices by the cost of removing them (eq. 6-8), bounded from below, then, cheapest
// first, brings each unmarked vertex to valence 4 by edge swaps, removes it by the
// diagonal of lower cost, passes its quadric on (eq. 9) and marks the four vertices
// around it, so that a set's clusters are independent.
//
// What the paper leaves open, and what is chosen here:
// - C(v) (eq. 7) is taken over the ring after the swaps: the vertices the removal's
//   faces keep, one of which takes v's place.
// - S(v) (eq. 8) sums the swaps' costs, each the squared volume of the tetrahedron
//   the swap flattens, read as the plane quadric of each face it replaces at the
//   opposite corner (swap_cost). The swaps are chosen one at a time, the cheapest
//   first by S times (2 - c), c the least compactness (eq. 4) of the two faces the
//   swap makes; at equal keys (on a flat patch every S is 0) the rounder faces.
// - The removal is the half-edge collapse of v into an end of the new diagonal (Velho
//   §3): C(v) is the cheaper end's C_i, and the diagonal with the cheapest end is
//   kept; eq. 9 gives each of its ends a share 1 - C_i / (C_a + C_b) of Q_v.
// - A vertex of valence 3 inside is removed as it is, its three faces becoming one
//   (its quadric shared by the three, eq. 9 for three ends). A vertex on the boundary
//   is brought to two faces by swaps and removed, the two faces becoming one along
//   a new boundary edge (its two ends share Q_v); the boundary edges' planes in the
//   quadrics make that cost as leaving the outline does. A boundary vertex of one
//   face (an ear) is removed with its face, when the face's inner edge has a face
//   beyond: the outline then runs along that edge. Without it the outline's
//   vertices stall the coarse levels of open meshes.
// - No record may make an edge that exists, a face of no area, a face whose normal
//   turns by 90 degrees or more from the face it replaces along an outline edge, a
//   face that leans from the replaced faces' normal by more than 75 degrees and more
//   than they do, a crease sharper than the sharpest it replaces (or than 150
//   degrees), or a face less compact than both kMinCompactness and half the least
//   compact it replaces.
#pragma once

#include <cstdint>
#include <vector>

#include "cluster/quadric.hpp"
#include "hierarchy/four_k_mesh.hpp"
#include "oocsimp/hierarchy.hpp"

namespace oocsimp {

class FourFaceSimplifier {
 public:
  /// A new face may not be less compact than this unless a face it replaces was
  /// nearly as bad: the least new compactness must be at least kNeedleSlack times the
  /// least old one. Without the slack, a mesh of slivers (the poles of a
  /// latitude-longitude sphere) stalls: no removal there makes faces compact enough.
  static constexpr double kMinCompactness = 0.05, kNeedleSlack = 0.5;
  /// Faces whose unit normals agree to this dot product are one flat patch.
  static constexpr double kFlat = 1 - 1e-9;
  static constexpr double kLeanCosine = 0.2588;  // cos 75 degrees: see faces_fit
  /// A new crease up to 150 degrees is allowed; a sharper one only where an old
  /// crease was as sharp. (A right angle kept a rough terrain's sharp places from
  /// going at the coarse levels, and dearer removals went instead: docs/hierarchy.md.)
  static constexpr double kCreaseCosine = -0.866;

  FourFaceSimplifier(FourKMesh* mesh, const HierarchyOptions& options);

  /// Q_v = sum of the area-weighted plane quadrics of v's faces (eq. 5), plus the
  /// boundary edges' planes; or `given` (when not empty, one per vertex), the quadrics a
  /// simplification that made this mesh summed, so that the error it made counts on.
  void assign_quadrics(std::vector<Quadric> given = {});
  /// One set of removals, a level or a part of one (HierarchyOptions::sets_per_level):
  /// rank, select and simplify (steps 1-3). Appends its records to `records`; returns
  /// how many vertices it removed.
  std::uint64_t simplify_level(std::vector<HierarchyRecord>* records);

  /// Plans the walk took as made before the vertex's turn: ahead on other threads
  /// (none under one thread), or when its entry went back.
  struct WalkStats {
    std::uint64_t made_ahead = 0, kept = 0;
  };
  const WalkStats& walk_stats() const { return walk_stats_; }

 private:
  struct Plan {
    double cost = 0;                     // E(v), eq. 6
    double removal = 0;                  // C(v), eq. 7
    double swaps = 0;                    // S(v)
    std::vector<std::uint32_t> swapped;  // ring vertices swapped out, in order
    std::uint32_t ring[4];               // the ring left, from the vertex the new faces fan from
    int ring_count = 0;
    bool closed = false;
    double ring_cost[4];  // C_i = (Q_v + Q_i)(p_i) for each
    /// v's neighbours when the plan was made: with v, the vertices whose faces and
    /// quadrics it read (empty when v's faces were not one fan).
    std::vector<std::uint32_t> neighbours;
    /// The removal's record, with the faces it replaces (its fan's: closed, one per
    /// ring vertex; open, one fewer) yet to be named.
    HierarchyRecord removal_record() const {
      HierarchyRecord r;
      r.face_count = std::uint8_t(closed ? ring_count : ring_count - 1);
      return r;
    }
  };

  bool plan_removal(std::uint32_t v, Plan* plan) const;
  double least_cost(std::uint32_t v) const;
  double collapse_cost(std::uint32_t v, std::uint32_t u) const;
  double swap_cost(std::uint32_t v, std::uint32_t prev, std::uint32_t mid, std::uint32_t next) const;
  bool faces_fit(const std::uint32_t* old_faces, int old_count, const std::uint32_t* new_faces, int new_count,
                 double* least_compactness) const;
  void rank_vertices();
  void take(std::uint32_t v, const Plan& plan);
  void apply_taken();
  bool reads_taken(std::uint32_t v) const;
  int apply_removal(std::uint32_t v, const Plan& plan, std::uint32_t first_face, HierarchyRecord* records);

  static constexpr std::uint32_t kNoSlot = 0xffffffffu;

  struct Entry {
    double cost;
    std::uint32_t vertex;
    std::uint32_t slot = kNoSlot;  // an entry that went back: its plan in kept_
    /// The queue's order: the cheapest, then the least vertex, first.
    struct Later {
      bool operator()(const Entry& a, const Entry& b) const {
        return a.cost > b.cost || (a.cost == b.cost && a.vertex > b.vertex);
      }
    };
  };

  /// A plan made before its vertex's turn: it holds then unless a removal since
  /// changed the faces or quadric of the vertex or of a neighbour (is_fresh()).
  struct KnownPlan {
    bool ready = false;         // made (else the walk plans the vertex itself)
    bool ok = false;            // plan_removal()'s answer
    std::uint32_t made_at = 0;  // removals_ when it was made
    Plan plan;
  };

  // Steps 2-3, the walk of the queue (simplify_level()).
  bool next_entry(Entry* entry, const KnownPlan** known);
  bool has_next() const { return next_ < order_.size() || !returned_.empty(); }
  const Entry& next_in_line() const;
  void go_back(const Entry& e, const Plan& plan);
  void work_ahead();
  void prefetch_neighbour(std::uint32_t u) const;
  bool is_fresh(std::uint32_t v, const KnownPlan& known) const;
  std::uint32_t next_claim();

  FourKMesh& mesh_;
  const HierarchyOptions& options_;
  std::vector<Quadric> quadrics_;
  // Per set: marked vertices, each vertex's least cost at the start, and the queue: the
  // entries sorted cheapest first (and the next to take), and a heap of the entries
  // that went back with a higher cost, their plans kept (free slots in free_slots_).
  std::vector<std::uint8_t> marked_;
  std::vector<double> cost_;
  std::vector<Entry> order_;
  std::size_t next_ = 0;
  std::vector<Entry> returned_;
  std::vector<KnownPlan> kept_;
  std::vector<std::uint32_t> free_slots_;
  // The removals taken this level, and per vertex how many had been taken when its
  // faces or quadric last changed.
  std::uint32_t removals_ = 0;
  std::vector<std::uint32_t> changed_;
  // Removals taken and not yet applied to the mesh (apply_taken()): each with its plan,
  // its first record in records_ and the number of the first face it makes. The live
  // faces the mesh will have when they are applied.
  struct Taken {
    std::uint32_t vertex = 0, first_face = 0;
    std::size_t first_record = 0;
    int vertex_change = 0;
    Plan plan;
  };
  std::vector<Taken> taken_;
  std::size_t taken_count_ = 0;
  std::uint32_t applied_at_ = 0;  // removals_ when apply_taken() last ran
  std::uint64_t faces_after_taken_ = 0;
  std::vector<HierarchyRecord>* records_ = nullptr;
  // The plans of order_[ahead_first_, ahead_first_ + ahead_.size()), when this level
  // works them out ahead; per vertex, the batch that claimed it (work_ahead()).
  bool ahead_on_ = false;
  std::vector<KnownPlan> ahead_;
  std::size_t ahead_first_ = 0;
  std::vector<std::uint32_t> claimed_;
  std::uint32_t claim_ = 0;
  WalkStats walk_stats_;
};

}  // namespace oocsimp
