// Pass 2 of floating cells, second half: the border decisions between tiles, first
// greedy and colour sweeps until no border changes. See docs/design.md,
// "Tiles and rounds".
#pragma once

#include <cstdint>
#include <vector>

#include "cluster/floating_cells.hpp"
#include "cluster/vertex_grading.hpp"
#include "grid/tile_grid.hpp"
#include "grid/grid_spec.hpp"
#include "grid/work_share.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"
#include "spill/block_store.hpp"

namespace oocsimp {

/// Per tile, the centres of a tile's cells that reach outside its box (the only ones
/// that can cover a neighbour's vertex).
using TileBorders = std::vector<std::vector<GradedVertex>>;

/// The external centres of `tile`: its neighbours' border centres whose cells can
/// reach into its box (within `half` a cell of it, widened by a rounding margin;
/// contains() decides exactly), in precedes order.
std::vector<GradedVertex> external_centres(const TileGrid& grid, std::uint32_t tile, const TileBorders& borders,
                                           double half);

/// The centres of `tile` (its `centres`) whose cells, of half side `half`, reach outside it.
std::vector<GradedVertex> border_of(const TileGrid& grid, std::uint32_t tile, const std::vector<GradedVertex>& centres,
                                    double half);

/// The border state of the rounds: every tile's published border and the external
/// centres it last ran with.
class BorderDecisions {
 public:
  BorderDecisions(const TileGrid& grid, const FloatingCellShape& cell);

  /// The first greedy over a tile's graded vertices (in precedes order), with the
  /// border centres its neighbours published so far: its centres (which live on in
  /// the tile's vertex block only); publishes its border. Tiles of one colour class
  /// may call it at once.
  std::vector<GradedVertex> choose_first(std::uint32_t tile, const std::vector<GradedVertex>& sorted);

  /// Parts that run at once, after each graded its own tiles: every part's borders
  /// to every part (share.exchange), so that each holds every tile's.
  void gather_borders(const TileShare& share);

  /// Sweeps by colour class until no tile's external input changes; updates the
  /// decisions in the vertex blocks of `blocks` in place. `stats` (may be null) gets
  /// `rounds` and the per-sweep counts. With `share` exchanging, only the part's own
  /// tiles run (and have blocks), and the parts exchange their changed borders after
  /// each colour class; the counts are then the part's own.
  void sweep(BlockStore& blocks, FloatingStats* stats, const TileShare* share = nullptr);

  /// The settled borders (after sweep()), for the assignment; the state is spent.
  TileBorders take_borders() {
    TileBorders().swap(ext_);
    return std::move(border_);
  }

 private:
  const TileGrid& grid_;
  FloatingCellShape cell_;
  double half_;
  TileBorders border_;  // per tile, its centres whose cells reach outside it
  TileBorders ext_;     // per tile, the external centres it last ran with
};

}  // namespace oocsimp
