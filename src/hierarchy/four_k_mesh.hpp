// The mesh a 4-k hierarchy is built on (Velho 1999 §3): faces are never changed in
// place; a record kills the faces it replaces and appends the ones it makes, so that
// every face keeps its number for the hierarchy's dependencies.
#pragma once

#include <cstdint>
#include <vector>

#include "oocsimp/geometry.hpp"
#include "oocsimp/hierarchy.hpp"

namespace oocsimp {

class FourKMesh {
 public:
  /// The faces around a vertex in counter-clockwise order: face i is (v, ring[i],
  /// ring[i + 1]); closed (inside) the ring has as many vertices as faces and wraps,
  /// open (on the boundary) one more.
  struct Fan {
    std::vector<std::uint32_t> ring, faces;
    bool closed = false;
  };
  /// A live face around a vertex v: the face (v, from, to), counter-clockwise. The
  /// lists hold the other corners so that walking a vertex's faces reads one list.
  struct Incidence {
    std::uint32_t face, from, to;
  };
  /// A vertex's live faces, a view into the mesh valid until the next change.
  class Incidences {
   public:
    Incidences(const Incidence* first, std::size_t count) : first_(first), count_(count) {}
    const Incidence* begin() const { return first_; }
    const Incidence* end() const { return first_ + count_; }
    std::size_t size() const { return count_; }
    bool empty() const { return count_ == 0; }
    const Incidence& operator[](std::size_t i) const { return first_[i]; }

   private:
    const Incidence* first_;
    std::size_t count_;
  };

  /// The finest mesh: 3 indices per face, every edge of at most two faces wound
  /// oppositely, every vertex's faces one fan (manifold_input.hpp makes it so).
  FourKMesh(std::vector<Vec3d> positions, std::vector<std::uint32_t> triangles);

  std::size_t vertex_count() const { return positions_.size(); }
  const Vec3d& position(std::uint32_t v) const { return positions_[v]; }
  const std::vector<Vec3d>& positions() const { return positions_; }
  /// Every face made so far, alive or not: 3 corners each.
  const std::vector<std::uint32_t>& face_corners() const { return corners_; }
  const std::uint32_t* corners(std::uint32_t f) const { return &corners_[3 * std::size_t(f)]; }
  std::uint64_t live_faces() const { return live_faces_; }
  std::uint64_t live_vertices() const { return live_vertices_; }
  bool vertex_alive(std::uint32_t v) const { return around_[v].count > 0; }
  /// v's live faces, in the order they were made.
  Incidences around(std::uint32_t v) const {
    const Around& a = around_[v];
    return {a.count > kInline ? overflow_[v].data() : a.faces, a.count};
  }

  /// Asks memory for v's faces ahead of their use.
  void prefetch_faces(std::uint32_t v) const {
    __builtin_prefetch(&around_[v]);
    __builtin_prefetch(reinterpret_cast<const char*>(&around_[v]) + sizeof(Around) - 1);
  }
  /// v's fan into `out`; false when its faces are not one fan.
  bool fan(std::uint32_t v, Fan* out) const;
  /// Whether a live face has the edge a-b (either way).
  bool has_edge(std::uint32_t a, std::uint32_t b) const;
  /// Whether a live face has the corners a, b and c (in any order).
  bool has_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) const;
  /// The live face with directed edge a->b; kNoFace when none.
  std::uint32_t face_with_edge(std::uint32_t a, std::uint32_t b) const;

  /// Replaces the record's faces by those it makes (record_new_faces); returns the
  /// number of the first new face. The record must fit (the builder plans it so).
  std::uint32_t apply(const HierarchyRecord& record);

  /// Records applied on several threads at once: add_face_numbers() numbers the faces
  /// they will make, in the order they are taken; apply_numbered() then makes a
  /// record's faces under its numbers, touching only the lists of its faces' corners,
  /// so that records whose corners are apart may run at once; count_applied() brings
  /// the live counts up to date with the sums of their changes.
  std::uint32_t add_face_numbers(std::size_t count);
  /// Returns the change in live vertices.
  int apply_numbered(const HierarchyRecord& record, std::uint32_t first);
  void count_applied(std::int64_t faces, std::int64_t vertices);

 private:
  void link(std::uint32_t f);  // face f into its corners' lists
  void unlink(std::uint32_t v, std::uint32_t f);

  // Each vertex's live faces, in a block of its own while they fit (one read of two
  // cache lines: the builder asks about neighbours' faces in no order it can predict),
  // else all in overflow_[v].
  static constexpr std::uint32_t kInline = 10;
  struct alignas(64) Around {
    std::uint32_t count = 0;
    Incidence faces[kInline];
  };

  std::vector<Vec3d> positions_;
  std::vector<std::uint32_t> corners_;
  std::vector<Around> around_;
  std::vector<std::vector<Incidence>> overflow_;
  std::uint64_t live_faces_ = 0, live_vertices_ = 0;
};

}  // namespace oocsimp
