// The rasteriser behind render_file, on an opened input.
#pragma once

#include "io/mesh_input.hpp"
#include "oocsimp/render.hpp"

namespace oocsimp {

/// Draws the triangles, edges and points of `input` (one pass over its triangle
/// stream, one more when the up axis is chosen and one more with thick edges) as seen
/// from the options' view, framing its projected outline (one pass over its
/// positions). An empty mesh gives the background.
/// Throws UsageError on a bad size, InputError from the reader.
/// The up axis of a surface, for UpAxis::automatic (one pass over the triangles): the
/// axis nearest the sum of its area-weighted normals where that sum is at least a
/// tenth of its area, as for a terrain, a facade or a scan open at its base (the
/// missing underside leaves the sum pointing up); else the axis of a closed surface's
/// base when it stands out; else y for glTF (y-up by its specification) and z for the
/// rest.
UpAxis choose_up_axis(MeshInput& input);

Image render_mesh(MeshInput& input, const RenderOptions& options, RenderStats* stats = nullptr);

}  // namespace oocsimp
