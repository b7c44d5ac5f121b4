// oocsimp — distance between two surfaces (target oocsimp::metrics, not part of the
// core library): Hausdorff and mean distance as Theoharis et al. 2008, "Graphics &
// Visualization: Principles and Algorithms", ch. 6 ("Model Representation and
// Simplification") defines them (section "Polygonal Model Simplification (8)"),
// discretised by sampling points on both surfaces.
//
// measure_surface_distance() samples points uniformly by area on both meshes and
// measures each sample's exact distance to the other surface. The first mesh (A, the
// original) is streamed and may be far larger than memory; the second (B, typically
// its simplification) is loaded into memory.
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>

#include "oocsimp/progress.hpp"

namespace oocsimp {

struct MeasureOptions {
  std::uint64_t samples = 1000000;  ///< points sampled on each surface (to within one)
  std::uint64_t seed = 1;           ///< the same seed gives the same samples and results
  unsigned threads = 0;             ///< 0 = all cores; results are identical for any count
  std::string temp_dir;             ///< for converted position arrays; empty = default_temp_dir()
  ProgressCallback progress;        ///< progress reports, and cancellation (see ProgressCallback)
  /// When not empty, a PLY file (.ply or .ply.zst) to write B into with each vertex's
  /// exact distance to surface A as float "quality" and as a colour (uchar red, green,
  /// blue) on error_ramp_colour from 0 to the largest vertex distance, as MeshLab's
  /// Hausdorff filter with "colour by quality" does. Two header comments name A and
  /// give the ramp's end and A's diagonal ("error_ramp MAX diagonal D"), which render
  /// draws as a legend. It costs one more pass over A.
  std::string error_colours;
};

/// The colour of `t` (0 to 1, clamped) on the error ramp, 0xRRGGBB: blue at 0, then
/// cyan, green, yellow, to red at 1, linear between those five, so that no error
/// reads cold and the largest hot.
inline std::uint32_t error_ramp_colour(double t) {
  static const std::uint32_t stops[5] = {0x0000FF, 0x00FFFF, 0x00FF00, 0xFFFF00, 0xFF0000};
  t = t > 0 ? (t < 1 ? t : 1) : 0;  // NaN to 0
  const double at = t * 4;
  const int i = at >= 4 ? 3 : int(at);
  const double f = at - i;
  std::uint32_t out = 0;
  for (int shift : {16, 8, 0}) {
    const double a = double((stops[i] >> shift) & 0xFF), b = double((stops[i + 1] >> shift) & 0xFF);
    out |= std::uint32_t(a + (b - a) * f + 0.5) << shift;
  }
  return out;
}

/// The words of the PLY comment measure writes with the error colours, "error_ramp MAX
/// diagonal D", and render reads back.
constexpr const char* kErrorRampComment = "error_ramp";
constexpr const char* kErrorDiagonalWord = "diagonal";

/// Statistics of the distances of one set of sample points to a surface, in model units.
struct DistanceStats {
  std::uint64_t samples = 0;
  double max = 0;   ///< the largest distance: the one-sided Hausdorff distance of a direction
  double mean = 0;  ///< mean distance
  double rms = 0;   ///< root of the mean squared distance
};

struct OOCSIMP_API DistanceReport {
  DistanceStats a_to_b;  ///< samples on A, distances to surface B
  DistanceStats b_to_a;  ///< samples on B, distances to surface A
  /// The larger max of the two (the paper's Hausdorff distance d_inf); mean and rms over
  /// both sample sets. The paper's "mean square distance" d_2 integrates the distance
  /// (not its square) over each surface divided by its area, i.e. a_to_b.mean +
  /// b_to_a.mean; with equal sample counts symmetric.mean is half of it.
  DistanceStats symmetric;
  /// With MeasureOptions::error_colours, the exact distances of B's vertices to A
  /// (their largest is the colour ramp's end); all zero without.
  DistanceStats b_vertices;
  double a_diagonal = 0;                           ///< length of A's bounding-box diagonal, the scale of the fractions
  double a_area = 0, b_area = 0;                   ///< surface areas, model units squared
  std::uint64_t a_triangles = 0, b_triangles = 0;  ///< triangles read (polygons fanned), degenerate ones included
  double seconds = 0;                              ///< wall time of measure_surface_distance
  std::uint64_t peak_rss_bytes = 0;
  std::uint64_t peak_anon_bytes = 0;  ///< heap and other anonymous memory (not the mapped input)

  /// `stats` with every distance divided by a_diagonal (samples unchanged); all zero
  /// when the diagonal is zero.
  DistanceStats fraction_of_diagonal(const DistanceStats& stats) const;
};

/// Measures the distance between the surfaces of the meshes at `a_path` and `b_path`
/// (any format open_mesh_input reads): options.samples points uniformly by area on
/// each, deterministic for a seed, each with its exact distance to the other surface
/// (closest point on a triangle, not on a vertex). Zero-area triangles are not part
/// of either surface. Heap memory grows with the sample count and with B, never with
/// A, which is streamed three times (twice to sample, once to measure B's samples).
/// Throws InputError for a malformed mesh or one without area, IoError for an
/// unreadable file, UsageError for options.samples outside 1 .. 2^32 - 1 or a B of
/// 2^32 vertices or more.
OOCSIMP_API DistanceReport measure_surface_distance(const std::string& a_path, const std::string& b_path,
                                                    const MeasureOptions& options);

/// `report` as a JSON object: per direction and symmetric, samples and the hausdorff,
/// mean and rms distances, absolute and as fractions of A's diagonal; the meshes'
/// triangle counts, areas and A's diagonal; seconds and peak memory.
OOCSIMP_API std::string distance_report_to_json(const DistanceReport& report);

}  // namespace oocsimp
