// PNG through libpng (Debian's libpng-dev) and JPEG through libjpeg-turbo (Debian's
// libjpeg62-turbo-dev): the well-kept encoders, not hand-written ones.
#include <png.h>
// jpeglib.h uses FILE and size_t without including their headers.
#include <cstdio>
#include <jpeglib.h>

#include <cctype>
#include <cstdlib>
#include <string>
#include <sys/stat.h>

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

// libjpeg reports errors through a callback that must not return: it throws, and
// encode_jpeg destroys the compressor on the way out.
[[noreturn]] void jpeg_fail(j_common_ptr info) {
  char message[JMSG_LENGTH_MAX];
  (*info->err->format_message)(info, message);
  throw IoError(std::string("JPEG: ") + message);
}

void jpeg_ignore(j_common_ptr, int) {}

bool ends_with(const std::string& name, const char* ext) {
  const std::string e(ext);
  if (name.size() < e.size()) return false;
  for (std::size_t i = 0; i < e.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(name[name.size() - e.size() + i])) != e[i]) return false;
  return true;
}

}  // namespace

ImageFormat image_format_for_path(const std::string& path) {
  if (ends_with(path, ".png")) return ImageFormat::png;
  if (ends_with(path, ".jpg") || ends_with(path, ".jpeg")) return ImageFormat::jpeg;
  // A stream has no name to go by: PNG, lossless.
  struct stat st {};
  if (path == "-" || (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)))
    return ImageFormat::png;
  throw UsageError(path + ": render writes PNG (.png) or JPEG (.jpg, .jpeg): give a name with one of those endings");
}

std::string encode_jpeg(const Image& image, int quality) {
  if (quality < 1 || quality > 100) throw UsageError("quality", "the JPEG quality must be 1 to 100");
  jpeg_compress_struct info{};
  jpeg_error_mgr errors{};
  info.err = jpeg_std_error(&errors);
  errors.error_exit = jpeg_fail;
  errors.emit_message = jpeg_ignore;
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  std::string bytes;
  try {
    jpeg_create_compress(&info);
    jpeg_mem_dest(&info, &buffer, &size);
    info.image_width = image.width;
    info.image_height = image.height;
    info.input_components = 3;
    info.in_color_space = JCS_RGB;
    jpeg_set_defaults(&info);
    jpeg_set_quality(&info, quality, TRUE);
    jpeg_start_compress(&info, TRUE);
    while (info.next_scanline < info.image_height) {
      JSAMPROW row = const_cast<JSAMPROW>(image.rgb.data() + std::size_t(info.next_scanline) * image.width * 3);
      jpeg_write_scanlines(&info, &row, 1);
    }
    jpeg_finish_compress(&info);
    bytes.assign(reinterpret_cast<const char*>(buffer), size);
  } catch (...) {
    jpeg_destroy_compress(&info);
    std::free(buffer);
    throw;
  }
  jpeg_destroy_compress(&info);
  std::free(buffer);
  return bytes;
}

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
  const ImageFormat format = image_format_for_path(output);
  OutputFile file(output);
  OpenOptions open;
  open.temp_dir = temp_dir;
  open.progress = options.progress;
  MeshInput mesh = open_mesh_input(input, open);
  RenderStats stats;
  const Image image = render_mesh(mesh, options, &stats);
  ProgressPhase phase(options.progress, "write", 0, "B");
  file.write_all(format == ImageFormat::jpeg ? encode_jpeg(image) : encode_png(image));
  file.commit();
  return stats;
}

}  // namespace oocsimp
