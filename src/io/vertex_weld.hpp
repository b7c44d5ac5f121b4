// Vertex welding: vertices at exactly the same position become one vertex, out of core.
//
// STL stores each triangle's three corners apart, so without welding no two triangles
// share a vertex: every cluster sees loose triangles, floating cells (which grade a
// vertex by its incident edges) choose poorly, and --ratio counts three times the
// vertices. PLY and OBJ files exported "unindexed" have the same defect (--weld).
#pragma once

#include <cstdint>
#include <string>

#include "io/mesh_input.hpp"

namespace oocsimp {

/// Replaces the positions of `input` by one vertex per distinct position, numbered in
/// order of first occurrence, and makes its triangle stream yield the new indices (a
/// triangle whose corners weld together then names a vertex twice, and is dropped and
/// counted as such). Positions are equal when their coordinates are equal as stored
/// (-0 equals +0); a vertex with a NaN or infinite coordinate is never welded.
/// Deterministic, whatever the budget and thread count. The heap holds at most about
/// `memory_budget` bytes of sort runs; the rest lives in files under `temp_dir`.
/// `wide_map`: 8-byte vertex numbers in the map even where 4 would do (inputs beyond
/// 2^32 vertices need them; tests use this to cover that layout on small inputs).
void weld_vertices(MeshInput& input, const std::string& temp_dir, std::uint64_t memory_budget, bool wide_map = false);

}  // namespace oocsimp
