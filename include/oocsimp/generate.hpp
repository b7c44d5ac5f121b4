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
/// Written as an OutputFile (a regular file: to a temporary name, renamed when
/// complete). Throws UsageError for options.triangles 0, IoError when writing fails.
GenerateResult generate_mesh(const std::string& path, const GenerateOptions& options);

}  // namespace oocsimp
