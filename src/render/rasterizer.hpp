// The rasteriser behind render_file, on an opened input.
#pragma once

#include "io/mesh_input.hpp"
#include "oocsimp/render.hpp"

namespace oocsimp {

/// Draws the triangles, edges and points of `input` (one pass over its triangle
/// stream) as seen from the options' view, framing its bounding box. An empty mesh gives the background.
/// Throws UsageError on a bad size, InputError from the reader.
Image render_mesh(MeshInput& input, const RenderOptions& options, RenderStats* stats = nullptr);

}  // namespace oocsimp
