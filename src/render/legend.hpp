// The legend render draws beside a mesh coloured by its error (measure
// --error-colours): the colour ramp, its values in model units and as a percentage of
// the input's diagonal, in a built-in pixel font, so that no font library is needed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/render.hpp"

namespace oocsimp {

/// The ramp's end and the input's diagonal, from the PLY comment measure writes
/// ("error_ramp MAX diagonal D"); found is false when the comments have none.
struct ErrorRamp {
  bool found = false;
  double top = 0, diagonal = 0;
};
ErrorRamp find_error_ramp(const std::vector<std::string>& comments);

/// Pixels the legend of `ramp` takes at the right of an image `width` x `height`: its
/// widest line and the bar (0 when the image is too small to hold it: then none is
/// drawn).
std::uint32_t legend_width(std::uint32_t width, std::uint32_t height, const ErrorRamp& ramp);

/// Draws the legend into the rightmost legend_width() columns of `image`: a title, a
/// bar of the ramp (0 at the bottom, ramp.top at the top) and five labels "VALUE
/// (PERCENT%)" along it.
void draw_error_legend(Image* image, const ErrorRamp& ramp);

}  // namespace oocsimp
