#include "grid/tile_binning.hpp"

#include "grid/tile_memory_gate.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "common/flat_hash_map.hpp"
#include "runtime/memory_budget.hpp"
#include "grid/tile_plan.hpp"
#include "runtime/ordered_pipeline.hpp"
#include "oocsimp/error.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/progress_phase.hpp"
#include "io/temp_file.hpp"

namespace oocsimp {

namespace {

/// Binning's unit of work: triangles read in input order, their records grouped by tile.
constexpr std::size_t kBinChunk = 1 << 15;

struct BinChunk {
  std::vector<std::uint64_t> tris = std::vector<std::uint64_t>(3 * kBinChunk);
  std::size_t count = 0;
  std::uint64_t first = 0;  // input index of the first triangle
  // The chunk's records grouped by tile, each group in input order, so each tile
  // gets one append: group g is records[group_start[g], group_start[g + 1]) of
  // tile tiles.key(g).
  std::vector<TriangleRecord> records;
  FlatHashSet<GridCoord, GridCoordHash> tiles;  // the chunk's tiles, numbered in order of first use
  std::vector<std::uint32_t> group_start;
  // Scratch: the chunk-local tile of each record in input order, and the next
  // free place of each group while grouping.
  std::vector<std::pair<std::uint32_t, TriangleRecord>> filed;
  std::vector<std::uint32_t> at;

  // Groups `filed` by chunk-local tile with a counting sort (stable: input order
  // within a tile), instead of sorting 56-byte (coordinate, record) pairs.
  void group() {
    const std::size_t count = tiles.size();
    group_start.assign(count + 1, 0);
    for (const auto& f : filed) ++group_start[f.first + 1];
    for (std::size_t g = 0; g < count; ++g) group_start[g + 1] += group_start[g];
    records.resize(filed.size());
    at.assign(group_start.begin(), group_start.end() - 1);
    for (const auto& f : filed) records[at[f.first]++] = f.second;
  }
  /// The chunk-local number of tile c.
  std::uint32_t local_tile(const GridCoord& c) { return tiles.insert(c); }
};

}  // namespace

std::vector<TriangleRecord> BinnedTiles::load(std::uint32_t tile) const {
  std::vector<TriangleRecord> t;
  triangles->read(tile, &t);
  // Input order matters: a vertex quadric sums its faces in this order. Binning
  // appends in input order, so this is normally sorted already.
  auto by_index = [](const TriangleRecord& a, const TriangleRecord& b) { return a.index() < b.index(); };
  if (!std::is_sorted(t.begin(), t.end(), by_index)) std::sort(t.begin(), t.end(), by_index);
  return t;
}

std::uint64_t BinnedTiles::largest_tile_records() const {
  std::uint64_t most = 0;
  for (std::uint32_t t = 0; t < triangles->stream_count(); ++t) most = std::max(most, triangles->record_count(t));
  return most;
}

std::uint64_t tile_work_share(std::uint64_t budget, std::uint64_t fullest_tile_records) {
  const unsigned threads = unsigned(std::max(1, tbb::this_task_arena::max_concurrency()));
  const std::uint64_t planned = std::uint64_t(2 * threads * kMaxTileTriangles * kTileBytesPerTriangle);
  // Tiles fuller than planned (a dense part of the input) get up to half the budget,
  // so that two of them can still run at once.
  return std::min(budget / 2, std::max(planned, fullest_tile_records * kTileBytesPerRecord * 5 / 4));
}

std::uint64_t tile_memory_reserve(std::uint64_t work_share, std::uint64_t fullest_tile_records) {
  // A tile over the share runs alone (TileMemoryGate), so the tiles in work take the
  // share or the fullest tile, whichever is more. The plan's estimate of the fullest
  // tile comes from a sample: a quarter more.
  return std::max(work_share, fullest_tile_records * kTileBytesPerRecord * 5 / 4);
}

// The raw triangle spill, estimated: most triangles are binned into one tile.
static std::uint64_t triangle_spill_bytes(const MeshInput& input) {
  return input.info.face_count * sizeof(TriangleRecord) * 5 / 4;
}

// The spills' memory allowances: what the budget leaves after the threads' tiles
// (half the budget, or what kMaxTileTriangles tiles can take: the fullest tile is
// up to twice the planned one), the binning buffers (a quarter) and the output
// tables (an eighth). Kept tiles go to their file anyway.
static SpillAllowances memory_for_spills(const MeshInput& input, const TileSettings& settings,
                                         std::size_t vertex_record_bytes, std::uint64_t tiles) {
  const std::uint64_t budget = settings.memory_budget;
  return spill_allowances(budget, tiles + budget / 4 + budget / 8, settings.keep_temp ? 0 : triangle_spill_bytes(input),
                          input.positions.count * vertex_record_bytes * 3 / 2);
}

// Whether the triangle, stitch and kept-triangle spills are zstd-compressed. zstd
// about halves the triangle spill but costs a noticeable share of the run's time;
// it pays only where the spill goes to the disk, not where memory or the page cache
// holds it (and kept tiles outlive the run on disk).
static bool spill_compression(const MeshInput& input, const TileSettings& settings, const SpillAllowances& allow) {
  switch (settings.spill_compression) {
    case SpillCompression::zstd:
      return true;
    case SpillCompression::none:
      return false;
    case SpillCompression::automatic:
      break;
  }
  // What goes to the disk: the part that does not stay in memory.
  const std::uint64_t to_disk = triangle_spill_bytes(input) - std::min(triangle_spill_bytes(input), allow.triangles);
  return settings.keep_temp || to_disk > available_memory_bytes() / 2;
}

SpillSettings spill_settings(const MeshInput& input, const TileSettings& settings, std::size_t vertex_record_bytes,
                             std::uint64_t fullest_tile_records, std::uint64_t work_share) {
  SpillSettings s;
  s.dir = settings.temp_dir.empty() ? default_temp_dir() : settings.temp_dir;
  const std::uint64_t budget = settings.memory_budget;
  s.work_share = work_share ? work_share : tile_work_share(budget, fullest_tile_records);
  const std::uint64_t fullest = fullest_tile_records * kTileBytesPerRecord;
  if (fullest > budget / 4 * 3)
    throw UsageError(
        "options.memory_budget",
        "options.memory_budget " + whole_mib(budget) + " MiB cannot hold the fullest tile of " + input.info.path +
            " (about " + std::to_string(fullest_tile_records) + " triangle records, " + whole_mib(fullest) +
            " MiB to grade, estimated from a sample): a dense part of the mesh; give options.memory_budget " +
            whole_mib(fullest / 3 * 4) +
            " MiB or more, or a larger options.sizing.cell (options.sizing.grid, options.sizing.ratio)");
  s.allow =
      memory_for_spills(input, settings, vertex_record_bytes, tile_memory_reserve(s.work_share, fullest_tile_records));
  s.compress = spill_compression(input, settings, s.allow);
  // A lower estimate, so no run that fits is refused: every used vertex is spilled
  // once, raw; the triangle records compress to an eighth or more, and (a header's
  // face count being unchecked so far) to no less than the input file holds.
  s.expected_bytes = input.positions.count * vertex_record_bytes +
                     std::min<std::uint64_t>(input.info.face_count * (sizeof(TriangleRecord) / 8), input.file_size);
  return s;
}

BinnedTiles bin_triangles(MeshInput& input, double tile_side, std::uint64_t memory_budget, const SpillSettings& spill,
                          const ProgressCallback& progress, const TileFilter& keep) {
  BinnedTiles out;
  TileGrid& tiles = out.grid;
  tiles.side = tile_side;
  std::uint64_t budget = memory_budget;
  // Buffers of all tiles together take at most a quarter of the budget.
  std::size_t est_tiles = 64;
  {
    const Box3d& b = input.info.bounds;
    if (!b.empty()) {
      double n = 1;
      for (double e : {b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z}) n *= std::floor(e / tiles.side) + 1;
      est_tiles = std::size_t(std::min(n, 1e6));
    }
  }
  // Blocks beyond 32 KiB buy nothing: larger buffers ran no faster and only raised
  // the peak memory.
  std::size_t buffer_records = std::clamp<std::size_t>(
      std::size_t(double(budget) / 4 / double(est_tiles) / sizeof(TriangleRecord)), kMinBufferRecords, 1024);
  // Free space for the spill, checked before writing it, when some of it goes to the disk.
  if (spill.expected_bytes > spill.allow.triangles + spill.allow.vertex_blocks)
    require_free_space(spill.dir, spill.expected_bytes, "the tile spill");
  out.triangles = std::make_unique<StreamSpill>(spill.dir, "tiles", sizeof(TriangleRecord), buffer_records,
                                                spill.compress, spill.allow.triangles);
  StreamSpill& triangles = *out.triangles;
  triangles.set_expected_bytes(spill.expected_bytes);
  std::vector<char> kept;  // per tile, whether it keeps its records
  auto tile_id = [&](const GridCoord& c) {
    std::int64_t id = tiles.find(c);
    if (id >= 0) return std::uint32_t(id);
    triangles.add_stream();  // stream `tile` holds the tile's triangles
    kept.push_back(!keep || keep(c));
    return tiles.add(c);
  };

  const PositionArray& pos = input.positions;
  TriangleStream& stream = *input.triangles;
  std::uint64_t next = 0;
  ProgressPhase phase(progress, "bin tiles", input.file_size, "B");
  run_ordered_pipeline<BinChunk>(
      2 * std::size_t(std::max(1, tbb::this_task_arena::max_concurrency())),
      [&](BinChunk& c) {
        c.count = stream.read(c.tris.data(), kBinChunk);
        c.first = next;
        next += c.count;
        phase.set(stream.bytes_consumed());
        return c.count > 0;
      },
      [&](BinChunk& c) {
        c.filed.clear();
        c.tiles.clear();
        for (std::size_t i = 0; i < c.count; ++i) {
          std::uint64_t t = c.first + i;
          TriangleRecord r{t, {c.tris[3 * i], c.tris[3 * i + 1], c.tris[3 * i + 2]}};
          GridCoord k[3];
          for (int j = 0; j < 3; ++j) k[j] = tiles.of(pos.get(r.v[j]));
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
        for (std::size_t g = 0; g + 1 < c.group_start.size(); ++g) {
          const std::uint32_t id = tile_id(c.tiles.key(g));
          if (kept[id]) triangles.append(id, &c.records[c.group_start[g]], c.group_start[g + 1] - c.group_start[g]);
        }
      });
  triangles.flush();
  out.triangle_count = next;
  out.skipped = stream.skipped();
  return out;
}

}  // namespace oocsimp
