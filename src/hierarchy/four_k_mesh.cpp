#include "hierarchy/four_k_mesh.hpp"

#include <algorithm>
#include <stdexcept>

#include "hierarchy/record_faces.hpp"

namespace oocsimp {

FourKMesh::FourKMesh(std::vector<Vec3d> positions, std::vector<std::uint32_t> triangles)
    : positions_(std::move(positions)),
      corners_(std::move(triangles)),
      around_(positions_.size()),
      overflow_(positions_.size()) {
  live_faces_ = corners_.size() / 3;
  for (std::size_t f = 0; f < live_faces_; ++f) link(std::uint32_t(f));
  for (const Around& a : around_) live_vertices_ += a.count > 0;
}

void FourKMesh::link(std::uint32_t f) {
  const std::uint32_t* c = corners(f);
  for (int k = 0; k < 3; ++k) {
    const Incidence incidence = {f, c[(k + 1) % 3], c[(k + 2) % 3]};
    Around& a = around_[c[k]];
    std::vector<Incidence>& more = overflow_[c[k]];
    if (a.count < kInline) {
      a.faces[a.count] = incidence;
    } else {
      if (a.count == kInline) more.assign(a.faces, a.faces + kInline);
      more.push_back(incidence);
    }
    ++a.count;
  }
}

// Face f out of v's list, the others kept in order.
void FourKMesh::unlink(std::uint32_t v, std::uint32_t f) {
  Around& a = around_[v];
  if (a.count <= kInline) {
    Incidence* end = a.faces + a.count;
    Incidence* at = std::find_if(a.faces, end, [f](const Incidence& x) { return x.face == f; });
    std::copy(at + 1, end, at);
  } else {
    std::vector<Incidence>& more = overflow_[v];
    more.erase(std::find_if(more.begin(), more.end(), [f](const Incidence& x) { return x.face == f; }));
    if (more.size() == kInline) {
      std::copy(more.begin(), more.end(), a.faces);
      more.clear();
    }
  }
  --a.count;
}

bool FourKMesh::fan(std::uint32_t v, Fan* out) const {
  const Incidences faces = around(v);
  const std::size_t n = faces.size();
  out->ring.clear();
  out->faces.clear();
  if (n == 0) return false;
  auto from = [&](std::size_t i) { return faces[i].from; };
  auto to = [&](std::size_t i) { return faces[i].to; };
  // The start: the face whose `from` is no face's `to` (the boundary), else the face
  // with the least `from`, so that the ring is the same however the list is ordered.
  std::size_t start = n, least = 0;
  for (std::size_t i = 0; i < n; ++i) {
    bool entered = false;
    for (std::size_t j = 0; j < n && !entered; ++j) entered = j != i && to(j) == from(i);
    if (!entered) {
      if (start != n) return false;  // two boundary starts: two fans
      start = i;
    }
    if (from(i) < from(least)) least = i;
  }
  out->closed = start == n;
  if (out->closed) start = least;
  out->ring.push_back(from(start));
  std::size_t face = start;
  for (std::size_t step = 0; step < n; ++step) {
    out->faces.push_back(faces[face].face);
    out->ring.push_back(to(face));
    if (step + 1 == n) break;
    std::size_t next = n;
    for (std::size_t j = 0; j < n; ++j)
      if (from(j) == to(face)) next = j;
    if (next == n) return false;
    face = next;
  }
  if (out->closed) {
    if (out->ring.back() != out->ring.front()) return false;
    out->ring.pop_back();
  }
  // One fan: every face once, every neighbour once.
  for (std::size_t i = 0; i < out->ring.size(); ++i)
    for (std::size_t j = i + 1; j < out->ring.size(); ++j)
      if (out->ring[i] == out->ring[j]) return false;
  return true;
}

bool FourKMesh::has_edge(std::uint32_t a, std::uint32_t b) const {
  for (const Incidence& i : around(a))
    if (i.from == b || i.to == b) return true;
  return false;
}

bool FourKMesh::has_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
  for (const Incidence& i : around(a))
    if ((i.from == b && i.to == c) || (i.from == c && i.to == b)) return true;
  return false;
}

std::uint32_t FourKMesh::face_with_edge(std::uint32_t a, std::uint32_t b) const {
  for (const Incidence& i : around(a))
    if (i.from == b) return i.face;
  return HierarchyRecord::kNoFace;
}

std::uint32_t FourKMesh::apply(const HierarchyRecord& record) {
  const std::uint32_t first = add_face_numbers(std::size_t(record_new_face_count(record)));
  const int vertices = apply_numbered(record, first);
  count_applied(std::int64_t(record_new_face_count(record)) - record.face_count, vertices);
  return first;
}

std::uint32_t FourKMesh::add_face_numbers(std::size_t count) {
  const std::uint32_t first = std::uint32_t(corners_.size() / 3);
  corners_.resize(corners_.size() + 3 * count);
  return first;
}

int FourKMesh::apply_numbered(const HierarchyRecord& record, std::uint32_t first) {
  std::uint32_t made[3 * kMostNewFaces];
  const int count = record_new_faces(
      record, [this](std::uint32_t f) { return corners(f); }, made);
  if (count < 0) throw std::logic_error("FourKMesh::apply: a record that does not fit the mesh");
  int vertices = 0;
  for (int i = 0; i < record.face_count; ++i) {
    const std::uint32_t f = record.faces[i];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = corners(f)[k];
      unlink(v, f);
      if (around_[v].count == 0) --vertices;
    }
  }
  for (int i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = made[3 * i + k];
      corners_[3 * std::size_t(first + std::uint32_t(i)) + std::size_t(k)] = v;
      if (around_[v].count == 0) ++vertices;
    }
    link(first + std::uint32_t(i));
  }
  return vertices;
}

void FourKMesh::count_applied(std::int64_t faces, std::int64_t vertices) {
  live_faces_ = std::uint64_t(std::int64_t(live_faces_) + faces);
  live_vertices_ = std::uint64_t(std::int64_t(live_vertices_) + vertices);
}

}  // namespace oocsimp
