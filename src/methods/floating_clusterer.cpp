// Floating-cell clustering out of core: tiles, sweeps of border decisions,
// partition-independent sums and a stitch of the cross-tile triangles.
// docs/design.md explains why the result equals the sequential algorithm.
//
// The stages hand each other typed results:
//   plan + bin   grid/tile_plan, grid/tile_binning: every triangle goes to the tile of
//                each of its corners (BinnedTiles); or the tiles kept by an earlier
//                run (--keep-tmp, cluster/kept_tiles)
//   grade        cluster/tile_grading: per tile, colour class by colour class, grade
//                the owned vertices (Low & Tan §3.1), sort them (§3.2) and run the
//                first greedy with the borders published so far, into a vertex block
//   regrade      cluster/tile_grading: each later level's first greedy over the graded
//                vertices of the level before (levels of detail)
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
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cluster/centre_sweeps.hpp"
#include "cluster/cluster_accumulation.hpp"
#include "cluster/floating_cells.hpp"
#include "cluster/kept_tiles.hpp"
#include "cluster/tile_grading.hpp"
#include "runtime/phase_timer.hpp"
#include "grid/tile_binning.hpp"
#include "grid/tile_memory_gate.hpp"
#include "grid/tile_plan.hpp"
#include "grid/work_share.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/progress_phase.hpp"
#include "stitch/mesh_assembly.hpp"

namespace oocsimp {

namespace {

// The tiles' buffers of a phase are freed at its end; let the caller's allocator
// give them back before the next (see SimplifyOptions::release_memory).
void release_memory(const RunPlan& plan) {
  if (plan.release_memory) plan.release_memory();
}

// The graded vertices of every tile, kept for --keep-tmp. They barely compress
// (positions and weights are noise to zstd), so they are stored raw.
std::unique_ptr<StreamSpill> graded_vertex_spill(const BinnedTiles& tiles, const SpillSettings& spill) {
  auto graded = std::make_unique<StreamSpill>(spill.dir, "vertices", sizeof(GradedVertex), 4096, false);
  graded->set_expected_bytes(spill.expected_bytes);
  for (std::uint32_t i = 0; i < tiles.count(); ++i) graded->add_stream();
  return graded;
}

// An uneven input can put many times the planned triangles into its fullest tile,
// whose working set then does not fit --mem even alone: the run stops (exit 2) before
// grading, or before clustering next to the borders and blocks that grading left,
// naming what it would take, rather than exceed the budget. `work`: "grade" or
// "cluster".
void check_fullest_tile_fits(const MemoryBudget& budget, const BinnedTiles& tiles, const std::string& path,
                             const char* work) {
  const std::uint64_t records = tiles.largest_tile_records();
  const std::uint64_t need = records * kTileBytesPerRecord;
  const std::uint64_t held = budget.held();
  budget.check(held, need,
               "the fullest tile of " + path + " (" + std::to_string(records) + " triangle records, " +
                   whole_mib(need) + " MiB to " + work + ")",
               "a dense part of the mesh: give options.memory_budget " + whole_mib(held + need + need / 4) +
                   " MiB or more, or a larger options.sizing.cell (options.sizing.grid, options.sizing.ratio)");
}

// One floating run over the levels' grids: the stages of the file's header, each a
// method, in the order cluster_floating_levels calls them. Binning and grading do not
// depend on the cell (kept_tiles.hpp): the tiles fit the coarsest level, and every
// level clusters the same graded tiles (Low & Tan 1997 §3.2.2 and §4, "sort once").
class FloatingRun {
 public:
  FloatingRun(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids,
              std::vector<Quadric>* quadrics);
  FloatingRun(const FloatingRun&) = delete;
  FloatingRun& operator=(const FloatingRun&) = delete;

  /// Makes this run part `part` of `parts` (before tile_mesh): its tiles are dealt
  /// after binning, and with a channel it grades and sweeps only its own.
  void run_as_part(std::uint32_t part, std::uint32_t parts, const PartChannel& channel);
  void tile_mesh();
  void check_same_tiling() const;
  bool resumed() const { return resumed_; }
  std::uint64_t faces_read() const { return tiles_.faces_read; }
  void grade();
  void regrade(std::size_t level);
  void sweep(SimplifyStats* stats);
  ClusterShares accumulate(std::size_t level);
  /// A part's plan: the tiling and the input's counts.
  FloatingPartPlan part_plan() const;
  /// The merge: empty shares bucketed for this process, which the parts' fill.
  ClusterShares open_shares(const FloatingPartPlan& plan);
  LargeArray<KeptTriangle> stitch(std::size_t level, ClusterShares& shares);
  OutputMesh assemble(std::size_t level, LargeArray<KeptTriangle> kept, ClusterShares& shares, AssemblyCounts* counts);
  void report(std::size_t level, const ClusterShares& shares, const AssemblyCounts& counts, const OutputMesh& m,
              SimplifyStats* stats) const;

 private:
  FloatingCellShape cell(std::size_t level) const { return {grids_[level].cell, plan_.floating.cell_shape}; }

  MeshInput& input_;
  const std::vector<GridSpec>& grids_;
  std::vector<Quadric>* quadrics_;
  const RunPlan& plan_;
  const MemoryBudget budget_;  // the output's check, at the end
  const ArrayPlace place_;     // of the kept triangles and the output's arrays
  bool keep_temp_;             // plan_.floating.keep_temp, but never in a part
  double coarsest_ = 0;
  std::vector<std::string> warnings_;  // the kept tiles', reported with the first level
  KeptTileStore kept_;
  BinnedTiles tiles_;
  std::unique_ptr<StreamSpill> graded_;  // --keep-tmp: every tile's graded vertices
  bool resumed_ = false, keeping_ = false;
  SpillSettings spill_;
  std::unique_ptr<BorderDecisions> decisions_;  // the level's
  FirstChoice first_;                           // the level's first greedy, by decisions_
  std::unique_ptr<BlockStore> blocks_;          // the level's graded vertex blocks
  TileShare share_;                             // the tiles this run owns (every tile but in a part of several)
};

FloatingRun::FloatingRun(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids,
                         std::vector<Quadric>* quadrics)
    : input_(input),
      grids_(grids),
      quadrics_(quadrics),
      plan_(plan),
      budget_(plan.budget_bytes, plan.budget_counts_process),
      place_(ArrayPlace::within(plan.budget_bytes, plan.temp_dir)),
      keep_temp_(plan.floating.keep_temp),
      kept_(input, plan.temp_dir, &warnings_),
      first_([this](std::uint32_t tile, const std::vector<GradedVertex>& sorted) {
        return decisions_->choose_first(tile, sorted);
      }) {
  for (const GridSpec& g : grids) coarsest_ = std::max(coarsest_, g.cell);
}

void FloatingRun::run_as_part(std::uint32_t part, std::uint32_t parts, const PartChannel& channel) {
  share_.part = part;
  share_.parts = parts;
  share_.exchange = channel.exchange;
  share_.deliver = channel.deliver;
  keep_temp_ = false;  // the kept tiles are one process's cache
}

// The tiled mesh: kept by an earlier run (--keep-tmp), or binned. A part's tiles are
// dealt by their records, which every part counts alike.
void FloatingRun::tile_mesh() {
  resumed_ = keep_temp_ && kept_.resume(coarsest_, &tiles_, &graded_);
  keeping_ = keep_temp_ && !resumed_ && kept_.start();
  // The tiles' share of the budget holds the fullest tile as planned (known exactly
  // when resumed); the spills' allowances come after it.
  const TileSettings tiling{plan_.budget_bytes, plan_.floating.tile_side, keep_temp_, plan_.floating.spill_compression,
                            plan_.temp_dir};
  // Planning reads every position (a pass of its own on a large input): a phase.
  std::optional<ProgressPhase> planning(std::in_place, plan_.progress, "plan tiles", 0, "vtx");
  const double tile_side = resumed_ ? 0 : plan_tile_side(input_, tiling, coarsest_);
  const std::uint64_t fullest =
      resumed_ ? tiles_.largest_tile_records() : estimate_fullest_tile_records(input_, std::max(tile_side, coarsest_));
  spill_ = spill_settings(input_, tiling, sizeof(GradedVertex), fullest);
  planning.reset();
  // Parts that exchange run only their own tiles: dealt before the binning, they keep
  // only those tiles' records, and where the faces can be read by range each reads
  // only its range and sends the others their tiles' records. (Parts that run apart
  // grade every tile, so they bin every tile and deal by its records after.)
  TileFilter keep;
  TileOwners owners;
  if (!resumed_ && share_.exchanging() && share_.parts > 1) {
    owners = tile_owners(input_.positions, tile_side, share_.parts, &share_);
    keep = [&owners, this](const GridCoord& c) { return tile_owner(owners, c) == share_.part; };
    std::optional<BinnedTiles> own =
        bin_own_face_range(input_, tile_side, plan_.budget_bytes, spill_, plan_.progress, owners, share_);
    if (own) {
      tiles_ = std::move(*own);
    } else {
      tiles_ = bin_triangles(input_, tile_side, plan_.budget_bytes, spill_, plan_.progress, keep);
    }
  } else if (!resumed_) {
    tiles_ = bin_triangles(input_, tile_side, plan_.budget_bytes, spill_, plan_.progress);
  }
  if (keep) {
    share_.owned.resize(tiles_.count());
    for (std::uint32_t t = 0; t < tiles_.count(); ++t) share_.owned[t] = keep(tiles_.grid.coord(t));
  } else if (share_.parts > 1) {
    std::vector<std::uint64_t> records(tiles_.count());
    std::vector<int> colours(tiles_.count());
    for (std::uint32_t t = 0; t < tiles_.count(); ++t) {
      records[t] = tiles_.triangles->record_count(t);
      colours[t] = tiles_.grid.colour(t);
    }
    share_.owned = owned_tiles(records, colours, share_.part, share_.parts);
  }
  if (share_.exchanging()) check_same_tiling();
}

// Parts that exchange borders must have tiled alike: a part with another budget
// (another machine's memory) may have planned other tiles.
void FloatingRun::check_same_tiling() const {
  const FloatingPartPlan mine = part_plan();
  const std::vector<std::vector<unsigned char>> all = share_.exchange(record_bytes(&mine, 1));
  for (std::size_t p = 0; p < all.size(); ++p) {
    FloatingPartPlan theirs;
    if (all[p].size() == sizeof theirs) std::memcpy(&theirs, all[p].data(), sizeof theirs);
    if (all[p].size() != sizeof theirs || theirs.tile_side != mine.tile_side || theirs.tiles != mine.tiles ||
        theirs.triangles != mine.triangles)
      throw UsageError("options.memory_budget", "part " + std::to_string(p) + " tiled " + input_.info.path +
                                                    " otherwise than part " + std::to_string(share_.part) +
                                                    " (another memory budget?): give every part the same --mem");
  }
}

FloatingPartPlan FloatingRun::part_plan() const {
  FloatingPartPlan plan;
  plan.tile_side = tiles_.grid.side;
  plan.tiles = tiles_.count();
  plan.triangles = tiles_.triangle_count;
  plan.vertices = input_.positions.count;
  plan.skipped = tiles_.skipped;
  return plan;
}

// Graded vertex blocks (Low & Tan 1997 §3.1, sorted as §3.2 visits them) with the
// first level's first greedy; kept for a later run with --keep-tmp.
void FloatingRun::grade() {
  release_memory(plan_);  // the binning chunks
  // The fullest tile is known now; it must fit in the budget next to what the run
  // holds, even alone (TileMemoryGate runs it alone).
  check_fullest_tile_fits(budget_, tiles_, input_.info.path, "grade");
  const FloatingCellShape first_cell = cell(0);
  decisions_ = std::make_unique<BorderDecisions>(tiles_.grid, first_cell);
  const BlockSettings blocks{first_cell.size, spill_.dir, spill_.allow.vertex_blocks, &plan_.locked_vertices,
                             plan_.lock_boundary};
  // The kept graded vertices do not say which are on the boundary: with a locked
  // boundary, the kept tiles are graded again.
  if (resumed_ && !plan_.lock_boundary) {
    blocks_ = blocks_from_kept(tiles_.grid, *graded_, first_, blocks);
  } else {
    if (keep_temp_ && !resumed_) graded_ = graded_vertex_spill(tiles_, spill_);
    GradingSettings grading;
    grading.blocks = blocks;
    grading.keep = resumed_ ? nullptr : graded_.get();
    grading.progress = &plan_.progress;
    grading.work_share = spill_.work_share;
    grading.budget = &budget_;
    grading.release_memory = plan_.release_memory;
    grading.only = share_.exchanging() ? &share_ : nullptr;
    blocks_ = grade_tiles(tiles_, input_.positions, first_, grading);
    if (grading.only) decisions_->gather_borders(share_);
    if (keeping_) kept_.keep(tiles_, *graded_);
  }
  release_memory(plan_);  // the tiles' grading buffers
}

// A later level's first greedy over the graded vertices of the level before.
void FloatingRun::regrade(std::size_t level) {
  ProgressPhase phase(plan_.progress, "regrade tiles", 0, "tile");
  const FloatingCellShape c = cell(level);
  decisions_ = std::make_unique<BorderDecisions>(tiles_.grid, c);
  // Both levels' blocks exist at once: the new ones get what the old ones leave
  // of the blocks' allowance.
  std::unique_ptr<BlockStore> before = std::move(blocks_);
  const std::uint64_t held = before->bytes_in_memory();
  const std::uint64_t allowance = spill_.allow.vertex_blocks > held ? spill_.allow.vertex_blocks - held : 0;
  blocks_ = blocks_from_blocks(tiles_.grid, *before, first_, {c.size, spill_.dir, allowance});
  before->discard();
}

// The sweeps of border decisions after the first greedy, until no border changes.
void FloatingRun::sweep(SimplifyStats* stats) {
  ProgressPhase phase(plan_.progress, "rounds", 0, "round");
  decisions_->sweep(*blocks_, stats ? &stats->floating : nullptr, &share_);
}

// Cluster shares and kept triangles, per tile against the decided centres.
ClusterShares FloatingRun::accumulate(std::size_t level) {
  TileBorders borders = decisions_->take_borders();
  release_memory(plan_);
  // The borders and the vertex blocks have grown since grading began: the fullest
  // tile must still fit next to them.
  check_fullest_tile_fits(budget_, tiles_, input_.info.path, "cluster");
  AccumulationSettings settings{cell(level),     plan_.floating.assign, plan_.budget_bytes, spill_,
                                &plan_.progress, &input_.attributes,    spill_.work_share,  plan_.thick_edges,
                                &budget_,        plan_.release_memory};
  settings.only = &share_;
  ClusterShares shares =
      accumulate_clusters(tiles_, input_.positions, *blocks_, borders, input_.positions.count, settings);
  // Centres live on in the cluster records; the per-tile lists are done, and the
  // memory of the triangles (after the last level) and vertex blocks goes to the
  // output tables.
  TileBorders().swap(borders);
  if (level + 1 == grids_.size()) {  // a next level reads the triangles again and grades from the blocks
    tiles_.triangles->discard();
    blocks_->discard();
  }
  release_memory(plan_);
  return shares;
}

ClusterShares FloatingRun::open_shares(const FloatingPartPlan& plan) {
  const TileSettings tiling{plan_.budget_bytes, plan_.floating.tile_side, false, plan_.floating.spill_compression,
                            plan_.temp_dir};
  spill_ = spill_settings(input_, tiling, sizeof(GradedVertex));
  AccumulationSettings settings{cell(0),         plan_.floating.assign, plan_.budget_bytes, spill_,
                                &plan_.progress, &input_.attributes,    spill_.work_share,  false,
                                &budget_,        plan_.release_memory};
  return open_cluster_shares(plan.triangles, input_.positions.count, settings);
}

// The triangles that cross tiles joined by index to the ones decided in tiles.
LargeArray<KeptTriangle> FloatingRun::stitch(std::size_t level, ClusterShares& shares) {
  LargeArray<KeptTriangle> kept;
  {
    ProgressPhase phase(plan_.progress, "stitch", 0, "bucket");
    CrossTileEdges cross{&input_.positions, cell(level).size, shares.edge_shares.get(), shares.cluster_span};
    kept =
        stitch_kept_triangles(*shares.inside, *shares.corners, place_, budget_, plan_.thick_edges ? &cross : nullptr);
  }
  shares.corners->discard();  // read into kept
  shares.inside->discard();
  return kept;
}

// Representatives, and the output triangles in input order of first occurrence.
OutputMesh FloatingRun::assemble(std::size_t level, LargeArray<KeptTriangle> kept, ClusterShares& shares,
                                 AssemblyCounts* counts) {
  ProgressPhase phase(plan_.progress, "assemble", 0, "cell");
  const ThickAssembly thick{shares.edge_shares.get(), &input_.positions};
  AssemblySettings settings;
  settings.cell = cell(level);
  settings.rule = plan_.floating.representative;
  settings.budget = budget_;
  settings.attribute_shares = shares.attribute_shares.get();
  settings.attributes = &shares.attributes;
  settings.thick = plan_.thick_edges ? &thick : nullptr;
  settings.origin = grids_[level].origin;
  settings.cluster_span = input_.positions.count;
  settings.place = place_;
  return assemble_mesh(std::move(kept), *shares.partials, settings, counts, quadrics_);
}

// The level's counts, and the spills' bytes so far.
void FloatingRun::report(std::size_t level, const ClusterShares& shares, const AssemblyCounts& counts,
                         const OutputMesh& m, SimplifyStats* stats) const {
  const StreamSpill* spills[] = {tiles_.triangles.get(),  graded_.get(),       shares.corners.get(),
                                 shares.partials.get(),   shares.inside.get(), shares.attribute_shares.get(),
                                 shares.edge_shares.get()};
  stats->floating.spill_bytes = stats->floating.spill_raw_bytes = blocks_->bytes_on_disk();
  stats->floating.spill_bytes_in_memory = blocks_->bytes_in_memory();
  for (const StreamSpill* sp : spills)
    if (sp) {
      stats->floating.spill_bytes += sp->bytes_on_disk();
      stats->floating.spill_raw_bytes += sp->bytes_spilled();
      stats->floating.spill_bytes_in_memory += sp->bytes_kept_in_memory();
    }
  stats->floating.stitch_corner_bytes = shares.corners->bytes_appended();
  stats->floating.inside_triangle_bytes = shares.inside->bytes_appended();
  stats->floating.cluster_share_bytes =
      shares.partials->bytes_appended() + (shares.attribute_shares ? shares.attribute_shares->bytes_appended() : 0);
  stats->input_triangles = tiles_.triangle_count;
  stats->skipped = tiles_.skipped;
  stats->occupied_cells = counts.clusters;
  stats->output_vertices = m.vertex_count();
  stats->output_triangles = m.triangle_count();
  stats->output_edges = m.primitives.edge_count();
  stats->output_points = m.primitives.point_count();
  stats->floating.tiles = tiles_.count();
  stats->floating.largest_tile_records = tiles_.largest_tile_records();
  stats->floating.resumed = resumed_;
  stats->floating.faces_read = tiles_.faces_read;
  if (level == 0) stats->warnings.insert(stats->warnings.end(), warnings_.begin(), warnings_.end());
  // A locked vertex whose neighbours all fall in one other cluster makes no triangle
  // with two others: it is dropped, and said so.
  warn_dropped_locks(counts.locked - counts.locked_used, counts.locked, stats);
}

}  // namespace

OutputMesh cluster_floating(MeshInput& input, const RunPlan& plan, const GridSpec& grid, SimplifyStats* stats,
                            std::vector<Quadric>* quadrics) {
  return single_level(cluster_floating_levels, input, plan, grid, stats, quadrics);
}

void cluster_floating_levels(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids,
                             const LevelSink& sink, const SimplifyStats& base, std::vector<Quadric>* quadrics) {
  PhaseTimer clock;  // the first level's phases begin with the binning (or resumption) and grading
  FloatingRun run(input, plan, grids, quadrics);
  run.tile_mesh();
  clock.end(run.resumed() ? "resume" : "bin");
  run.grade();
  clock.end("grade");
  for (std::size_t level = 0; level < grids.size(); ++level) {
    if (level > 0) {  // every later level re-runs its first greedy from the graded vertices
      clock.restart();
      run.regrade(level);
      clock.end("regrade");
    }
    SimplifyStats stats = base;
    run.sweep(&stats);
    clock.end("rounds");
    ClusterShares shares = run.accumulate(level);
    clock.end("cluster");
    LargeArray<KeptTriangle> kept = run.stitch(level, shares);
    clock.end("stitch");
    AssemblyCounts counts;
    OutputMesh m = run.assemble(level, std::move(kept), shares, &counts);
    clock.end("assemble");
    run.report(level, shares, counts, m, &stats);
    clock.move_to(&stats.phases);
    sink(level, m, stats);
  }
}

void cluster_floating_part(MeshInput& input, const RunPlan& plan, const GridSpec& grid, std::uint32_t part,
                           std::uint32_t parts, const PartChannel& channel, const ClusterShareSink& sink,
                           FloatingPartPlan* tiling, SimplifyStats* stats) {
  PhaseTimer clock;
  const std::vector<GridSpec> grids{grid};
  FloatingRun run(input, plan, grids, nullptr);
  run.run_as_part(part, parts, channel);
  run.tile_mesh();
  clock.end("bin");
  run.grade();
  clock.end("grade");
  run.sweep(stats);
  clock.end("rounds");
  ClusterShares shares = run.accumulate(0);
  clock.end("cluster");
  for_each_share_run(shares, sink);
  clock.end("hand on");
  *tiling = run.part_plan();
  if (stats) {
    stats->input_triangles = tiling->triangles;
    stats->skipped = tiling->skipped;
    stats->floating.faces_read = run.faces_read();
    clock.move_to(&stats->phases);
  }
}

OutputMesh merge_floating_shares(MeshInput& input, const RunPlan& plan, const GridSpec& grid,
                                 const FloatingPartPlan& tiling, const ClusterShareSource& source, SimplifyStats* stats,
                                 std::vector<Quadric>* quadrics) {
  PhaseTimer clock;
  const std::vector<GridSpec> grids{grid};
  FloatingRun run(input, plan, grids, quadrics);
  ClusterShares shares = run.open_shares(tiling);
  source([&](ShareKind kind, const void* records, std::size_t count) {
    add_share_records(&shares, kind, records, count, input.info.path);
  });
  flush_shares(&shares);
  clock.end("gather");
  LargeArray<KeptTriangle> kept = run.stitch(0, shares);
  clock.end("stitch");
  AssemblyCounts counts;
  OutputMesh m = run.assemble(0, std::move(kept), shares, &counts);
  clock.end("assemble");
  stats->input_triangles = tiling.triangles;
  stats->skipped = tiling.skipped;
  stats->occupied_cells = counts.clusters;
  stats->output_vertices = m.vertex_count();
  stats->output_triangles = m.triangle_count();
  stats->floating.tiles = tiling.tiles;
  clock.move_to(&stats->phases);
  return m;
}

}  // namespace oocsimp
