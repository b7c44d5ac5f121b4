#include <algorithm>
#include <optional>

#include "hierarchy/four_face_simplifier.hpp"
#include "hierarchy/four_k_mesh.hpp"
#include "hierarchy/hierarchy_steps.hpp"
#include "hierarchy/record_faces.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

MeshHierarchy build_four_k_hierarchy(const std::vector<Vec3d>& positions, const std::vector<std::uint32_t>& triangles,
                                     const HierarchyOptions& options, std::vector<Quadric> quadrics) {
  MeshHierarchy h;
  h.positions.reserve(3 * positions.size());
  for (const Vec3d& p : positions) h.positions.insert(h.positions.end(), {p.x, p.y, p.z});
  h.triangles = triangles;

  // The mesh's adjacency and its vertices' quadrics: seconds on a large mesh, a phase
  // of its own so that a log does not fall silent.
  std::optional<ProgressPhase> setup(std::in_place, options.progress, "4-k mesh", 0, "tri");
  FourKMesh mesh(positions, triangles);
  FourFaceSimplifier simplifier(&mesh, options);
  simplifier.assign_quadrics(std::move(quadrics));
  setup.reset();
  h.levels.push_back({0, mesh.live_faces(), mesh.live_vertices(), 0});
  // Progress in faces gone: a level takes a share of what is left.
  ProgressPhase progress(options.progress, "4-k levels", mesh.live_faces(), "tri");
  // Velho's level is one independent set of removals (simplify_level), or
  // options.sets_per_level smaller ones. Where they fall short of kMostLevelRatio
  // (the late levels of rough or small meshes, whose removals the flip and crease
  // guards mostly refuse), further sets join the level, so that every level shrinks
  // the mesh by a useful step; a last level that still falls short, nothing more
  // being removable, joins the one before.
  constexpr double kMostLevelRatio = 0.75;
  const double most = std::max(kMostLevelRatio, options.level_ratio);
  float largest = 0;
  bool done = false;
  for (std::uint32_t level = 1; !done && (options.levels == 0 || level <= options.levels); ++level) {
    const std::uint64_t start = mesh.live_faces();
    const std::size_t first = h.records.size();
    std::uint32_t sets = 0;
    do {
      done = simplifier.simplify_level(&h.records) == 0;
      ++sets;
    } while (!done && (sets < options.sets_per_level || double(mesh.live_faces()) > most * double(start)));
    if (h.records.size() == first) break;
    for (std::size_t r = first; r < h.records.size(); ++r) largest = std::max(largest, h.records[r].error);
    h.levels.push_back({h.records.size(), mesh.live_faces(), mesh.live_vertices(), largest});
    progress.set(h.levels[0].triangles - mesh.live_faces());
  }
  const std::size_t levels = h.levels.size();
  if (done && levels > 2 && double(h.levels[levels - 1].triangles) > most * double(h.levels[levels - 2].triangles)) {
    h.levels[levels - 2] = h.levels[levels - 1];
    h.levels.pop_back();
  }
  h.face_corners = mesh.face_corners();
  h.first_new_face.resize(h.records.size());
  std::uint32_t next = std::uint32_t(triangles.size() / 3);
  for (std::size_t r = 0; r < h.records.size(); ++r) {
    h.first_new_face[r] = next;
    next += std::uint32_t(record_new_face_count(h.records[r]));
  }
  return h;
}

std::size_t derive_faces(MeshHierarchy* h) {
  const std::size_t finest = h->triangles.size() / 3;
  h->face_corners = h->triangles;
  h->face_corners.reserve(h->triangles.size() + 6 * h->records.size());
  h->first_new_face.assign(h->records.size(), 0);
  std::vector<std::uint8_t> replaced(finest, 0);
  replaced.reserve(finest + 2 * h->records.size());
  const std::uint64_t vertices = h->positions.size() / 3;
  for (std::size_t r = 0; r < h->records.size(); ++r) {
    const HierarchyRecord& record = h->records[r];
    if (record.face_count > 4 || record.vertex >= vertices) return r;
    for (int i = 0; i < record.face_count; ++i) {
      const std::uint32_t f = record.faces[i];
      if (f >= replaced.size() || replaced[f]) return r;
      for (int j = 0; j < i; ++j)
        if (record.faces[j] == f) return r;
    }
    std::uint32_t made[3 * kMostNewFaces];
    const int count = record_new_faces(
        record, [h](std::uint32_t f) { return &h->face_corners[3 * std::size_t(f)]; }, made);
    if (count < 0) return r;
    for (int i = 0; i < record.face_count; ++i) replaced[record.faces[i]] = 1;
    h->first_new_face[r] = std::uint32_t(replaced.size());
    h->face_corners.insert(h->face_corners.end(), made, made + 3 * count);
    replaced.resize(replaced.size() + std::size_t(count), 0);
  }
  return h->records.size();
}

}  // namespace oocsimp
