// oocsimp — synthetic dense meshes of any size (target oocsimp::generate, not part of
// the core library).
#pragma once

#include <cstdint>
#include <string>

#include "oocsimp/progress.hpp"

namespace oocsimp {

enum class SyntheticShape { sphere, terrain, parts };

struct GenerateOptions {
  std::uint64_t triangles = 1000000;  ///< target; the result is within 2% for 10^4 and more
  SyntheticShape shape = SyntheticShape::sphere;
  std::uint64_t seed = 1;
  bool ascii = false;  ///< ascii PLY instead of binary little-endian
  /// Every vertex also gets uchar red, green, blue and float nx, ny, nz (see
  /// generate_mesh); without it the file is what it always was, byte for byte.
  bool attributes = false;
  /// Progress ("generate", in triangles), and cancellation (see ProgressCallback).
  ProgressCallback progress;
};

struct GenerateResult {
  std::uint64_t vertices = 0;
  std::uint64_t triangles = 0;
};

/// Streams a synthetic mesh to `path` as PLY (".zst" compresses) in O(1) memory,
/// deterministically from the seed:
///  - sphere: a closed genus-0 surface (latitude-longitude tessellation) displaced by
///    a sum of seeded sinusoids of several frequencies;
///  - terrain: an open height field over the unit square with a boundary;
///  - parts: intersecting boxes and cylinders with sharp edges and small features.
/// With `attributes`, each vertex follows x, y, z with
///  - uchar red, green, blue: a linear function of position over the bounding box
///    [lo, hi] of the written (float) positions: red = floor(255 (x - lo_x) /
///    (hi_x - lo_x) + 0.5), green the same of y, blue of z (0 where the box is flat);
///  - float nx, ny, nz: the unit outward normal of the surface, analytic from the
///    parametrisation: on the sphere the gradient of |p| - 1 - f(p / |p|) (f the
///    displacement), on the terrain (-h_x, -h_y, 1) normalised, on the parts the
///    normal of the box face, cylinder side or cap the vertex belongs to.
/// The vertices are then computed twice (the box first), still in O(1) memory.
/// Written as an OutputFile (a regular file: to a temporary name, renamed when
/// complete). Throws UsageError for options.triangles 0, IoError when writing fails.
GenerateResult generate_mesh(const std::string& path, const GenerateOptions& options);

}  // namespace oocsimp
