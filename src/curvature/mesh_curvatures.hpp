// The curvatures of every vertex of an opened mesh, in memory when it fits the budget
// and tile by tile otherwise, into an array the caller holds (a mapped temporary file
// for inputs larger than memory).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

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

/// Which vertices part `part` of `parts` of a distributed run estimates: the input's
/// bounding box cut into blocks, a block that holds many vertices cut finer, and the
/// blocks dealt to the parts by their vertex counts (deal_by_weight), so that every
/// part finds its own share from the input alone, the shares cover each vertex once,
/// and a part's vertices lie together (its tiles of the estimate are few). A vertex's
/// values do not depend on who estimates it (tiled_curvatures.hpp), so the parts'
/// values are one process's.
class VertexDeal {
 public:
  /// One part: every vertex.
  VertexDeal() = default;
  VertexDeal(const PositionArray& positions, const Box3d& bounds, std::uint32_t part, std::uint32_t parts);
  bool whole() const { return owned_.empty(); }
  /// The finite vertices the part estimates (when not whole()).
  std::uint64_t owned_vertices() const { return owned_vertices_; }
  /// Whether the part estimates a vertex at `p` (false for a non-finite position).
  bool owns(const Vec3d& p) const;

 private:
  static constexpr int kDivisions = 32;  // blocks along each axis of the box
  static constexpr int kSplit = 8;       // a heavy block's sub-blocks along each axis
  // The block of `p` and its sub-block within it, from one fine coordinate per axis.
  void place(const Vec3d& p, std::size_t* block, std::size_t* sub) const;
  Vec3d origin_;
  double fine_side_ = 1;
  std::vector<char> owned_;             // per block; empty: every vertex
  std::vector<std::int64_t> split_at_;  // per block, its first entry in sub_owned_, or -1
  std::vector<char> sub_owned_;         // kSplit^3 per split block
  std::uint64_t owned_vertices_ = 0;
};

/// Hears the values of some vertices: n vertex numbers and their k1 and k2.
using CurvatureSink =
    std::function<void(const std::uint64_t* vertices, const float* k1, const float* k2, std::size_t n)>;

/// estimate_mesh_curvatures for the vertices `deal` gives the part, handed to `sink`
/// (a tile's, or in memory a run of them, at a time) instead of written into an array. The stats count the part's
/// vertices only: invariant and fitted are its own, none is left 0.
CurvatureStats estimate_dealt_curvatures(MeshInput& input, const CurvatureOptions& options, const VertexDeal& deal,
                                         const CurvatureSink& sink);

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
