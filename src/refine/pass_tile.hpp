// One tile of one pass of the out-of-core edge collapse (Cignoni et al. 2003, OEMM:
// the mesh cut into cells that are simplified in core one by one, with the vertices
// their borders share held still).
//
// A pass cuts space into cubic tiles. A vertex belongs to the tile its position falls
// in, and a face goes to every tile that holds one of its corners, so a tile sees all
// the faces around each vertex it owns. An owned vertex none of whose faces reaches
// another tile may collapse; every other vertex is locked. The collapses of two tiles
// thus never share a face, and each is checked (link condition, flips, needles) on
// the whole of its neighbourhood, as in the whole mesh. A face whose corners the tile
// all owns comes out of it, changed or not; a face reaching other tiles is locked in
// all of them and comes out, unchanged, of the tile owning its first corner.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cluster/quadric.hpp"
#include "oocsimp/geometry.hpp"
#include "refine/edge_collapse.hpp"

namespace oocsimp {

/// A face between the passes.
struct PassFace {
  std::uint64_t index = 0;         ///< the face's index in the input: the order faces are taken in
  std::uint64_t v[3] = {0, 0, 0};  ///< its corners' vertex ids (their indices in the input)
  Vec3d p[3];                      ///< its corners' positions, in the run's frame
  UnitNormal normal;               ///< its normal in the input, for the flip check
};

/// A vertex between the passes: its quadric holds every face that ever met at it, and
/// the boundary planes of its edges. Its attribute values travel beside it.
struct PassVertex {
  std::uint64_t id = 0;
  Vec3d position;
  Quadric quadric;
};

/// What a tile holds in one pass.
struct TileMesh {
  std::vector<PassFace> faces;      ///< every face with a corner the tile owns, by ascending index
  std::vector<PassVertex> owned;    ///< the vertices the tile owns, by ascending id
  std::size_t attribute_count = 0;  ///< values per vertex in `attributes`
  std::vector<double> attributes;   ///< attribute_count per owned vertex
  /// The first pass: the owned vertices' quadrics are still to be summed from their
  /// faces, with the boundary planes of their edges (CollapseSettings::boundary_weight).
  bool first_pass = false;
  /// False for a sample of the pass, which only measures costs: every vertex is free,
  /// the other tiles' too, as if the tile were an open patch of the mesh (and without
  /// boundary planes, which would hold its cut edge).
  bool hold_border = true;
};

/// What a tile gives the next pass.
struct TileOutput {
  std::vector<PassFace> faces;     ///< the faces the tile gives out (see the file comment), by index
  std::vector<PassVertex> owned;   ///< its owned vertices still alive, by id
  std::vector<double> attributes;  ///< attribute_count per vertex of `owned`
  CollapseStats stats;
};

/// The collapses of `tile` in order of cost (collapse_state) until the next one's
/// cost is above settings.max_cost (or its error above settings.max_error) or none is left, its locked vertices held.
/// `cost_log` (if given) gets the cost of each collapse taken.
TileOutput collapse_pass_tile(const TileMesh& tile, const CollapseSettings& settings,
                              std::vector<double>* cost_log = nullptr);

}  // namespace oocsimp
