// The clusters of curvature-adaptive clustering (Hua et al. §3.3-3.4): the grid's
// cells split as an octree wherever the principal curvatures of their vertices do
// not match, and each leaf cut into the connected parts of the surface in it. Each
// input vertex gets the number of its cluster; methods/curvature_clusterer.cpp then
// sums and solves the clusters as uniform cells do (cluster/uniform_cells.hpp).
//
// The per-vertex arrays live in mapped temporary files, out of the heap; the heap
// holds one depth's per-cell moments, the cells that split, and a record per leaf and
// per cluster.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/vec3_math.hpp"
#include "grid/grid_spec.hpp"
#include "io/mapped_file.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/progress.hpp"
#include "runtime/memory_budget.hpp"

namespace oocsimp {

struct CurvatureCellSettings {
  /// A cell of side s splits when a child's principal curvatures differ from its own
  /// by more than tolerance / s; a vertex matches a leaf of side s when both its
  /// curvatures lie within tolerance / s of the leaf's means.
  double tolerance = 0.5;
  std::uint32_t max_depth = 0;  ///< splits below a grid cell; capped where the finest grid would pass kMaxDim
};

/// A leaf of the octree: a cell of side grid.cell / 2^depth and, for the vertex
/// representatives, its vertices' mean curvatures.
struct LeafCell {
  std::uint64_t key = 0;  ///< cell coordinates at its depth, packed as GridSpec::key_relative does
  std::uint32_t depth = 0;
  float k1 = 0, k2 = 0;
};

class VertexClusters {
 public:
  /// No clusters yet, for `vertices` input vertices on `grid`; the mapped arrays go to
  /// `temp_dir`.
  VertexClusters(const GridSpec& grid, const CurvatureCellSettings& settings, std::uint64_t vertices,
                 const std::string& temp_dir);
  ~VertexClusters();
  VertexClusters(const VertexClusters&) = delete;
  VertexClusters& operator=(const VertexClusters&) = delete;

  /// Hua et al. §3.4: the octree, from the faces' moments (cluster/cell_moments.hpp).
  /// Depth by depth, one pass over the triangle stream of `input` sums the moments of
  /// the cells one depth down, where the cell above is undecided; a cell splits when
  /// the curvature of one of its children (from the child's sums) differs from its own
  /// (from its sums, its children's) by more than the tolerance over its side, down
  /// to the settings' depth. Then each vertex goes to its
  /// leaf. With `k` (each vertex's k1, k2, mesh_curvatures.hpp), a leaf's curvatures
  /// are its vertices' means, for matches(); without, they are 0. The tables stay
  /// within `budget` or the run stops with a UsageError. Leaves are numbered by their
  /// first vertex.
  void find_leaves(MeshInput& input, const float* k, const MemoryBudget& budget, const ProgressCallback& progress);
  /// The connected parts of each leaf: one pass over the triangle stream of `input`
  /// joins the two ends of every side whose ends share a leaf (union-find, each part
  /// named by its least vertex), so that two sheets passing through one cell stay two
  /// clusters. Then the clusters are numbered in the order of their least vertex.
  void join_components(MeshInput& input, const ProgressCallback& progress);

  /// The cluster of vertex v (after join_components).
  std::uint32_t cluster(std::uint64_t v) const { return labels_[v]; }
  /// The cell of cluster c: its lower corner relative to the grid's origin, and side.
  Vec3d cell_min_relative(std::uint32_t c) const;
  double cell_side(std::uint32_t c) const;
  /// Whether vertex v, with curvatures k1 and k2, matches the cell of its cluster c.
  bool matches(std::uint32_t c, float k1, float k2) const;

 private:
  GridSpec grid_;
  CurvatureCellSettings settings_;
  std::uint64_t vertices_;
  std::string temp_dir_;
  std::vector<LeafCell> leaves_;
  std::vector<std::uint32_t> cluster_leaf_;  // per cluster, its leaf
  std::unique_ptr<MappedScratch> leaf_of_;   // per vertex, its leaf; freed once the clusters are numbered
  std::unique_ptr<MappedScratch> parts_;     // per vertex: the union-find parent, then its cluster
  std::uint32_t* labels_ = nullptr;
};

}  // namespace oocsimp
