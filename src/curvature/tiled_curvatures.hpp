// Curvatures out of core: the mesh binned into cubic tiles with a halo, each tile's
// vertices estimated from the faces of the tile and its halo, the values written at
// the vertices' places. A vertex's value depends only on the faces near it, which its
// tile holds, so the values are those of the whole mesh in memory, for any tiling.
#pragma once

#include <cstdint>
#include <string>

#include <functional>

#include "curvature/vertex_curvatures.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

/// What one pass over the triangles says: their count, the mean length of their
/// sides (each face's three; a shared side counts once per face) and the longest.
struct MeshSurvey {
  std::uint64_t triangles = 0;
  double mean_edge_length = 0;
  double longest_edge = 0;
};

/// One pass over the triangle stream of `input` (restarted after), reported as the
/// progress phase "survey".
MeshSurvey survey_mesh(MeshInput& input, const ProgressCallback& progress = {});

struct TiledCurvatureSettings {
  VertexCurvatureSettings vertex;
  double longest_edge = 0;          ///< MeshSurvey::longest_edge: how far a face reaches
  double tile_side = 0;             ///< 0: from the budget
  std::uint64_t memory_budget = 0;  ///< bytes the tiles' data and the spill's memory take
  std::string temp_dir;
  /// Where the binning ("bin tiles") and then the estimate ("curvatures", of
  /// estimated_vertices) report their phases.
  ProgressCallback progress;
  std::uint64_t estimated_vertices = 0;
};

/// Heap bytes of a tile's work per vertex it holds (halo included): the triangle
/// records, the local mesh and its adjacency, the results, each thread's marks.
std::uint64_t tile_bytes_per_vertex(unsigned threads);

/// The tile side for `settings` (settings.tile_side when given), or UsageError naming
/// options.memory_budget with the smallest budget that works when even tiles as small
/// as their halo would not fit.
double curvature_tile_side(const MeshInput& input, const TiledCurvatureSettings& settings, unsigned threads);

/// k1 and k2 of every vertex into k[2 v] and k[2 v + 1] (zero where no estimate),
/// tile by tile; returns the counts. Vertices in no face, or at non-finite positions,
/// count as none.
VertexCurvatureCounts tiled_vertex_curvatures(MeshInput& input, const TiledCurvatureSettings& settings, double side,
                                              float* k);

/// Whether a vertex at a (finite) position is to be estimated; and where a tile's
/// values go: its estimated vertices' numbers, k1 and k2.
using VertexFilter = std::function<bool(const Vec3d& p)>;
using TileValuesSink = std::function<void(const std::vector<std::uint64_t>& vertices, const std::vector<float>& k1,
                                          const std::vector<float>& k2)>;

/// The same for the vertices `wanted` accepts, each tile's handed to `sink`; tiles
/// without such a vertex are not binned. The counts are those vertices' (none counts
/// only the wanted vertices in a tile that got no estimate).
VertexCurvatureCounts tiled_vertex_curvatures(MeshInput& input, const TiledCurvatureSettings& settings, double side,
                                              const VertexFilter& wanted, const TileValuesSink& sink);

}  // namespace oocsimp
