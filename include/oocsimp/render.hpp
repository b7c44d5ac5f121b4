// oocsimp — pictures of a mesh file, to compare inputs, levels and results by eye on a
// machine without a display: a headless software rasteriser.
//
// The triangles are streamed from the file, projected orthographically and
// drawn into a depth buffer one at a time, so memory is the image's (about 8 bytes a
// pixel) whatever the mesh's size. No GPU, display or OpenGL is involved.
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/enum_names.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

enum class Shading : std::uint8_t {
  flat,    ///< each face by its own normal
  smooth,  ///< by the file's vertex normals (nx, ny, nz), interpolated; flat without them
};

/// The model's up axis: z for scans and CAD in z-up frames, y for most scanners' and
/// glTF's (y-up) frames, x for the rest; automatic picks one from the surface
/// (choose_up_axis).
enum class UpAxis : std::uint8_t { automatic, z, y, x };

struct RenderOptions {
  std::uint32_t width = 1024, height = 768;  ///< pixels, 1 to 16384 each
  /// The direction the camera looks from, in degrees: azimuth about the up axis (from
  /// +x about +z, from +z about +y, from +y about +x), elevation above the plane of the
  /// other two (90: from straight above, looking down the up axis).
  double azimuth_degrees = 30, elevation_degrees = 20;
  /// Which axis is up on the screen.
  UpAxis up = UpAxis::automatic;
  Shading shading = Shading::flat;
  /// The file's edges and points (LinePrimitive): with thick_edges, an edge of
  /// thickness T is drawn T / R pixels wide and a point as a disc T / R pixels across,
  /// R the pixel size (Low & Tan 1997 §3.3, §4), at least one pixel; without, one
  /// pixel wide. Either way a line is lit by Low & Tan's dynamic normal (§3.3.2: in
  /// the plane of the edge and the view, across the edge), turned across the line's
  /// width as a cylinder's, and a disc as a sphere.
  bool thick_edges = false;
  /// The background's and the surface's colour, 0xRRGGBB. Faces are lit by a light at
  /// the camera: surface x (0.2 + 0.8 |cos|) of the angle to the view, both sides alike.
  std::uint32_t background = 0xFFFFFF, surface = 0xB4B4BE;
  ProgressCallback progress;  ///< phase "render" (input bytes)
};

/// An RGB image, 3 bytes a pixel, rows from the top.
struct Image {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
};

struct RenderStats {
  std::uint64_t triangles = 0;          ///< triangles read
  std::uint64_t edges = 0, points = 0;  ///< thick edges and points read
  std::uint64_t covered_pixels = 0;     ///< pixels the surface covers
  /// The size of a pixel in model units: the camera frames the model's projected
  /// outline (its vertices as seen, and with thick edges their widths), centred, x 1.05
  /// across the image's width or height, whichever it fills first.
  double pixel_size = 0;
  UpAxis up = UpAxis::z;  ///< the up axis drawn: the one asked for, or the one chosen
  /// The input was a mesh coloured by its error (measure --error-colours: vertex
  /// colours and the "error_ramp" comment), drawn in its colours with the ramp's
  /// legend at the right: the ramp, its values in model units and as a percentage of
  /// the input's diagonal. Faces are then lit 0.5 + 0.5 |cos|, and the model is framed
  /// in the width the legend leaves.
  bool legend = false;
};

/// `image` as PNG bytes (8-bit RGB, through libpng).
OOCSIMP_API std::string encode_png(const Image& image);
/// `image` as baseline JPEG bytes (JFIF, 8-bit YCbCr, through libjpeg) at `quality`,
/// 1 to 100 (UsageError otherwise).
OOCSIMP_API std::string encode_jpeg(const Image& image, int quality = 90);

enum class ImageFormat : std::uint8_t { png, jpeg };

/// The format a picture at `path` is written in, by its extension (any case): .png,
/// or .jpg and .jpeg for JPEG; stdout ("-") and an existing device or FIFO get PNG.
/// Throws UsageError for any other name, so that no file's bytes contradict its name.
OOCSIMP_API ImageFormat image_format_for_path(const std::string& path);

/// Opens `input` (converted positions and stream copies go under `temp_dir`, empty:
/// the default temporary directory), renders it and writes the picture, PNG or JPEG by
/// image_format_for_path (checked before anything is opened), to `output` under a
/// temporary name, renamed when complete (the output is opened first: a bad folder
/// fails before the work). Throws UsageError (output = input, a name of neither
/// format), InputError, IoError.
OOCSIMP_API RenderStats render_file(const std::string& input, const std::string& output, const RenderOptions& options,
                                    const std::string& temp_dir = {});

/// The shadings as the command line spells them, the default first.
OOCSIMP_API const EnumNames<Shading>& shading_names();
/// The up axes as the command line spells them ("auto", "z", "y", "x"), the default first.
OOCSIMP_API const EnumNames<UpAxis>& up_axis_names();

}  // namespace oocsimp
