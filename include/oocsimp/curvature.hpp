// oocsimp — principal curvatures by integral invariants (Hua et al. §3.4, after
// Pottmann et al. 2007): for each vertex p, the covariance of the ball B_r(p) cut by
// the solid the surface bounds (or of the sphere S_r(p) cut by it), whose tangential
// eigenvalues give k1 and k2. The choices the paper leaves open are in
// docs/curvature.md.
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/mesh.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

/// Which neighbourhood of p the invariants measure: the ball B_r(p) cut by the solid
/// (Hua et al. eq. 8-14) or the sphere S_r(p) cut by it (eq. 15-18).
enum class CurvatureNeighbourhood : std::uint8_t { ball, sphere };

/// The default radius, in mean edge lengths of the mesh: on an icosphere the error
/// (the flat faces between vertices on the surface) falls steeply up to it and little
/// beyond (docs/curvature.md, Accuracy, has the errors for each radius).
constexpr double kDefaultCurvatureRadiusEdges = 5;

struct CurvatureOptions {
  /// Of the ball or sphere, in model units; 0 = kDefaultCurvatureRadiusEdges times the
  /// mean edge length. Must be positive, finite and no longer than the bounding box's
  /// diagonal.
  double radius = 0;
  CurvatureNeighbourhood neighbourhood = CurvatureNeighbourhood::ball;
  /// Side of the cubic tiles the mesh is estimated in, model units; 0 = in memory when
  /// it fits the budget, else tiles sized to it. The values are the same either way.
  double tile_side = 0;
  /// The cell-scale estimate instead of the ball or sphere: each vertex takes the
  /// curvatures of the cells of this side (model units) around it, each read from
  /// the faces' moments in it and its 26 neighbours, interpolated (docs/curvature.md,
  /// "The cell-scale estimate"). 0 = the integral invariants, the accurate reference.
  double at_scale = 0;
  unsigned threads = 0;             ///< 0 = all cores; the values are the same for any count
  std::uint64_t memory_budget = 0;  ///< heap bytes; 0 = default_memory_budget()
  std::string temp_dir;             ///< for converted position arrays; empty = default_temp_dir()
  /// Hears "read positions", "survey" (the pass that finds the mean edge), "bin tiles"
  /// (in tiles) and "curvatures"; may cancel.
  ProgressCallback progress;
};

struct CurvatureStats {
  std::uint64_t vertices = 0, triangles = 0;
  double mean_edge_length = 0;
  double radius = 0;     ///< the radius used
  double tile_side = 0;  ///< the tiles' side; 0 when the mesh was held in memory whole
  /// How the vertices' values were found: by the integral invariants; by the fallback,
  /// a quadratic fit to the vertices within the radius, where the surface does not
  /// cover the disk around the vertex (an outline, a hole, a soup); neither (no face,
  /// no area, a non-finite position or too few neighbours), written as 0 and 0.
  std::uint64_t invariant = 0, fitted = 0, none = 0;
  /// With CurvatureOptions::at_scale: the cells' side; `invariant` then counts the
  /// vertices interpolated from cells around them and `none` those with no cell
  /// around them that has an estimate (0 and 0).
  double at_scale = 0;
  double seconds = 0;
  std::uint64_t peak_rss_bytes = 0, peak_anon_bytes = 0;
};

/// Each vertex's principal curvatures, k1 >= k2, positive where the surface is convex
/// seen along its outward normal (triangles wound counter-clockwise seen from outside).
struct VertexCurvatures {
  std::vector<float> k1, k2;
  CurvatureStats stats;
};

/// The curvatures of every vertex of `mesh` (positions and indices; attributes are not
/// read). A mesh larger than the budget is estimated tile by tile, each tile with a
/// halo of the radius: the same values. UsageError for a bad radius, or a budget that
/// cannot hold one tile and its halo (naming the smallest that can).
OOCSIMP_API VertexCurvatures estimate_curvatures(const MeshView& mesh, const CurvatureOptions& options);

/// Reads the mesh at `input_path` (any format open_mesh_input reads), estimates its
/// curvatures and writes `outputs.mesh`, a PLY file (ascii with outputs.ascii, ".zst"
/// compresses; the other fields of OutputOptions are simplify_file's, refused here):
/// the vertices with float properties k1 and k2 after x, y, z, and the faces. The
/// output is written as a stream and the values kept in a mapped temporary file, so
/// heap memory stays within the budget for any size. Renamed into place only when
/// complete. Fills `stats` when given. Throws UsageError (options, a non-PLY
/// output, a budget too small for one tile), InputError and IoError.
OOCSIMP_API void curvature_file(const std::string& input_path, const OutputOptions& outputs,
                                const CurvatureOptions& options, CurvatureStats* stats = nullptr);
/// The same with only a mesh path, written as binary PLY.
OOCSIMP_API void curvature_file(const std::string& input_path, const std::string& output_path,
                                const CurvatureOptions& options, CurvatureStats* stats = nullptr);

}  // namespace oocsimp
