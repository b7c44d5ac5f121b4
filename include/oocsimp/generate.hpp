// oocsimp — synthetic dense meshes of any size (target oocsimp::generate, not part of
// the core library).
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>

#include "oocsimp/enum_names.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

enum class SyntheticShape { sphere, terrain, parts, branches, boxes, holes, soup };

/// The branches shape's dimensions (model units): the trunk's radius, the thin
/// branches' radius and count, the buds' radius.
constexpr double kBranchTrunkRadius = 0.035;
constexpr double kBranchRadius = 0.005;
constexpr int kBranchCount = 24;
constexpr double kBudRadius = 0.004;

/// The boxes shape: one box per this many triangles asked, at most kBoxesMostCount.
constexpr std::uint64_t kBoxesTrianglesEach = 6500;
constexpr std::uint64_t kBoxesMostCount = 26;

struct GenerateOptions {
  std::uint64_t triangles = 1000000;  ///< target; the result is within 2% for 10^4 and more
  SyntheticShape shape = SyntheticShape::sphere;
  std::uint64_t seed = 1;
  bool ascii = false;  ///< ascii PLY instead of binary little-endian
  /// Every vertex also gets uchar red, green, blue and float nx, ny, nz (see
  /// generate_mesh); without it the file is what it always was, byte for byte.
  bool attributes = false;
  /// Progress ("generate", in triangles), and cancellation (see ProgressCallback).
  ProgressCallback progress;
};

struct GenerateResult {
  std::uint64_t vertices = 0;
  std::uint64_t triangles = 0;
};

/// Streams a synthetic mesh to `path` as PLY (".zst" compresses) in O(1) memory,
/// deterministically from the seed:
///  - sphere: a closed genus-0 surface (latitude-longitude tessellation) displaced by
///    a sum of seeded sinusoids of several frequencies;
///  - terrain: an open height field over the unit square with a boundary;
///  - parts: intersecting boxes and cylinders with sharp edges and small features;
///  - branches: a leafless tree (Low & Tan 1997, Plate 3) in the unit cube: a trunk
///    (a closed cylinder of radius kBranchTrunkRadius along z from (0.5, 0.5, 0) up
///    0.45), kBranchCount closed cylinders of radius kBranchRadius and length 0.25 to
///    0.4 leaving its axis upwards, and past every other tip, 0.02 beyond it, a closed
///    ball of radius kBudRadius: thin parts that vertex clustering reduces to edges and
///    points. At least 2000 triangles' worth, however few are asked;
///  - boxes: a city block in the unit square: min(kBoxesMostCount, triangles /
///    kBoxesTrianglesEach) (at least 1) closed axis-aligned boxes of random sizes on
///    z = 0, apart from one another, each one closed 2-manifold facing outwards whose
///    flat faces are tessellated into long thin triangles (4 cells up the walls, top
///    cells 4 times longer one way than the other), with about 12 zero-area slivers a
///    box (three collinear corners: an edge split at its midpoint on one side, the
///    T-junction closed by the sliver), as CAD exports leave them;
///  - holes: a bumpy torus (major radius 1, minor 0.4, displaced by seeded sinusoids) of
///    square quads with hundreds of holes, as scans have: nine in ten 3 x 3 blocks of
///    cells lose their middle cell (half the time with the cell after it along u, v or
///    both), and one 9 x 9 super-block in three instead holds a round hole of radius
///    1.5 to 3.5 cells. Holes never touch: every edge has one or two faces,
///    consistently oriented, and every vertex one fan. About a sixth of the edges are
///    on the holes' outlines. Only vertices a face uses are written;
///  - soup: the terrain's height field exported nearly as a triangle soup: blocks of
///    4 x 4 cells, four in five welded (their own lattice of vertices, one cell in ten
///    with a fin, a triangle standing on the cell's diagonal: an edge of three faces),
///    the rest unwelded (each triangle its own three vertices, one cell in twenty with
///    an exact unwelded copy of its first triangle, one in twenty with a jittered copy
///    overlapping it). About half the edges have one face.
/// With `attributes`, each vertex follows x, y, z with
///  - uchar red, green, blue: a linear function of position over the bounding box
///    [lo, hi] of the written (float) positions: red = floor(255 (x - lo_x) /
///    (hi_x - lo_x) + 0.5), green the same of y, blue of z (0 where the box is flat);
///  - float nx, ny, nz: the unit outward normal of the surface, analytic from the
///    parametrisation: on the sphere the gradient of |p| - 1 - f(p / |p|) (f the
///    displacement), on the terrain (-h_x, -h_y, 1) normalised, on the parts the
///    normal of the box face, cylinder side or cap the vertex belongs to, on the
///    boxes the normalised sum of the outward normals of the faces through the vertex,
///    on the holes the normal of the displaced torus, on the soup the terrain's at the
///    corner's (x, y) (level across the diagonal for a fin's apex).
/// The vertices are then computed twice (the box first), still in O(1) memory.
/// Written as an OutputFile (a regular file: to a temporary name, renamed when
/// complete). Throws UsageError for options.triangles 0, IoError when writing fails.
OOCSIMP_API GenerateResult generate_mesh(const std::string& path, const GenerateOptions& options);

/// The shapes as the command line spells them, the default first.
OOCSIMP_API const EnumNames<SyntheticShape>& synthetic_shape_names();

}  // namespace oocsimp
