// oocsimp — picking a level of detail by viewing distance (Low & Tan 1997 §4).
//
// A chain of levels (simplify --lods) is described by OUT.lods.json: per
// level its file and clustering cell. At distance D from a camera of vertical field of
// view FOV drawing H pixels, one pixel spans R = 2 D tan(FOV / 2) / H model units; a
// level whose cell spans at most X pixels (cell <= X R) differs from the full model by
// at most about X pixels on the screen.
#pragma once

#include "oocsimp/export.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace oocsimp {

/// One level of detail, as OUT.lods.json lists it.
struct LodLevel {
  std::string file;  ///< as written in the JSON (relative to its folder)
  double cell = 0;   ///< clustering cell, model units
  std::uint64_t vertices = 0, triangles = 0, edges = 0, points = 0;
  double seconds = 0;  ///< the level's wall time (the first level's includes opening, binning and grading)
  std::vector<std::pair<std::string, double>> phases;  ///< seconds per phase (SimplifyStats::phases)
  /// Symmetric RMS and Hausdorff distance to the input (measure), model units; -1
  /// when not measured.
  double rms = -1, hausdorff = -1;
};

/// The levels as OUT.lods.json: {"levels": [{"file", "cell", "vertices",
/// "triangles", "edges", "points", "seconds", "phases" {name: seconds}, and "rms" and
/// "hausdorff" when
/// measured}, ...]}, numbers written so that they read back exactly.
OOCSIMP_API std::string lod_levels_json(const std::vector<LodLevel>& levels);

/// Writes lod_levels_json to `path` under a temporary name, renamed when complete.
/// Throws IoError.
OOCSIMP_API void write_lod_levels(const std::string& path, const std::vector<LodLevel>& levels);

/// Reads OUT.lods.json: {"levels": [{"file": ..., "cell": ..., "vertices": ...,
/// "triangles": ..., "edges": ..., "points": ...}, ...]} (other members are read past).
/// Throws InputError naming the file and what is wrong, IoError when it cannot be read.
OOCSIMP_API std::vector<LodLevel> read_lod_levels(const std::string& path);

/// Low & Tan's object-space-to-pixel-space ratio R = 2 D tan(FOV / 2) / H: the model
/// units one pixel spans at `distance` (model units) with a vertical field of view of
/// `fov_degrees` over `height_pixels`. Throws UsageError unless D > 0, 0 < FOV < 180
/// and H >= 1.
OOCSIMP_API double pixel_size_at(double distance, double fov_degrees, double height_pixels);

/// The level to draw for pixel size `pixel` (R) and relaxation `factor` (X >= 1): the
/// coarsest level whose cell is at most X R (Low & Tan §4, "one-cell-width-to-X-pixel-
/// width"), or, when even the finest is coarser, the finest with `finest_too_coarse`.
struct LodChoice {
  std::size_t level = 0;
  bool finest_too_coarse = false;
};
OOCSIMP_API LodChoice choose_lod(const std::vector<LodLevel>& levels, double pixel, double factor);

/// The choice as one JSON object: level, file, cell, pixel_size (R), factor,
/// thick_line_pixels_per_unit (1 / R: an edge of thickness T is drawn T / R pixels
/// wide, Low & Tan §4) and finest_too_coarse.
OOCSIMP_API std::string lod_choice_json(const std::vector<LodLevel>& levels, const LodChoice& choice, double pixel,
                                        double factor);

}  // namespace oocsimp
