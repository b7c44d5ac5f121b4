// Reading back the PNGs `oocsimp render` writes, for the render tests.
#pragma once

#include <catch2/catch.hpp>
#include <png.h>
// jpeglib.h uses FILE and size_t without including their headers.
#include <cstdio>
#include <jpeglib.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

#include "oocsimp/render.hpp"

namespace oocsimp_test {

/// The PNG at `path`, decoded by libpng as 8-bit RGB.
inline oocsimp::Image read_png(const std::string& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  REQUIRE(png_image_begin_read_from_file(&png, path.c_str()) != 0);
  png.format = PNG_FORMAT_RGB;
  oocsimp::Image out;
  out.width = png.width;
  out.height = png.height;
  out.rgb.resize(PNG_IMAGE_SIZE(png));
  REQUIRE(png_image_finish_read(&png, nullptr, out.rgb.data(), 0, nullptr) != 0);
  return out;
}

/// The JPEG at `path`, decoded by libjpeg as 8-bit RGB.
inline oocsimp::Image read_jpeg(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  REQUIRE(f != nullptr);
  jpeg_decompress_struct info{};
  jpeg_error_mgr errors{};
  info.err = jpeg_std_error(&errors);
  jpeg_create_decompress(&info);
  jpeg_stdio_src(&info, f);
  jpeg_read_header(&info, TRUE);
  info.out_color_space = JCS_RGB;
  jpeg_start_decompress(&info);
  oocsimp::Image out;
  out.width = info.output_width;
  out.height = info.output_height;
  out.rgb.resize(std::size_t(out.width) * out.height * 3);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = out.rgb.data() + std::size_t(info.output_scanline) * out.width * 3;
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  std::fclose(f);
  return out;
}

/// The smallest box of pixels holding every pixel that is not white (x0 > x1 if none).
struct PixelBox {
  std::uint32_t x0 = ~0u, y0 = ~0u, x1 = 0, y1 = 0;
};
inline PixelBox covered_box(const oocsimp::Image& image) {
  PixelBox b;
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const std::uint8_t* p = &image.rgb[3 * (std::size_t(y) * image.width + x)];
      if (p[0] == 255 && p[1] == 255 && p[2] == 255) continue;
      b.x0 = std::min(b.x0, x);
      b.y0 = std::min(b.y0, y);
      b.x1 = std::max(b.x1, x);
      b.y1 = std::max(b.y1, y);
    }
  return b;
}

/// The pixels that are not the white background.
inline std::size_t non_white(const oocsimp::Image& image) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < image.rgb.size(); i += 3)
    n += !(image.rgb[i] == 255 && image.rgb[i + 1] == 255 && image.rgb[i + 2] == 255);
  return n;
}

}  // namespace oocsimp_test
