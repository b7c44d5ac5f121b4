// The 4-k hierarchy's stages on plain data: building it on a manifold mesh, deriving
// the faces its records make, and extracting a mesh from it.
#pragma once

#include <cstdint>
#include <vector>

#include "cluster/quadric.hpp"
#include "oocsimp/geometry.hpp"
#include "oocsimp/hierarchy.hpp"

namespace oocsimp {

/// Velho 1999 Algorithm 1 on a manifold mesh (manifold_input.hpp): the records of
/// each level until a level removes nothing or options.levels are built, with
/// face_corners and first_new_face filled. Positions are copied into the result.
/// `quadrics` (one per vertex, or none) are the vertices' starting quadrics in place
/// of their faces' and outline's (FourFaceSimplifier::assign_quadrics).
MeshHierarchy build_four_k_hierarchy(const std::vector<Vec3d>& positions, const std::vector<std::uint32_t>& triangles,
                                     const HierarchyOptions& options, std::vector<Quadric> quadrics = {});

/// Fills hierarchy->face_corners and first_new_face from the finest mesh and the
/// records. Returns the index of the first record that does not fit (a face that does
/// not exist yet or is already replaced, or faces that do not make the record's
/// shape), or records.size() when all fit.
std::size_t derive_faces(MeshHierarchy* hierarchy);

/// The longest dependency chain (oocsimp::hierarchy_height).
std::uint64_t dependency_height(const MeshHierarchy& hierarchy);

/// The selected records' mesh (oocsimp::extract_mesh).
SimplifiedMesh extract_from_hierarchy(const MeshHierarchy& hierarchy, const HierarchyQuery& query);

}  // namespace oocsimp
