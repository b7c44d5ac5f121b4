// Reading back the PNGs `oocsimp render` writes, for the render tests.
#pragma once

#include <catch2/catch.hpp>
#include <png.h>

#include <cstddef>
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

/// The pixels that are not the white background.
inline std::size_t non_white(const oocsimp::Image& image) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < image.rgb.size(); i += 3)
    n += !(image.rgb[i] == 255 && image.rgb[i + 1] == 255 && image.rgb[i + 2] == 255);
  return n;
}

}  // namespace oocsimp_test
