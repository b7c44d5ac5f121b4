// PNG through libpng (Debian's libpng-dev): the well-kept encoder, not a hand-written one.
#include <png.h>

#include <string>

#include "io/temp_file.hpp"
#include "runtime/progress_phase.hpp"
#include "oocsimp/error.hpp"
#include "render/rasterizer.hpp"

namespace oocsimp {

namespace {

void append(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

void no_flush(png_structp) {}

[[noreturn]] void fail(png_structp, png_const_charp message) { throw IoError(std::string("PNG: ") + message); }

void ignore_warning(png_structp, png_const_charp) {}

}  // namespace

std::string encode_png(const Image& image) {
  std::string bytes;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, fail, ignore_warning);
  if (!png) throw IoError("PNG: out of memory");
  png_infop info = png_create_info_struct(png);
  try {
    if (!info) throw IoError("PNG: out of memory");
    png_set_write_fn(png, &bytes, append, no_flush);
    png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 9);
    png_write_info(png, info);
    for (std::uint32_t y = 0; y < image.height; ++y)
      png_write_row(png, const_cast<png_bytep>(image.rgb.data() + std::size_t(y) * image.width * 3));
    png_write_end(png, nullptr);
  } catch (...) {
    png_destroy_write_struct(&png, &info);
    throw;
  }
  png_destroy_write_struct(&png, &info);
  return bytes;
}

RenderStats render_file(const std::string& input, const std::string& output, const RenderOptions& options,
                        const std::string& temp_dir) {
  if (input != "-" && output != "-" && same_file(input, output))
    throw UsageError(output + ": the picture would overwrite its input");
  OutputFile file(output);
  OpenOptions open;
  open.temp_dir = temp_dir;
  open.progress = options.progress;
  MeshInput mesh = open_mesh_input(input, open);
  RenderStats stats;
  const Image image = render_mesh(mesh, options, &stats);
  ProgressPhase phase(options.progress, "write", 0, "B");
  file.write_all(encode_png(image));
  file.commit();
  return stats;
}

}  // namespace oocsimp
