// Floating-cell clustering out of core: tiles, sweeps of border decisions,
// partition-independent sums and a stitch of the cross-tile triangles.
// floating_cells_design.md explains why the result equals the sequential algorithm.
//
//   pass 1  bin: every triangle goes to the tile of each of its corners
//   pass 2  per tile, colour class by colour class: grade the owned vertices
//           (Low & Tan §3.1), sort them (§3.2), run the greedy with the borders
//           published so far, keep them in a vertex block; then sweeps with the
//           neighbours' border centres until no border changes
//   pass 3  per tile: assign vertices to centres, add vertex quadrics to clusters
//           in fixed point, keep the triangles that span three clusters; the
//           triangles that cross tiles are grouped by index through a bucket spill
//           (stitch/kept_triangles.*)
//   solve   representatives; output triangles in input order of first occurrence
//
// OOCSIMP_DEBUG_ROUNDS=1 in the environment prints the tiles looked at in every
// sweep, the seconds of every phase and the memory of each phase, for tuning.
#include "cluster/floating_clusterer.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <limits.h>
#include <malloc.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cluster/fixed_point_sums.hpp"
#include "cluster/floating_cells.hpp"
#include "cluster/kept_tiles.hpp"
#include "cluster/ordered_pipeline.hpp"
#include "grid/cell_map.hpp"
#include "grid/grid_coord.hpp"
#include "grid/occupancy.hpp"
#include "spill/block_store.hpp"
#include "spill/spill_allowances.hpp"
#include "spill/stream_spill.hpp"
#include "grid/tile_triangles.hpp"
#include "io/content_hash.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/progress.hpp"
#include "oocsimp/quadric.hpp"
#include "oocsimp/temp_file.hpp"
#include "stitch/kept_triangles.hpp"

namespace oocsimp {

namespace {

// --- tiles ---

struct TileGeometry {
  double side = 1;
  GridCoord of(const Vec3d& p) const { return GridCoord::of(p, side); }
  Box3d box(const GridCoord& c) const {
    Box3d b;
    b.min = {double(c.x) * side, double(c.y) * side, double(c.z) * side};
    b.max = {double(c.x + 1) * side, double(c.y + 1) * side, double(c.z + 1) * side};
    return b;
  }
};

// Whether a centre's cell reaches outside the tile box: only such centres can
// cover a neighbour's vertex (tiles are at least one cell wide).
bool near_border(const Vec3d& c, const Box3d& box, double half) {
  return c.x - half < box.min.x || c.x + half >= box.max.x || c.y - half < box.min.y || c.y + half >= box.max.y ||
         c.z - half < box.min.z || c.z + half >= box.max.z;
}

// Tiles allocate and free large vectors on several threads; glibc keeps the freed
// memory in per-thread arenas, where it counts against the budget. Give it back
// between phases.
void release_free_heap() { ::malloc_trim(0); }

bool same_centres(const std::vector<GradedVertex>& a, const std::vector<GradedVertex>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].index != b[i].index) return false;
  return true;
}

class FloatingRun {
 public:
  FloatingRun(MeshInput& input, const SimplifyOptions& options, double cell, SimplifyStats* stats)
      : input_(input), options_(options), cell_{cell, options.cell_shape}, half_(0.5 * cell), stats_(stats) {}

  SimplifiedMesh run() {
    const bool debug = std::getenv("OOCSIMP_DEBUG_ROUNDS") != nullptr;
    // Debug: the peak anonymous memory of each phase, sampled every 20 ms.
    std::atomic<std::uint64_t> phase_peak{0};
    std::atomic<bool> sampling{debug};
    std::thread sampler;
    if (debug)
      sampler = std::thread([&] {
        while (sampling) {
          std::uint64_t a = current_anon_bytes(), p = phase_peak.load();
          while (a > p && !phase_peak.compare_exchange_weak(p, a)) {
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
      });
    struct StopSampler {
      std::atomic<bool>& on;
      std::thread& t;
      ~StopSampler() {
        on = false;
        if (t.joinable()) t.join();
      }
    } stop_sampler{sampling, sampler};
    auto note = [&](const char* phase) {
      if (debug)
        std::fprintf(stderr, "%s: anon now %.1f MiB, peak %.1f MiB\n", phase, double(current_anon_bytes()) / 1048576.0,
                     double(phase_peak.exchange(0)) / 1048576.0);
    };
    double t0 = now_seconds();
    allow_ = memory_for_spills();
    compress_spill_ = spill_compression();
    bool resumed = options_.keep_temp && resume_kept_tiles();
    bool keeping = options_.keep_temp && !resumed && start_input_digest();
    if (!resumed) {
      plan_tiles();
      bin_triangles();
    }
    double t1 = now_seconds();
    release_free_heap();  // the binning chunks
    note("binning");
    if (debug) {
      std::uint64_t most = 0;
      for (std::uint32_t t = 0; t < triangles_->stream_count(); ++t) most = std::max(most, triangles_->record_count(t));
      std::fprintf(stderr, "tiles %u, largest %llu triangle records\n", triangles_->stream_count(), (unsigned long long)most);
    }
    if (resumed) {
      choose_from_kept();
    } else {
      grade_and_choose();
      if (keeping) keep_tiles();
    }
    release_free_heap();  // the tiles' grading buffers
    note("grading");
    {
      ProgressPhase phase(options_.progress, "rounds", 0, "round");
      run_rounds();
      std::vector<std::vector<GradedVertex>>().swap(ext_);
    }
    note("rounds");
    double t2 = now_seconds();
    release_free_heap();
    assign_and_accumulate();
    triangles_->discard();  // their memory goes to the output tables
    blocks_->discard();
    note("clustering");
    // Centres live on in the cluster records; the per-tile lists are done.
    std::vector<std::vector<GradedVertex>>().swap(border_);
    release_free_heap();
    double t3 = now_seconds();
    {
      ProgressPhase phase(options_.progress, "stitch", 0, "bucket");
      stitch_cross_tile_triangles();
    }
    corners_->discard();  // read into kept_
    inside_->discard();
    note("stitch");
    double t4 = now_seconds();
    SimplifiedMesh m;
    {
      ProgressPhase phase(options_.progress, "assemble", 0, "cell");
      m = assemble();
    }
    double t5 = now_seconds();
    note("assembly");
    if (stats_) {  // a resumed run reads kept tiles where the others bin
      const PhaseTime phases[] = {{resumed ? "resume" : "bin", t1 - t0}, {"grade", t2 - t1 - rounds_seconds_},
                                  {"rounds", rounds_seconds_},           {"cluster", t3 - t2},
                                  {"stitch", t4 - t3},                   {"assemble", t5 - t4}};
      stats_->phases.insert(stats_->phases.end(), std::begin(phases), std::end(phases));
    }
    if (debug)
      std::fprintf(stderr, "bin %.3f grade+rounds %.3f (rounds %.3f) cluster %.3f stitch %.3f assemble %.3f\n", t1 - t0,
                   t2 - t1, rounds_seconds_, t3 - t2, t4 - t3, t5 - t4);
    return m;
  }

 private:
  // Whether the triangle, stitch and kept-triangle spills are zstd-compressed. zstd
  // halves the triangle spill (10M sphere: 620 -> 346 MB) but cost 1.4 s of a 10.6 s
  // run on 2 threads; it pays only where the spill goes to the disk, not where the
  // page cache holds it (and kept tiles outlive the run on disk).
  bool spill_compression() const {
    switch (options_.spill_compression) {
      case SpillCompression::zstd: return true;
      case SpillCompression::none: return false;
      case SpillCompression::automatic: break;
    }
    // What goes to the disk: the part that does not stay in memory.
    const std::uint64_t to_disk = triangle_spill_bytes() - std::min(triangle_spill_bytes(), allow_.triangles);
    return options_.keep_temp || to_disk > available_memory_bytes() / 2;
  }

  // The raw triangle spill, estimated: most triangles are binned into one tile.
  std::uint64_t triangle_spill_bytes() const { return input_.info.face_count * sizeof(TriangleRecord) * 5 / 4; }

  // The spills' memory allowances: what the budget leaves after the threads' tiles
  // (half the budget, or what kMaxTileTriangles tiles can take: the fullest tile is
  // up to twice the planned one, 1.7x measured on the 4M sphere), the binning buffers
  // (a quarter) and the output tables (an eighth). Kept tiles go to their file anyway.
  SpillAllowances memory_for_spills() const {
    const std::uint64_t budget = options_.memory_budget;
    const unsigned threads = unsigned(std::max(1, tbb::this_task_arena::max_concurrency()));
    const std::uint64_t tiles = std::min<std::uint64_t>(budget / 2, 2 * threads * kMaxTileTriangles * kBytesPerTriangle);
    return spill_allowances(budget, tiles + budget / 4 + budget / 8, options_.keep_temp ? 0 : triangle_spill_bytes(),
                            input_.positions.count * sizeof(GradedVertex) * 3 / 2);
  }

  // Tile side from the memory budget: a tile's working set is about kBytesPerTriangle
  // per triangle and `threads` tiles are in memory at once; use half the budget.
  // Tiles beyond kMaxTileTriangles outgrow the processor caches: measured on the
  // 10M sphere (--grid 256, 1 thread), 8 tiles of 1.25M triangles took 23.7 s,
  // 128 tiles of 78k 18.6 s, 483 tiles of 21k 19.6 s (more border rounds).
  static constexpr double kBytesPerTriangle = 400;
  static constexpr double kMaxTileTriangles = 1 << 16;
  void plan_tiles() {
    std::uint64_t budget = options_.memory_budget;
    unsigned threads = unsigned(std::max(1, tbb::this_task_arena::max_concurrency()));
    double side = options_.tile_side;
    if (side <= 0) {
      double per_tile =
          std::clamp(double(budget) / 2 / threads / kBytesPerTriangle, 1.0, kMaxTileTriangles);
      double tiles_needed = std::max(1.0, double(input_.info.face_count) / per_tile);
      // Enough tiles to keep every thread busy, once tiles are worth their overhead.
      constexpr double kMinTileTriangles = 1 << 15;
      tiles_needed = std::max(tiles_needed, std::min(4.0 * threads, double(input_.info.face_count) / kMinTileTriangles));
      const Box3d& b = input_.info.bounds;
      double longest = b.empty() ? 1 : std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z});
      if (tiles_needed <= 1 || longest <= 0) {
        side = std::max(longest, cell_.size);
      } else {
        // Occupied tiles grow as divisions^2 on a surface: scale from the finest
        // counted level that does not exceed the need (or the coarsest one).
        // An estimate is enough (the tiling never changes the output): about 2^20
        // vertices, a few per cell of the finest level on a surface.
        std::uint64_t stride = std::max<std::uint64_t>(1, input_.positions.count >> 20);
        std::vector<std::uint64_t> occ = count_occupancy(input_.positions, b, stride);
        int l = 0;
        while (l + 1 < kLevelCount && double(occ[std::size_t(l + 1)]) <= tiles_needed) ++l;
        double divisions =
            double(kLevels[l]) * std::sqrt(tiles_needed / double(std::max<std::uint64_t>(occ[std::size_t(l)], 1)));
        side = longest / divisions;
        // That is the average tile; the fullest one can hold several times as much
        // (measured: 6.4x on the generated sphere, whose poles are dense), and the
        // fullest sets the memory. Shrink the side until the fullest, estimated from
        // a sample of the vertices, fits, but to no less than half: a denser part
        // would otherwise cut the whole mesh into tiny tiles (11064 tiles instead
        // of 243 on the 10M sphere at --mem 64M), each costing buffers and rounds.
        const double average_side = side;
        for (int pass = 0; pass < 4 && side > 0.5 * average_side; ++pass) {
          double fullest = 2 * fullest_tile_vertices(std::max(side, cell_.size));  // ~2 triangles per vertex
          if (fullest <= per_tile) break;
          side = std::max(0.5 * average_side, side * 0.95 * std::sqrt(per_tile / fullest));
        }
      }
    }
    // A tile is at least one floating cell wide, so a cell reaches only into the
    // adjacent tiles.
    tiles_.side = std::max(side, cell_.size);
    if (options_.tile_side > 0) check_tile_count_fits(budget);
  }

  // Every occupied tile costs a binning buffer of at least kMinBufferRecords records
  // and its bookkeeping (spill chains, coordinates, borders, neighbour lists: under
  // 1 KiB). Binning gives the buffers a quarter of the budget.
  static constexpr std::size_t kMinBufferRecords = 256;
  static constexpr std::uint64_t kTileFixedBytes = kMinBufferRecords * sizeof(TriangleRecord) + 1024;

  // A --tile so small that its tiles' fixed costs exceed the budget is refused before
  // binning (exit 2): the user chose the side, so it is not silently changed. The
  // occupied tiles of the vertices are counted until there are too many.
  void check_tile_count_fits(std::uint64_t budget) const {
    const std::uint64_t most = std::max<std::uint64_t>(1, budget / 4 / kTileFixedBytes);
    const Box3d& b = input_.info.bounds;
    if (b.empty()) return;
    double box_tiles = 1;
    for (double e : {b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z})
      box_tiles *= std::floor(e / tiles_.side) + 2;
    if (box_tiles <= double(most)) return;  // even a full box fits
    std::unordered_set<GridCoord, GridCoordHash> occupied;
    GridCoord last{INT64_MIN, 0, 0};
    const PositionArray& pos = input_.positions;
    for (std::uint64_t i = 0; i < pos.count && occupied.size() <= most; ++i) {
      Vec3d p = pos.get(i);
      if (!is_finite(p)) continue;
      GridCoord c = tiles_.of(p);
      if (c == last) continue;  // neighbouring vertices mostly share a tile
      last = c;
      occupied.insert(c);
    }
    if (occupied.size() <= most) return;
    char side[64];
    std::snprintf(side, sizeof side, "%g", options_.tile_side);
    throw UsageError("--tile " + std::string(side) + " makes more than " + std::to_string(most) +
                     " tiles here, whose buffers (" + std::to_string(kTileFixedBytes >> 10) +
                     " KiB each) need more than a quarter of --mem " + std::to_string(budget >> 20) +
                     " MiB: give a larger --tile or --mem, or leave --tile out to size tiles from --mem");
  }

  // The vertex count of the fullest tile of side `side`, estimated from at most
  // about 4M evenly spaced vertices.
  double fullest_tile_vertices(double side) const {
    const PositionArray& pos = input_.positions;
    std::uint64_t stride = std::max<std::uint64_t>(1, pos.count / (std::uint64_t(1) << 22));
    std::unordered_map<GridCoord, std::uint64_t, GridCoordHash> count;
    std::uint64_t most = 0;
    for (std::uint64_t i = 0; i < pos.count; i += stride) {
      Vec3d p = pos.get(i);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
      most = std::max(most, ++count[GridCoord::of(p, side)]);
    }
    return double(most) * double(stride);
  }

  std::uint32_t tile_id(const GridCoord& c) {
    auto it = tile_ids_.find(c);
    if (it != tile_ids_.end()) return it->second;
    std::uint32_t id = triangles_->add_stream();
    tile_ids_.emplace(c, id);
    tile_coords_.push_back(c);
    return id;
  }

  void bin_triangles() {
    std::uint64_t budget = options_.memory_budget;
    // Buffers of all tiles together take at most a quarter of the budget.
    std::size_t est_tiles = 64;
    {
      const Box3d& b = input_.info.bounds;
      if (!b.empty()) {
        double n = 1;
        for (double e : {b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z}) n *= std::floor(e / tiles_.side) + 1;
        est_tiles = std::size_t(std::min(n, 1e6));
      }
    }
    // Blocks beyond 32 KiB buy nothing (10M sphere, 2 threads: 8192 records per
    // buffer ran as fast as 1024, with 175 instead of 97 MiB at the peak).
    std::size_t buffer_records =
        std::clamp<std::size_t>(std::size_t(double(budget) / 4 / double(est_tiles) / sizeof(TriangleRecord)),
                                kMinBufferRecords, 1024);
    // Free space for the spill, checked before writing it. A lower estimate, so no
    // run that fits is refused: every used vertex is spilled once, raw; the triangle
    // records compress to an eighth or more, and (a header's face count being
    // unchecked so far) to no less than the input file holds.
    const std::uint64_t spill_estimate =
        input_.positions.count * sizeof(GradedVertex) +
        std::min<std::uint64_t>(input_.info.face_count * (sizeof(TriangleRecord) / 8), input_.file_size);
    if (spill_estimate > allow_.triangles + allow_.vertex_blocks)  // some of it goes to the disk
      require_free_space(temp_dir(), spill_estimate, "the tile spill");
    triangles_ = std::make_unique<StreamSpill>(temp_dir(), "tiles", sizeof(TriangleRecord), buffer_records,
                                               compress_spill_, allow_.triangles);
    triangles_->set_expected_bytes(spill_estimate);

    const PositionArray& pos = input_.positions;
    TriangleStream& stream = *input_.triangles;
    std::uint64_t next = 0;
    ProgressReporter* progress = options_.progress;
    if (progress) progress->begin("bin tiles", input_.file_size, "B");
    run_ordered_pipeline<BinChunk>(
        2 * std::size_t(std::max(1, tbb::this_task_arena::max_concurrency())),
        [&](BinChunk& c) {
          c.count = stream.read(c.tris.data(), kBinChunk);
          c.first = next;
          next += c.count;
          if (progress) progress->set(stream.bytes_consumed());
          return c.count > 0;
        },
        [&](BinChunk& c) {
          c.filed.clear();
          c.group_tile.clear();
          // At most 3 tiles per triangle: a table of twice that never fills.
          std::size_t slots = 16;
          while (slots < 6 * c.count) slots *= 2;
          c.slots.assign(slots, 0);
          for (std::size_t i = 0; i < c.count; ++i) {
            std::uint64_t t = c.first + i;
            TriangleRecord r{t, {c.tris[3 * i], c.tris[3 * i + 1], c.tris[3 * i + 2]}};
            GridCoord k[3];
            for (int j = 0; j < 3; ++j) k[j] = tiles_.of(pos.get(r.v[j]));
            for (int j = 0; j < 3; ++j) {
              if ((j >= 1 && k[j] == k[0]) || (j == 2 && k[2] == k[1])) continue;  // tile already has it
              std::uint64_t mask = 0;
              for (int m = 0; m < 3; ++m) mask |= std::uint64_t(k[m] == k[j]) << m;
              r.tm = t | mask << TriangleRecord::kMaskShift;
              c.filed.push_back({c.local_tile(k[j]), r});
            }
          }
          c.group();
        },
        [&](BinChunk& c) {
          for (std::size_t g = 0; g + 1 < c.group_start.size(); ++g)
            triangles_->append(tile_id(c.group_tile[g]), &c.records[c.group_start[g]],
                               c.group_start[g + 1] - c.group_start[g]);
        });
    triangles_->flush();
    if (progress) progress->end();
    triangle_count_ = next;
    border_.resize(triangles_->stream_count());
    ext_.resize(triangles_->stream_count());
    vertices_ = std::make_unique<StreamSpill>(temp_dir(), "vertices", sizeof(GradedVertex), 4096, compress_vertices_);
    vertices_->set_expected_bytes(spill_estimate);
    for (std::uint32_t i = 0; i < triangles_->stream_count(); ++i) vertices_->add_stream();
  }

  std::string temp_dir() const { return options_.temp_dir.empty() ? default_temp_dir() : options_.temp_dir; }

  // The tile's triangles, sorted by input index (the spill order depends on nothing
  // but the input, but sorting makes that obvious).
  std::vector<TriangleRecord> load_triangles(std::uint32_t tile) const {
    std::vector<TriangleRecord> t;
    triangles_->read(tile, &t);
    // Input order matters: a vertex quadric sums its faces in this order. Binning
    // appends in input order, so this is normally sorted already.
    auto by_index = [](const TriangleRecord& a, const TriangleRecord& b) { return a.index() < b.index(); };
    if (!std::is_sorted(t.begin(), t.end(), by_index)) std::sort(t.begin(), t.end(), by_index);
    return t;
  }

  std::vector<GradedVertex> load_vertices(std::uint32_t tile) const {
    std::vector<GradedVertex> v;
    vertices_->read(tile, &v);
    return v;
  }

  // Neighbouring tile ids (up to 26).
  std::vector<std::uint32_t> neighbours(std::uint32_t tile) const {
    std::vector<std::uint32_t> out;
    const GridCoord& c = tile_coords_[tile];
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (!dx && !dy && !dz) continue;
          auto it = tile_ids_.find(GridCoord{c.x + dx, c.y + dy, c.z + dz});
          if (it != tile_ids_.end()) out.push_back(it->second);
        }
    std::sort(out.begin(), out.end());
    return out;
  }

  // The external centres of `tile`: its neighbours' border centres whose cells can
  // reach into its box (within half a cell of it, widened by a rounding margin;
  // contains() decides exactly), in precedes order.
  std::vector<GradedVertex> external_centres(std::uint32_t tile,
                                             const std::vector<std::vector<GradedVertex>>& borders) const {
    Box3d box = tiles_.box(tile_coords_[tile]);
    double reach = half_ * (1 + 1e-9);
    std::vector<GradedVertex> ext;
    for (std::uint32_t n : neighbours(tile))
      for (const GradedVertex& c : borders[n])
        if (c.p.x >= box.min.x - reach && c.p.x <= box.max.x + reach && c.p.y >= box.min.y - reach &&
            c.p.y <= box.max.y + reach && c.p.z >= box.min.z - reach && c.p.z <= box.max.z + reach)
          ext.push_back(c);
    std::sort(ext.begin(), ext.end(), [](const GradedVertex& a, const GradedVertex& b) { return precedes(a, b); });
    return ext;
  }

  // The centres of `tile` (its `centres`) whose cells reach outside it.
  std::vector<GradedVertex> border_of(std::uint32_t tile, const std::vector<GradedVertex>& centres) const {
    Box3d box = tiles_.box(tile_coords_[tile]);
    std::vector<GradedVertex> b;
    for (const GradedVertex& c : centres)
      if (near_border(c.p, box, half_)) b.push_back(c);
    return b;
  }

  void grade_and_choose() {
    std::uint32_t n = triangles_->stream_count();
    ProgressReporter* progress = options_.progress;
    if (progress) progress->begin("grade tiles", n, "tile");
    std::atomic<std::uint32_t> done{0};
    // Round 1: grade, sort and spill every tile's vertices; the greedy with the
    // borders of the neighbours graded before.
    blocks_ = std::make_unique<BlockStore>(temp_dir(), "vertex-blocks", n, allow_.vertex_blocks);
    for_each_tile_by_colour([&](std::uint32_t tile) {
      std::vector<TriangleRecord> tris = load_triangles(tile);
      // The tile's vertices as local ids in order of first use, each position read
      // once; the owned ones (whose fans are complete here) are graded.
      TileLocalMesh local(tris, input_.positions);
      std::vector<GradedVertex> graded = grade_local_vertices(local.mesh(), local.owned);
      std::sort(graded.begin(), graded.end(), [](const GradedVertex& a, const GradedVertex& b) { return precedes(a, b); });
      if (options_.keep_temp) vertices_->append(tile, graded.data(), graded.size());
      std::vector<unsigned char> block = TileVertexBlock::build(graded, choose_first(tile, graded), cell_.size);
      blocks_->put(tile, block.data(), block.size());
      if (progress) progress->set(++done);
    });
    vertices_->flush();
    blocks_->map();
    if (progress) progress->end();
  }

  // --- --keep-tmp: the binned and graded tiles outlive the run ---
  //
  // Binning and grading depend only on the input and the tile side, not on the
  // cell, its shape, the assignment rule or the representative, so a later run on
  // the same input with other options reuses them, provided its cell still fits in
  // a tile. The files are oocsimp-kept-KEY.{tiles,vertices,manifest} in the temp
  // folder, KEY naming the input's path and whether it was welded (which numbers
  // the vertices otherwise). The manifest records the input's identity (device,
  // inode, size, modification and status change times) and the XXH64 of its bytes, read while binning; a resume requires the same identity and reads the
  // input again to compare the checksum (a sequential read: on the 2M sphere it
  // costs a small fraction of the binning it saves), then checks the size and XXH64
  // of both kept files. Anything that does not match, or a damaged manifest, means
  // binning again, with a warning: kept tiles are a cache, never a reason to fail.

  std::string kept_path(const char* ext) const {
    char real[PATH_MAX];
    std::string id = ::realpath(input_.info.path.c_str(), real) ? std::string(real) : input_.info.path;
    if (input_.info.unwelded_vertex_count) id += "|welded";
    char key[17];
    std::snprintf(key, sizeof key, "%016llx", (unsigned long long)content_hash(id.data(), id.size()));
    return temp_dir() + "/oocsimp-kept-" + key + "." + ext;
  }

  void warn(const std::string& text) {
    if (stats_) stats_->warnings.push_back(text);
  }

  // Starts the input's checksum for keep_tiles(); false (with a warning) when the
  // input is no regular file, which cannot be keyed.
  bool start_input_digest() {
    if (!regular_file_identity(input_.info.path, &kept_input_)) {
      warn(input_.info.path + ": --keep-tmp needs a regular file as input; nothing is kept");
      return false;
    }
    input_digest_ = std::make_unique<BackgroundDigest>(input_.info.path);
    return true;
  }

  void keep_tiles() {
    FileDigest input_digest;
    std::string error;
    FileIdentity after;
    if (!input_digest_->get(&input_digest, &error) || !regular_file_identity(input_.info.path, &after) ||
        after != kept_input_ || input_digest.size != kept_input_.size) {
      warn(error.empty() ? input_.info.path + ": changed during the run; its tiles are not kept" : error);
      return;
    }
    // The old manifest goes first: a crash below must not leave it describing new files.
    ::unlink(kept_path("manifest").c_str());
    triangles_->keep_as(kept_path("tiles"));
    vertices_->keep_as(kept_path("vertices"));
    KeptManifest m;
    m.input = kept_input_;
    m.input_digest = input_digest;
    m.tiles_digest = file_digest(kept_path("tiles"));
    m.vertices_digest = file_digest(kept_path("vertices"));
    m.tile_side = tiles_.side;
    m.triangles = triangle_count_;
    m.skipped = input_.triangles->skipped();  // a resumed run does not read the stream
    for (std::uint32_t t = 0; t < triangles_->stream_count(); ++t)
      m.tiles.push_back({tile_coords_[t], triangles_->chain(t), vertices_->chain(t)});
    write_file_atomically(kept_path("manifest"), format_kept_manifest(m));
  }

  // Why kept tiles cannot be used, as a warning; empty when they can. `m` is the
  // parsed manifest, `now` the input's identity.
  std::string kept_tiles_fault(const KeptManifest& m, const FileIdentity& now) const {
    const std::string& in = input_.info.path;
    if (now != m.input) return in + ": changed since its tiles were kept (inode, size or times differ); binning again";
    const std::pair<const char*, const FileDigest*> kept[2] = {{"tiles", &m.tiles_digest},
                                                               {"vertices", &m.vertices_digest}};
    for (const auto& [ext, digest] : kept) {
      struct stat st;
      std::string path = kept_path(ext);
      if (::stat(path.c_str(), &st) != 0) return path + ": kept file missing; binning again";
      if (std::uint64_t(st.st_size) != digest->size)
        return path + ": kept file of " + std::to_string(st.st_size) + " bytes, " + std::to_string(digest->size) +
               " expected (truncated?); binning again";
    }
    try {
      if (file_digest(in) != m.input_digest)
        return in + ": content differs from the input whose tiles were kept (checksum); binning again";
      for (const auto& [ext, digest] : kept)
        if (file_digest(kept_path(ext)) != *digest)
          return kept_path(ext) + ": kept file damaged (checksum differs); binning again";
    } catch (const IoError& e) {
      return std::string(e.what()) + "; binning again";
    }
    return "";
  }

  // Loads kept tiles when a manifest for this input exists, its tiles are at least a
  // cell wide and every check above passes; false (and nothing changed) otherwise.
  bool resume_kept_tiles() {
    FileIdentity now;
    if (!regular_file_identity(input_.info.path, &now)) return false;  // start_input_digest() says why
    std::string text;
    if (!read_kept_manifest(&text)) {
      struct stat st;
      for (const char* ext : {"tiles", "vertices"})
        if (::stat(kept_path(ext).c_str(), &st) == 0) {
          warn(kept_path("manifest") + ": missing beside kept tiles; binning again");
          break;
        }
      return false;
    }
    KeptManifest m;
    if (!parse_kept_manifest(text, &m)) {
      warn(kept_path("manifest") + ": damaged manifest of kept tiles; binning again");
      return false;
    }
    if (m.tile_side < cell_.size) return false;  // the options, not the files: no warning
    std::string fault = kept_tiles_fault(m, now);
    if (!fault.empty()) {
      warn(fault);
      return false;
    }
    std::vector<StreamSpill::Chain> tri_chains, vtx_chains;
    for (const KeptTile& t : m.tiles) {
      tri_chains.push_back(t.triangles);
      vtx_chains.push_back(t.vertices);
    }
    triangles_ = StreamSpill::open_kept(kept_path("tiles"), sizeof(TriangleRecord), tri_chains);
    vertices_ = StreamSpill::open_kept(kept_path("vertices"), sizeof(GradedVertex), vtx_chains);
    tiles_.side = m.tile_side;
    triangle_count_ = m.triangles;
    resumed_skipped_ = m.skipped;
    for (const KeptTile& t : m.tiles) {
      tile_ids_.emplace(t.coord, std::uint32_t(tile_coords_.size()));
      tile_coords_.push_back(t.coord);
    }
    border_.resize(m.tiles.size());
    ext_.resize(m.tiles.size());
    resumed_ = true;
    if (stats_) stats_->resumed = true;
    return true;
  }

  // The manifest's text; false when there is none. A file beyond any plausible
  // manifest (a line per tile) is read as far as that and then fails its checksum.
  bool read_kept_manifest(std::string* text) const {
    FILE* f = std::fopen(kept_path("manifest").c_str(), "rb");
    if (!f) return false;
    char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0 && text->size() < (std::size_t(1) << 30);)
      text->append(buf, n);
    std::fclose(f);
    return true;
  }

  // Round 1 on kept tiles: the graded vertices are on disk already.
  void choose_from_kept() {
    blocks_ = std::make_unique<BlockStore>(temp_dir(), "vertex-blocks", triangles_->stream_count(),
                                           allow_.vertex_blocks);
    for_each_tile_by_colour([&](std::uint32_t tile) {
      std::vector<GradedVertex> sorted = load_vertices(tile);
      std::vector<unsigned char> block = TileVertexBlock::build(sorted, choose_first(tile, sorted), cell_.size);
      blocks_->put(tile, block.data(), block.size());
    });
    blocks_->map();
  }

  // The colour class of a tile: the parity of its coordinates. Tiles of a class
  // are never adjacent (a cell reaches only adjacent tiles), so they can run at
  // once while the borders they read, their neighbours', hold still.
  int colour(std::uint32_t tile) const {
    const GridCoord& c = tile_coords_[tile];
    return int(c.x & 1) | int(c.y & 1) << 1 | int(c.z & 1) << 2;
  }

  // The tiles of colour class k, ascending; with `only`, those t with (*only)[t].
  std::vector<std::uint32_t> tiles_of_colour(int k, const std::vector<char>* only = nullptr) const {
    std::vector<std::uint32_t> out;
    for (std::uint32_t t = 0; t < triangles_->stream_count(); ++t)
      if ((!only || (*only)[t]) && colour(t) == k) out.push_back(t);
    return out;
  }

  // f(tile) for every tile: the 8 colour classes one after the other, each in parallel.
  template <class F>
  void for_each_tile_by_colour(F&& f) {
    for (int k = 0; k < 8; ++k) {
      std::vector<std::uint32_t> of_colour = tiles_of_colour(k);
      tbb::parallel_for(std::size_t(0), of_colour.size(), [&](std::size_t i) { f(of_colour[i]); });
    }
  }

  // The first greedy over a tile's graded vertices (in precedes order), with the
  // border centres its neighbours published so far: its centres, and its border.
  // (The centres live on in the tile's vertex block only.)
  std::vector<GradedVertex> choose_first(std::uint32_t tile, const std::vector<GradedVertex>& sorted) {
    ext_[tile] = external_centres(tile, border_);
    std::vector<GradedVertex> centres = choose_centres(sorted, ext_[tile], cell_);
    border_[tile] = border_of(tile, centres);
    return centres;
  }

  void run_rounds() {
    std::uint32_t n = triangles_->stream_count();
    // A tile runs again when the external centres it sees (its neighbours' border
    // centres near it) changed since its last run; rechoose_centres re-decides only
    // the vertices near a change. Tiles are visited by colour class, one class after
    // the other, as in the first round: each class sees the borders the classes
    // before it just published (Gauss-Seidel rather than Jacobi: a chain of
    // decisions crosses several tiles in one sweep). The order depends only on the
    // tiling, not on the threads, and the end is the unique fixed point whatever
    // the order (design note).
    double rounds_start = now_seconds();
    std::vector<std::vector<std::uint32_t>> adjacent(n);
    for (std::uint32_t t = 0; t < n; ++t) adjacent[t] = neighbours(t);
    std::vector<std::vector<GradedVertex>>& ext = ext_;
    // Whether a neighbour's border may have changed since the tile's last run: in
    // the first round the later classes' borders came after it.
    std::vector<char> stale(n, 1);
    // Rounds: the first greedy, then every sweep in which some tile re-ran (the last
    // sweep, which only confirms, is not one).
    std::uint64_t rounds = 1, sweep = 0;
    const bool debug = std::getenv("OOCSIMP_DEBUG_ROUNDS") != nullptr;
    for (;;) {
      std::size_t runs = 0;
      std::atomic<std::size_t> reran{0};  // of those, the tiles whose input had changed
      for (int k = 0; k < 8; ++k) {
        std::vector<std::uint32_t> dirty = tiles_of_colour(k, &stale);
        std::vector<char> border_changed(dirty.size(), 0);
        std::vector<std::vector<GradedVertex>> next_border(dirty.size());
        tbb::parallel_for(std::size_t(0), dirty.size(), [&](std::size_t i) {
          std::uint32_t tile = dirty[i];
          std::vector<GradedVertex> next_ext = external_centres(tile, border_);
          if (same_centres(next_ext, ext[tile])) return;
          ++reran;
          TileVertexBlock block(blocks_->block(tile));
          if (rechoose_centres(block, ext[tile], next_ext, cell_)) {
            next_border[i] = border_of(tile, block.centres());
            border_changed[i] = !same_centres(next_border[i], border_[tile]);
          }
          ext[tile] = std::move(next_ext);  // only this tile's own slot
        });
        for (std::size_t i = 0; i < dirty.size(); ++i) {
          std::uint32_t tile = dirty[i];
          stale[tile] = 0;
          ++runs;
          if (!border_changed[i]) continue;
          border_[tile] = std::move(next_border[i]);
          for (std::uint32_t nb : adjacent[tile]) stale[nb] = 1;
        }
      }
      if (runs == 0) break;
      ++sweep;
      if (reran > 0) ++rounds;
      if (debug)
        std::fprintf(stderr, "sweep %llu: %zu tiles looked at, %zu re-run\n", (unsigned long long)sweep, runs,
                     reran.load());
    }
    rounds_seconds_ = now_seconds() - rounds_start;
    if (stats_) stats_->rounds = rounds;
  }

  // Per tile: assignment, vertex quadrics into cluster sums, surviving triangles.
  void assign_and_accumulate() {
    std::uint32_t n = triangles_->stream_count();
    std::size_t buckets = std::max<std::size_t>(1, std::size_t(triangle_count_ / (1 << 22)) + 1);
    bucket_span_ = std::max<std::uint64_t>(1, (triangle_count_ + buckets - 1) / buckets);
    corners_ = std::make_unique<StreamSpill>(temp_dir(), "stitch", sizeof(CornerRecord), 4096, compress_spill_,
                                             allow_.buckets);
    inside_ =
        std::make_unique<StreamSpill>(temp_dir(), "kept", sizeof(KeptTriangle), 1024, compress_spill_, allow_.buckets);
    for (std::size_t b = 0; b < buckets; ++b) {
      corners_->add_stream();
      inside_->add_stream();
    }
    // Cluster buckets by centre index: a bucket's shares must fit in an eighth of
    // the budget even if every vertex were a centre.
    cluster_span_ = std::max<std::uint64_t>(1, options_.memory_budget / 8 / sizeof(PartialCluster));
    std::uint64_t cluster_buckets = input_.positions.count / cluster_span_ + 1;
    partials_ = std::make_unique<StreamSpill>(temp_dir(), "clusters", sizeof(PartialCluster), 64, false, allow_.buckets);
    for (std::uint64_t b = 0; b < cluster_buckets; ++b) partials_->add_stream();
    ProgressReporter* progress = options_.progress;
    if (progress) progress->begin("cluster tiles", n, "tile");
    std::atomic<std::uint32_t> done{0};
    tbb::parallel_for(std::uint32_t(0), n, [&](std::uint32_t tile) {
      std::vector<TriangleRecord> tris = load_triangles(tile);
      // Owned vertices grouped by lookup cube: consecutive assignments then probe the
      // same cubes (by input index, the cluster pass took 15% longer). Their order
      // changes no sum: vertex quadrics follow the triangles, cluster sums are fixed point.
      TileVertexBlock block(blocks_->block(tile));
      std::vector<GradedVertex> owned(block.size());
      for (std::size_t j = 0; j < owned.size(); ++j) owned[j] = block.vertex(block.filed(j));
      // Local vertex id -> position in `owned` (a binary search per corner took 40%
      // of this pass).
      TileLocalMesh mesh(tris, input_.positions);
      std::vector<std::size_t> owned_at(mesh.index.size(), SIZE_MAX);
      for (std::size_t i = 0; i < owned.size(); ++i) owned_at[std::size_t(mesh.ids.find(owned[i].index))] = i;
      std::vector<GradedVertex> near = block.centres();
      std::vector<GradedVertex> ext = external_centres(tile, border_);
      near.insert(near.end(), ext.begin(), ext.end());
      // Per owned vertex: the position in `near` of its cluster's centre.
      std::vector<std::uint32_t> cluster_of = assign_to_centres(owned, near, cell_, options_.assign);

      // Vertex quadrics (Garland & Heckbert: the sum of the incident faces' plane
      // quadrics), in double, relative to the vertex's cluster centre in cell
      // units. A vertex's faces all lie in its tile and are summed in input order,
      // so Q_v is the same for any tiling; Q_v then goes into the cluster's
      // fixed-point sum.
      std::vector<Quadric> vertex_q(owned.size());
      std::vector<KeptTriangle> kept;
      std::vector<CornerRecord> corners;
      const double inv = 1.0 / cell_.size;
      for (std::size_t t = 0; t < tris.size(); ++t) {
        const TriangleRecord& r = tris[t];
        const std::uint32_t* id = &mesh.corners[3 * t];
        std::size_t local[3];
        int owned_count = 0;
        for (int k = 0; k < 3; ++k) {
          local[k] = r.owned(k) ? owned_at[id[k]] : SIZE_MAX;
          owned_count += local[k] != SIZE_MAX;
        }
        const Vec3d p[3] = {mesh.positions[id[0]], mesh.positions[id[1]], mesh.positions[id[2]]};
        // The face's plane once, in cell units relative to its first corner; each
        // owned corner adds it relative to its own cluster's centre.
        Vec3d e1{(p[1].x - p[0].x) * inv, (p[1].y - p[0].y) * inv, (p[1].z - p[0].z) * inv};
        Vec3d e2{(p[2].x - p[0].x) * inv, (p[2].y - p[0].y) * inv, (p[2].z - p[0].z) * inv};
        Vec3d m{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
        double len = std::sqrt(m.x * m.x + m.y * m.y + m.z * m.z);  // twice the area, in cells^2
        if (len > 0)
          for (int k = 0; k < 3; ++k) {
            if (local[k] == SIZE_MAX) continue;
            const Vec3d& c = near[cluster_of[local[k]]].p;
            double d = m.x * (p[0].x - c.x) * inv + m.y * (p[0].y - c.y) * inv + m.z * (p[0].z - c.z) * inv;
            vertex_q[local[k]].add_plane(m, 0.5 / len, d);
          }
        if (owned_count == 3) {
          std::uint64_t c0 = near[cluster_of[local[0]]].index, c1 = near[cluster_of[local[1]]].index,
                        c2 = near[cluster_of[local[2]]].index;
          if (c0 != c1 && c1 != c2 && c0 != c2) kept.push_back(KeptTriangle::of(r.index(), c0, c1, c2));
        } else {
          for (int k = 0; k < 3; ++k)
            if (local[k] != SIZE_MAX)
              corners.push_back({r.index() << 2 | std::uint64_t(k), near[cluster_of[local[k]]].index});
        }
      }
      std::vector<ClusterRecord> sums(near.size());
      for (std::size_t i = 0; i < owned.size(); ++i) {
        ClusterRecord& s = sums[cluster_of[i]];
        const Quadric& q = vertex_q[i];
        const Vec3d& c = near[cluster_of[i]].p;
        double terms[12] = {q.a00, q.a01, q.a02, q.a11, q.a12, q.a22, q.b0, q.b1, q.b2,
                            (owned[i].p.x - c.x) * inv, (owned[i].p.y - c.y) * inv, (owned[i].p.z - c.z) * inv};
        for (int k = 0; k < 12; ++k) s.sum[k].add(Fixed::of(terms[k]));
        ++s.members;
      }
      // Cross-tile corners go to the stitch buckets by triangle index.
      append_by_bucket(*corners_, &corners, [&](const CornerRecord& c) { return (c.t_and_slot >> 2) / bucket_span_; });
      // This tile's shares of clusters go to the cluster buckets, by centre index.
      std::vector<PartialCluster> partial;
      for (std::size_t i = 0; i < near.size(); ++i)
        if (sums[i].members) {
          sums[i].centre = near[i].p;
          partial.push_back({near[i].index, sums[i]});
        }
      append_by_bucket(*partials_, &partial, [&](const PartialCluster& c) { return c.centre / cluster_span_; });
      // The triangles decided here go to the same buckets as the stitch's, so that
      // the output-sized list of kept triangles is built once, at its exact size,
      // instead of growing (and being copied) in the heap tile by tile.
      dedupe_kept_triangles(kept);
      append_by_bucket(*inside_, &kept, [&](const KeptTriangle& k) { return k.index() / bucket_span_; });
      if (progress) progress->set(++done);
    });
    corners_->flush();
    partials_->flush();
    inside_->flush();
    if (progress) progress->end();
  }

  // Cross-tile triangles: their corners' clusters were written by the tiles owning
  // the corners into buckets by triangle index; a bucket fits in memory.
  void stitch_cross_tile_triangles() {
    // At most: every triangle decided in a tile, and one per three stitch corners.
    kept_.reserve(inside_->bytes_appended() / sizeof(KeptTriangle) +
                  corners_->bytes_appended() / sizeof(CornerRecord) / 3);
    for (std::uint32_t b = 0; b < inside_->stream_count(); ++b) {
      std::size_t at = kept_.size();
      kept_.resize(at + inside_->record_count(b));
      inside_->read_into(b, kept_.data() + at, (kept_.size() - at) * sizeof(KeptTriangle));
    }
    stitch_cross_tile_corners(*corners_, &kept_);
    if (stats_) {
      stats_->spill_bytes = triangles_->bytes_on_disk() + vertices_->bytes_on_disk() + corners_->bytes_on_disk() +
                            partials_->bytes_on_disk() + inside_->bytes_on_disk() + blocks_->bytes_on_disk();
      stats_->spill_raw_bytes = triangles_->bytes_spilled() + vertices_->bytes_spilled() + corners_->bytes_spilled() +
                                partials_->bytes_spilled() + inside_->bytes_spilled() + blocks_->bytes_on_disk();
      stats_->spill_bytes_in_memory = triangles_->bytes_kept_in_memory() + corners_->bytes_kept_in_memory() +
                                      partials_->bytes_kept_in_memory() + inside_->bytes_kept_in_memory() +
                                      blocks_->bytes_in_memory();
    }
  }

  // Appends `records` to `spill`, a run per bucket(record), after sorting them by
  // it (stably: within a bucket the records keep their order).
  template <class Record, class Bucket>
  static void append_by_bucket(StreamSpill& spill, std::vector<Record>* records, Bucket bucket) {
    std::vector<Record>& r = *records;
    std::stable_sort(r.begin(), r.end(), [&](const Record& a, const Record& b) { return bucket(a) < bucket(b); });
    for (std::size_t i = 0; i < r.size();) {
      std::uint64_t k = bucket(r[i]);
      std::size_t j = i;
      while (j < r.size() && bucket(r[j]) == k) ++j;
      spill.append(std::uint32_t(k), &r[i], j - i);
      i = j;
    }
  }

  Vec3d representative(const ClusterRecord& s) const {
    const Vec3d& c = s.centre;
    double m = double(std::max<std::uint64_t>(s.members, 1));
    Vec3d mean{s.sum[9].value() / m, s.sum[10].value() / m, s.sum[11].value() / m};  // relative, in cells
    Vec3d x;
    switch (options_.representative) {
      case RepresentativeRule::centre: return c;
      case RepresentativeRule::mean: x = mean; break;
      case RepresentativeRule::quadric: {
        Quadric q;
        double* coeff = &q.a00;  // a00 a01 a02 a11 a12 a22 b0 b1 b2, as in sum[]
        for (int i = 0; i < 9; ++i) coeff[i] = s.sum[i].value();
        // Kept inside the floating cell: the cube around the centre, then (for a
        // spherical cell) pulled back onto the sphere.
        x = minimize_quadric(q, mean, {-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
        if (cell_.shape == CellShape::sphere) {
          double r = std::sqrt(x.x * x.x + x.y * x.y + x.z * x.z);
          if (r > 0.5) x = {x.x * 0.5 / r, x.y * 0.5 / r, x.z * 0.5 / r};
        }
        break;
      }
    }
    return {c.x + x.x * cell_.size, c.y + x.y * cell_.size, c.z + x.z * cell_.size};
  }

  SimplifiedMesh assemble() {
    std::vector<KeptTriangle>& tris = kept_;
    dedupe_kept_triangles(tris);
    tbb::parallel_sort(tris.begin(), tris.end(), [](const KeptTriangle& a, const KeptTriangle& b) {
      return a.index() < b.index();  // input order of first occurrence
    });
    // Output vertices are the clusters in order of first use; CellMap numbers its
    // keys in insertion order, which is exactly that.
    CellMap<char> index(2 * tris.size() + 16);
    SimplifiedMesh mesh;
    mesh.triangles.reserve(3 * tris.size());
    for (const KeptTriangle& t : tris)
      for (std::uint64_t c : t.corners()) mesh.triangles.push_back(index.insert(c));
    const std::uint64_t output_triangles = tris.size();
    std::vector<KeptTriangle>().swap(kept_);
    // Representatives, a cluster bucket at a time: merge each centre's shares (in
    // fixed point, so in any order) and solve for the clusters some triangle uses.
    mesh.positions.assign(3 * index.size(), 0.0);
    std::uint64_t clusters = 0;
    for (std::uint32_t b = 0; b < partials_->stream_count(); ++b) {
      std::vector<PartialCluster> shares;
      partials_->read(b, &shares);
      // Shares of one centre in any order: they are summed in fixed point.
      tbb::parallel_sort(shares.begin(), shares.end(),
                         [](const PartialCluster& a, const PartialCluster& c) { return a.centre < c.centre; });
      std::vector<std::size_t> starts;  // first share of each centre
      for (std::size_t i = 0; i < shares.size(); ++i)
        if (i == 0 || shares[i].centre != shares[i - 1].centre) starts.push_back(i);
      clusters += starts.size();
      starts.push_back(shares.size());
      tbb::parallel_for(std::size_t(0), starts.size() - 1, [&](std::size_t k) {
        std::int64_t id = index.find(shares[starts[k]].centre);
        if (id < 0) return;  // a cluster no output triangle uses
        ClusterRecord sum = shares[starts[k]].sums;
        for (std::size_t i = starts[k] + 1; i < starts[k + 1]; ++i) sum.add(shares[i].sums);
        Vec3d p = representative(sum);
        mesh.positions[3 * std::size_t(id)] = p.x;
        mesh.positions[3 * std::size_t(id) + 1] = p.y;
        mesh.positions[3 * std::size_t(id) + 2] = p.z;
      });
    }
    if (stats_) {
      stats_->input_triangles = triangle_count_;
      stats_->skipped = resumed_ ? resumed_skipped_ : input_.triangles->skipped();
      stats_->occupied_cells = clusters;
      stats_->output_vertices = index.size();
      stats_->output_triangles = output_triangles;
      stats_->tiles = triangles_->stream_count();
    }
    return mesh;
  }

  MeshInput& input_;
  const SimplifyOptions& options_;
  FloatingCellShape cell_;
  double half_;
  SimplifyStats* stats_;
  TileGeometry tiles_;
  std::unique_ptr<StreamSpill> triangles_, vertices_, corners_;
  std::unique_ptr<StreamSpill> inside_;  // triangles decided in their tile, by triangle-index bucket
  // Per tile its graded vertices for the rounds and the clustering (TileVertexBlock).
  // The vertices_ spill holds the same only for --keep-tmp, in the kept format.
  std::unique_ptr<BlockStore> blocks_;
  SpillAllowances allow_;  // what the spills may hold in memory
  std::unordered_map<GridCoord, std::uint32_t, GridCoordHash> tile_ids_;
  std::vector<GridCoord> tile_coords_;
  std::uint64_t triangle_count_ = 0;
  double rounds_seconds_ = 0;
  bool resumed_ = false;
  SkippedFaces resumed_skipped_;
  FileIdentity kept_input_;                          // --keep-tmp: the input when binning started
  std::unique_ptr<BackgroundDigest> input_digest_;  // --keep-tmp: its checksum, read while binning
  // The kept vertex spill barely compresses (positions and weights are noise to
  // zstd: 422 vs 498 MiB for the whole spill of the 10M sphere, when every round
  // read it). The triangle spill: see bin_triangles().
  static constexpr bool compress_vertices_ = false;
  bool compress_spill_ = true;  // the triangle, stitch and kept-triangle spills; see spill_compression()
  std::uint64_t bucket_span_ = 1;
  std::vector<std::vector<GradedVertex>> border_;  // per tile, its centres whose cells reach outside it
  std::vector<std::vector<GradedVertex>> ext_;  // per tile, the external centres it last ran with
  std::unique_ptr<StreamSpill> partials_;  // PartialCluster shares, bucketed by centre index
  std::uint64_t cluster_span_ = 1;           // centre indices per bucket
  std::vector<KeptTriangle> kept_;           // candidates, deduplicated per tile and bucket
};

}  // namespace

SimplifiedMesh cluster_floating(MeshInput& input, const SimplifyOptions& options, double cell, SimplifyStats* stats) {
  // Tiles allocate and free buffers of 0.1-10 MiB on every thread. glibc's dynamic
  // threshold would soon serve even the largest from its per-thread arenas, which
  // keep freed memory: a fixed threshold maps those and unmaps them on free, so the
  // heap follows what is in use. Measured on the 10M sphere, --mem 64M, 2 threads
  // (peak anonymous / system seconds): dynamic 124 MiB / 1.3 s, 256 KiB 90 MiB / 4.0 s
  // (every tile faults its buffers in afresh), 4 MiB 89 MiB / 2.5 s.
  ::mallopt(M_MMAP_THRESHOLD, 4 << 20);
  FloatingRun run(input, options, cell, stats);
  return run.run();
}

}  // namespace oocsimp
