// The curvatures of every vertex of an opened mesh, in memory when it fits the budget
// and tile by tile otherwise, into an array the caller holds (a mapped temporary file
// for inputs larger than memory).
#pragma once

#include <cstdint>
#include <string>

#include "io/mapped_file.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/curvature.hpp"

namespace oocsimp {

/// Every vertex's k1 and k2 into k[2 v] and k[2 v + 1] (0 and 0 where there is no
/// estimate), with the counts, the radius used and the time in the stats; the triangle
/// stream of `input` is read from its start and restarted after. In memory when the
/// mesh fits options.memory_budget and no tile side is asked, else in tiles; both give
/// the same values. UsageError for a bad radius or a budget too small for a tile.
CurvatureStats estimate_mesh_curvatures(MeshInput& input, const CurvatureOptions& options, float* k);

/// k1 and k2 of every vertex (2 floats a vertex) in a mapped temporary file: out of the
/// heap, for inputs larger than memory.
class MappedCurvatures {
 public:
  MappedCurvatures(const std::string& dir, std::uint64_t vertices) : scratch_(dir, "curvature-values", 8 * vertices) {}
  float* data() { return reinterpret_cast<float*>(scratch_.data()); }
  const float* data() const { return reinterpret_cast<const float*>(scratch_.data()); }

 private:
  MappedScratch scratch_;
};

}  // namespace oocsimp
