#include "render/legend.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "oocsimp/measure.hpp"

namespace oocsimp {

namespace {

// A 5 x 7 pixel font: per glyph seven rows, the top first, bit 4 the leftmost column.
// Only the characters the legend writes; any other is a space.
struct Glyph {
  char c;
  std::uint8_t rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}}, {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}}, {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}},
    {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}}, {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}}, {'g', {0x00, 0x00, 0x0F, 0x11, 0x0F, 0x01, 0x0E}},
    {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}}, {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}},
    {'p', {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}}, {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}}, {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}},
};
constexpr std::uint32_t kAdvance = 6;  // glyph columns and one of space
constexpr std::uint32_t kLines = 9;    // glyph rows and two of space

const Glyph* glyph(char c) {
  for (const Glyph& g : kFont)
    if (g.c == c) return &g;
  return nullptr;
}

void set_pixel(Image* image, std::int64_t x, std::int64_t y, std::uint32_t colour) {
  if (x < 0 || y < 0 || x >= std::int64_t(image->width) || y >= std::int64_t(image->height)) return;
  std::uint8_t* p = &image->rgb[3 * (std::size_t(y) * image->width + std::size_t(x))];
  p[0] = std::uint8_t(colour >> 16);
  p[1] = std::uint8_t(colour >> 8);
  p[2] = std::uint8_t(colour);
}

// `text` with its top left corner at (x, y), each font pixel `scale` pixels square.
void draw_text(Image* image, const std::string& text, std::int64_t x, std::int64_t y, std::uint32_t scale) {
  for (char c : text) {
    if (const Glyph* g = glyph(c))
      for (std::uint32_t row = 0; row < 7; ++row)
        for (std::uint32_t col = 0; col < 5; ++col)
          if (g->rows[row] >> (4 - col) & 1)
            for (std::uint32_t dy = 0; dy < scale; ++dy)
              for (std::uint32_t dx = 0; dx < scale; ++dx)
                set_pixel(image, x + std::int64_t(col * scale + dx), y + std::int64_t(row * scale + dy), 0x000000);
    x += kAdvance * scale;
  }
}

std::uint32_t font_scale(std::uint32_t height) { return height >= 600 ? 2 : 1; }

// The label of the ramp value `value`: in model units and as a percentage of the
// diagonal, each to three significant digits.
std::string label(double value, double diagonal) {
  char buf[64];
  if (diagonal > 0)
    std::snprintf(buf, sizeof buf, "%.3g (%.3g%%)", value, 100 * value / diagonal);
  else
    std::snprintf(buf, sizeof buf, "%.3g", value);
  return buf;
}

constexpr const char* kTitle[2] = {"distance to input", "(% of diagonal)"};
constexpr std::uint32_t kBar = 16;    // the bar's width, font pixels
constexpr std::uint32_t kMargin = 8;  // around the legend, font pixels
constexpr std::uint32_t kTick = 4;    // the ticks' length, font pixels

}  // namespace

ErrorRamp find_error_ramp(const std::vector<std::string>& comments) {
  ErrorRamp ramp;
  for (const std::string& line : comments) {
    std::istringstream in(line);
    std::string keyword, name, word;
    double top = 0, diagonal = 0;
    if (!(in >> keyword >> name) || keyword != "comment" || name != kErrorRampComment) continue;
    if (!(in >> top >> word >> diagonal) || word != kErrorDiagonalWord) continue;
    if (!std::isfinite(top) || !std::isfinite(diagonal) || top < 0 || diagonal < 0) continue;
    ramp.found = true;
    ramp.top = top;
    ramp.diagonal = diagonal;
  }
  return ramp;
}

std::uint32_t legend_width(std::uint32_t width, std::uint32_t height, const ErrorRamp& ramp) {
  const std::uint32_t s = font_scale(height);
  std::size_t label_chars = 0;
  for (int k = 0; k <= 4; ++k) label_chars = std::max(label_chars, label(k / 4.0 * ramp.top, ramp.diagonal).size());
  const std::uint32_t title = std::uint32_t(std::max(std::strlen(kTitle[0]), std::strlen(kTitle[1])));
  const std::uint32_t w =
      (2 * kMargin + std::max(title * kAdvance, kBar + kTick + 2 + std::uint32_t(label_chars) * kAdvance)) * s;
  // The legend needs its lines, and should leave the model most of the picture.
  if (height < 12 * kLines * s || 2 * w > width) return 0;
  return w;
}

void draw_error_legend(Image* image, const ErrorRamp& ramp) {
  const std::uint32_t w = legend_width(image->width, image->height, ramp);
  if (w == 0) return;
  const std::uint32_t s = font_scale(image->height);
  const std::int64_t left = std::int64_t(image->width - w + kMargin * s);
  // The title's two lines, then the bar from there to a margin above the bottom.
  draw_text(image, kTitle[0], left, std::int64_t(kMargin * s), s);
  draw_text(image, kTitle[1], left, std::int64_t((kMargin + kLines) * s), s);
  const std::int64_t bar_top = std::int64_t((kMargin + 2 * kLines + 6) * s);
  const std::int64_t bar_bottom = std::int64_t(image->height) - std::int64_t((kMargin + 6) * s);
  const std::int64_t bar_w = std::int64_t(kBar * s);
  const double span = double(bar_bottom - bar_top);
  for (std::int64_t y = bar_top; y <= bar_bottom; ++y) {
    const std::uint32_t c = error_ramp_colour(span > 0 ? double(bar_bottom - y) / span : 0);
    for (std::int64_t x = left; x < left + bar_w; ++x) set_pixel(image, x, y, c);
  }
  for (int k = 0; k <= 4; ++k) {
    const double t = k / 4.0;
    const std::int64_t y = bar_bottom - std::int64_t(std::lround(t * span));
    for (std::int64_t x = left + bar_w; x < left + bar_w + std::int64_t(kTick * s); ++x)
      for (std::uint32_t dy = 0; dy < s; ++dy) set_pixel(image, x, y + std::int64_t(dy), 0x000000);
    draw_text(image, label(t * ramp.top, ramp.diagonal), left + bar_w + std::int64_t((kTick + 2) * s),
              y - std::int64_t(3 * s), s);
  }
}

}  // namespace oocsimp
