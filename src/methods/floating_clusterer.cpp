// Floating-cell clustering out of core: tiles, sweeps of border decisions,
// partition-independent sums and a stitch of the cross-tile triangles.
// floating_cells_design.md explains why the result equals the sequential algorithm.
//
// The stages hand each other typed results:
//   plan + bin   grid/tile_plan, grid/tile_binning: every triangle goes to the tile of
//                each of its corners (BinnedTiles); or the tiles kept by an earlier
//                run (--keep-tmp, cluster/kept_tiles)
//   grade        cluster/tile_grading: per tile, colour class by colour class, grade
//                the owned vertices (Low & Tan §3.1), sort them (§3.2) and run the
//                first greedy with the borders published so far, into a vertex block
//   sweep        cluster/centre_sweeps: the neighbours' border centres until no
//                border changes (the decided centres)
//   accumulate   cluster/cluster_accumulation: per tile, assign vertices to centres,
//                add vertex quadrics to clusters in fixed point, keep the triangles
//                that span three clusters (ClusterShares)
//   stitch       stitch/mesh_assembly: the triangles that cross tiles joined by index
//   assemble     stitch/mesh_assembly: representatives; output triangles in input
//                order of first occurrence
#include "methods/floating_clusterer.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cluster/centre_sweeps.hpp"
#include "cluster/cluster_accumulation.hpp"
#include "cluster/floating_cells.hpp"
#include "cluster/kept_tiles.hpp"
#include "cluster/tile_grading.hpp"
#include "common/phase_timer.hpp"
#include "grid/tile_binning.hpp"
#include "grid/tile_memory_gate.hpp"
#include "grid/tile_plan.hpp"
#include "report/memory_usage.hpp"
#include "report/progress_phase.hpp"
#include "stitch/mesh_assembly.hpp"

namespace oocsimp {

namespace {

// The tiles' buffers of a phase are freed at its end; let the caller's allocator
// give them back before the next (see SimplifyOptions::release_memory).
void release_memory(const SimplifyOptions& options) {
  if (options.release_memory) options.release_memory();
}

// The graded vertices of every tile, kept for --keep-tmp. They barely compress
// (positions and weights are noise to zstd: 422 vs 498 MiB for the whole spill of
// the 10M sphere, when every round read it).
std::unique_ptr<StreamSpill> graded_vertex_spill(const BinnedTiles& tiles, const SpillSettings& spill) {
  auto graded = std::make_unique<StreamSpill>(spill.dir, "vertices", sizeof(GradedVertex), 4096, false);
  graded->set_expected_bytes(spill.expected_bytes);
  for (std::uint32_t i = 0; i < tiles.count(); ++i) graded->add_stream();
  return graded;
}

// An uneven input can put many times the planned triangles into its fullest tile
// (1.19M records against the planned 65k on the generated 100M parts mesh), whose
// working set then does not fit --mem even alone: the run stops (exit 2) before
// grading, naming what it would take, rather than exceed the budget.
void check_fullest_tile_fits(const MemoryBudget& budget, const BinnedTiles& tiles, const std::string& path) {
  const std::uint64_t records = tiles.largest_tile_records();
  const std::uint64_t need = records * kTileBytesPerRecord;
  const std::uint64_t held = budget.held();
  budget.check(held, need,
               "the fullest tile of " + path + " (" + std::to_string(records) + " triangle records, " +
                   whole_mib(need) + " MiB to grade)",
               "a dense part of the mesh: give options.memory_budget " + whole_mib(held + need + need / 4) +
                   " MiB or more, or a larger options.sizing.cell (options.sizing.grid, options.sizing.ratio)");
}

}  // namespace

SimplifiedMesh cluster_floating(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                                SimplifyStats* stats, std::vector<Quadric>* quadrics) {
  SimplifiedMesh out;
  cluster_floating_levels(
      input, options, {grid},
      [&](std::size_t, SimplifiedMesh& m, SimplifyStats& s) {
        out = std::move(m);
        if (stats) *stats = std::move(s);
      },
      stats ? *stats : SimplifyStats(), quadrics);
  return out;
}

void cluster_floating_levels(MeshInput& input, const SimplifyOptions& given, const std::vector<GridSpec>& grids,
                             const FloatingLevelSink& sink, const SimplifyStats& base, std::vector<Quadric>* quadrics) {
  SimplifyOptions options = given;
  const MemoryBudget budget(options);  // the output's check, at the end
  if (options.memory_budget == 0) options.memory_budget = default_memory_budget();
  // Binning and grading do not depend on the cell (kept_tiles.hpp): the tiles fit the
  // coarsest level, and every level clusters the same graded tiles.
  double coarsest = 0;
  for (const GridSpec& g : grids) coarsest = std::max(coarsest, g.cell);
  const FloatingCellShape first_cell{grids.front().cell, options.floating.cell_shape};
  PhaseTimer clock;  // the first level's phases begin with the binning (or resumption) and grading

  // The tiled mesh: kept by an earlier run, or binned.
  std::vector<std::string> warnings;  // the kept tiles', reported with the first level
  KeptTileStore kept(input, options.temp_dir.empty() ? default_temp_dir() : options.temp_dir, &warnings);
  BinnedTiles tiles;
  std::unique_ptr<StreamSpill> graded;  // --keep-tmp: every tile's graded vertices
  const bool resumed = options.floating.keep_temp && kept.resume(coarsest, &tiles, &graded);
  const bool keeping = options.floating.keep_temp && !resumed && kept.start();
  // The tiles' share of the budget holds the fullest tile as planned (known exactly
  // when resumed); the spills' allowances come after it.
  const double tile_side = resumed ? 0 : plan_tile_side(input, options, coarsest);
  const std::uint64_t fullest =
      resumed ? tiles.largest_tile_records() : estimate_fullest_tile_records(input, std::max(tile_side, coarsest));
  const SpillSettings spill = spill_settings(input, options, sizeof(GradedVertex), fullest);
  if (!resumed) tiles = bin_triangles(input, tile_side, options.memory_budget, spill, options.progress);
  clock.end(resumed ? "resume" : "bin");
  release_memory(options);  // the binning chunks
  // The fullest tile is known now; it must fit in the budget next to what the run
  // holds, even alone (TileMemoryGate runs it alone).
  const std::uint64_t work_share = spill.work_share;
  check_fullest_tile_fits(budget, tiles, input.info.path);

  // Graded vertex blocks with the first level's first greedy.
  auto decisions = std::make_unique<BorderDecisions>(tiles.grid, first_cell);
  FirstChoice first = [&](std::uint32_t tile, const std::vector<GradedVertex>& sorted) {
    return decisions->choose_first(tile, sorted);
  };
  std::unique_ptr<BlockStore> blocks;
  if (resumed) {
    blocks = blocks_from_kept(tiles.grid, *graded, first, {first_cell.size, spill.dir, spill.allow.vertex_blocks});
  } else {
    if (options.floating.keep_temp) graded = graded_vertex_spill(tiles, spill);
    const GradingSettings grading{
        {first_cell.size, spill.dir, spill.allow.vertex_blocks}, graded.get(), &options.progress, work_share};
    blocks = grade_tiles(tiles, input.positions, first, grading);
    if (keeping) kept.keep(tiles, *graded);
  }
  release_memory(options);  // the tiles' grading buffers
  clock.end("grade");

  for (std::size_t level = 0; level < grids.size(); ++level) {
    const FloatingCellShape cell{grids[level].cell, options.floating.cell_shape};
    if (level > 0) {
      // Every later level re-runs its first greedy from the graded vertices.
      clock.restart();
      // This level's first greedy over the graded vertices of the level before.
      decisions = std::make_unique<BorderDecisions>(tiles.grid, cell);
      // Both levels' blocks exist at once: the new ones get what the old ones leave
      // of the blocks' allowance.
      std::unique_ptr<BlockStore> before = std::move(blocks);
      const std::uint64_t held = before->bytes_in_memory();
      const std::uint64_t allowance = spill.allow.vertex_blocks > held ? spill.allow.vertex_blocks - held : 0;
      blocks = blocks_from_blocks(tiles.grid, *before, first, {cell.size, spill.dir, allowance});
      before->discard();
      clock.end("regrade");
    }
    SimplifyStats stats = base;
    {
      ProgressPhase phase(options.progress, "rounds", 0, "round");
      decisions->sweep(*blocks, &stats);
    }
    clock.end("rounds");
    TileBorders borders = decisions->take_borders();
    release_memory(options);

    // Cluster shares and kept triangles.
    AccumulationSettings acc{cell,       options.floating.assign, options.memory_budget,
                             spill,      &options.progress,       &input.attributes,
                             work_share, options.thick_edges};
    ClusterShares shares = accumulate_clusters(tiles, input.positions, *blocks, borders, input.positions.count, acc);
    // Centres live on in the cluster records; the per-tile lists are done, and the
    // memory of the triangles (after the last level) and vertex blocks goes to the
    // output tables.
    TileBorders().swap(borders);
    const bool last = level + 1 == grids.size();
    if (last) {  // a next level reads the triangles again and grades from the blocks
      tiles.triangles->discard();
      blocks->discard();
    }
    release_memory(options);
    clock.end("cluster");

    std::vector<KeptTriangle> kept_triangles;
    {
      ProgressPhase phase(options.progress, "stitch", 0, "bucket");
      CrossTileEdges cross{&input.positions, cell.size, shares.edge_shares.get(), shares.cluster_span};
      kept_triangles =
          stitch_kept_triangles(*shares.inside, *shares.corners, budget, options.thick_edges ? &cross : nullptr);
    }
    shares.corners->discard();  // read into kept_triangles
    shares.inside->discard();
    clock.end("stitch");
    SimplifiedMesh m;
    AssemblyCounts counts;
    {
      ProgressPhase phase(options.progress, "assemble", 0, "cell");
      const ThickAssembly thick{shares.edge_shares.get(), &input.positions};
      const AssemblySettings assembly{cell,
                                      options.floating.representative,
                                      budget,
                                      shares.attribute_shares.get(),
                                      &shares.attributes,
                                      options.thick_edges ? &thick : nullptr,
                                      grids[level].origin};
      m = assemble_mesh(std::move(kept_triangles), *shares.partials, assembly, &counts, quadrics);
    }
    clock.end("assemble");

    const StreamSpill* spills[] = {tiles.triangles.get(),   graded.get(),        shares.corners.get(),
                                   shares.partials.get(),   shares.inside.get(), shares.attribute_shares.get(),
                                   shares.edge_shares.get()};
    stats.spill_bytes = stats.spill_raw_bytes = blocks->bytes_on_disk();
    stats.spill_bytes_in_memory = blocks->bytes_in_memory();
    for (const StreamSpill* sp : spills)
      if (sp) {
        stats.spill_bytes += sp->bytes_on_disk();
        stats.spill_raw_bytes += sp->bytes_spilled();
        stats.spill_bytes_in_memory += sp->bytes_kept_in_memory();
      }
    stats.input_triangles = tiles.triangle_count;
    stats.skipped = tiles.skipped;
    stats.occupied_cells = counts.clusters;
    stats.output_vertices = m.positions.size() / 3;
    stats.output_triangles = m.triangles.size() / 3;
    stats.output_edges = m.primitives.edge_count();
    stats.output_points = m.primitives.point_count();
    stats.tiles = tiles.count();
    stats.largest_tile_records = tiles.largest_tile_records();
    stats.resumed = resumed;
    if (level == 0) stats.warnings.insert(stats.warnings.end(), warnings.begin(), warnings.end());
    clock.move_to(&stats.phases);
    sink(level, m, stats);
  }
}

}  // namespace oocsimp
