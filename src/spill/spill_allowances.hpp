// How much of the memory budget the spill stores of a floating-cells run may hold in
// memory instead of writing to their files.
#pragma once

#include <algorithm>
#include <cstdint>

namespace oocsimp {

/// Bytes each store may hold in memory (StreamSpill's and BlockStore's allowance).
struct SpillAllowances {
  std::uint64_t triangles = 0;      ///< the tiles' triangle spill
  std::uint64_t vertex_blocks = 0;  ///< the graded vertex blocks
  std::uint64_t buckets = 0;        ///< each of the stitch, kept-triangle and cluster buckets
};

/// What `budget` leaves once `reserved` (the threads' tiles, the binning buffers,
/// the output tables: what the run needs whatever it spills) is taken, given to the
/// largest consumer first: the triangle spill up to its expected `triangle_bytes`,
/// then the vertex blocks up to `vertex_block_bytes`, and what is left to the
/// bucket spills, a third each, at most an eighth of the budget in all. The buckets
/// are read while the output tables are built, which the reserve counts only once.
/// Expected sizes only steer the split: a store that needs more spills the rest.
/// The output tables' share is a guess; assembly checks their real need (mesh_assembly.cpp).
inline SpillAllowances spill_allowances(std::uint64_t budget, std::uint64_t reserved, std::uint64_t triangle_bytes,
                                        std::uint64_t vertex_block_bytes) {
  std::uint64_t left = budget > reserved ? budget - reserved : 0;
  SpillAllowances a;
  a.triangles = std::min(left, triangle_bytes);
  left -= a.triangles;
  a.vertex_blocks = std::min(left, vertex_block_bytes);
  left -= a.vertex_blocks;
  a.buckets = std::min(left, budget / 8) / 3;
  return a;
}

}  // namespace oocsimp
