// The faces a hierarchy record makes from the faces it replaces (Velho 1999 §3,
// Figure 1): one rule, used by the builder when it makes them and by the reader when
// it derives them again from a file that stores only the replaced faces.
#pragma once

#include <cstdint>

#include "oocsimp/hierarchy.hpp"

namespace oocsimp {

/// The most faces a record makes.
constexpr int kMostNewFaces = 2;

/// How many faces `record` makes: 2 for a swap and for a removal of 4 faces, none for
/// a removal of 1 face (a boundary ear), else 1.
inline int record_new_face_count(const HierarchyRecord& record) {
  if (record.swap || record.face_count == 4) return 2;
  return record.face_count == 1 ? 0 : 1;
}

/// Writes the corners of the faces `record` makes into `out` (3 per face) and returns
/// how many (record_new_face_count); -1 when the replaced faces, whose corners
/// `corners_of(f)` gives, do not fit the record:
/// - a swap: faces (x, y, a) and (y, x, b) sharing edge x-y become (a, x, b) and
///   (b, y, a);
/// - a removal: faces (v, w0, w1), (v, w1, w2), ... around v in order, closed (3 or 4
///   faces inside) or open (1 or 2 faces on the boundary), become the fan from w0 over
///   the ring: (w0, w1, w2) and, for 4 faces, (w0, w2, w3); one face on the boundary
///   (an ear) becomes none, its inner edge w0-w1 joining the outline.
template <class CornersOf>
int record_new_faces(const HierarchyRecord& record, const CornersOf& corners_of, std::uint32_t out[3 * kMostNewFaces]);

/// The ring around a removal's vertex, read from the faces it replaces: `*ring_count`
/// vertices into `ring`, counter-clockwise from the one the new faces fan from, and
/// whether it is `closed` (inside). False when the faces do not make a removal's fan
/// (a swap, or faces that do not fit).
template <class CornersOf>
bool removal_ring(const HierarchyRecord& record, const CornersOf& corners_of, std::uint32_t ring[5], int* ring_count,
                  bool* closed);

// --- implementation ---------------------------------------------------------------

template <class CornersOf>
int record_new_faces(const HierarchyRecord& record, const CornersOf& corners_of, std::uint32_t out[3 * kMostNewFaces]) {
  if (record.swap) {
    if (record.face_count != 2) return -1;
    const std::uint32_t* f = corners_of(record.faces[0]);
    const std::uint32_t* g = corners_of(record.faces[1]);
    int shared = 0;
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t x = f[i], y = f[(i + 1) % 3], a = f[(i + 2) % 3];
      for (int j = 0; j < 3; ++j) {
        if (g[j] != y || g[(j + 1) % 3] != x) continue;
        const std::uint32_t b = g[(j + 2) % 3];
        if (a == b) return -1;
        const std::uint32_t made[6] = {a, x, b, b, y, a};
        for (int k = 0; k < 6; ++k) out[k] = made[k];
        ++shared;
      }
    }
    return shared == 1 ? 2 : -1;
  }
  std::uint32_t ring[5];
  int count = 0;
  bool closed = false;
  if (!removal_ring(record, corners_of, ring, &count, &closed)) return -1;
  int made = 0;
  for (int j = 1; j + 1 < count; ++j, ++made) {
    out[3 * made] = ring[0];
    out[3 * made + 1] = ring[j];
    out[3 * made + 2] = ring[j + 1];
  }
  return made;
}

template <class CornersOf>
bool removal_ring(const HierarchyRecord& record, const CornersOf& corners_of, std::uint32_t ring[5], int* ring_count,
                  bool* is_closed) {
  if (record.swap) return false;
  const int n = record.face_count;
  if (n < 1 || n > 4) return false;
  const std::uint32_t v = record.vertex;
  for (int i = 0; i < n; ++i) {
    const std::uint32_t* f = corners_of(record.faces[i]);
    int at = -1;
    for (int k = 0; k < 3; ++k)
      if (f[k] == v) at = k;
    if (at < 0) return false;
    const std::uint32_t from = f[(at + 1) % 3], to = f[(at + 2) % 3];
    if (i == 0)
      ring[0] = from;
    else if (ring[i] != from)
      return false;
    ring[i + 1] = to;
  }
  const bool closed = ring[n] == ring[0];
  // Inside: 3 or 4 faces around v; on the boundary: 1 or 2.
  if (closed ? n < 3 : n > 2) return false;
  const int count = closed ? n : n + 1;  // ring vertices
  for (int i = 0; i < count; ++i) {
    if (ring[i] == v) return false;
    for (int j = i + 1; j < count; ++j)
      if (ring[i] == ring[j]) return false;
  }
  *ring_count = count;
  *is_closed = closed;
  return true;
}

}  // namespace oocsimp
