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
#include "io/face_range.hpp"
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

TriangleRecords BinnedTiles::load(std::uint32_t tile) const {
  TriangleRecords t;
  triangles->read(tile, &t);
  // Input order matters: a vertex quadric sums its faces in this order. Binning
  // appends in input order, so this is normally sorted already; parts that read
  // ranges append runs in input order (bin_own_face_range), merged here pairwise.
  auto by_index = [](const TriangleRecord& a, const TriangleRecord& b) { return a.index() < b.index(); };
  std::vector<std::size_t> runs{0};
  for (std::size_t i = 1; i < t.size(); ++i)
    if (t[i].index() < t[i - 1].index()) runs.push_back(i);
  runs.push_back(t.size());
  while (runs.size() > 2) {
    std::vector<std::size_t> merged{0};
    for (std::size_t r = 0; r + 1 < runs.size(); r += 2) {
      if (r + 2 < runs.size())
        std::inplace_merge(t.begin() + std::ptrdiff_t(runs[r]), t.begin() + std::ptrdiff_t(runs[r + 1]),
                           t.begin() + std::ptrdiff_t(runs[r + 2]), by_index);
      merged.push_back(runs[std::min(r + 2, runs.size() - 1)]);
    }
    runs = std::move(merged);
  }
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

namespace {

// Binning's steps, for a whole input or a part's range of it: the tile spill and
// the tiles numbered in order of first use, then bin() for each run of triangles.
class TileBinner {
 public:
  // Records of a tile that `keep` refuses go to the `away` of bin() (or nowhere).
  TileBinner(const MeshInput& input, double tile_side, std::uint64_t memory_budget, const SpillSettings& spill,
             TileFilter keep)
      : pos_(input.positions), keep_(std::move(keep)) {
    out_.grid.side = tile_side;
    // Buffers of all tiles together take at most a quarter of the budget.
    std::size_t est_tiles = 64;
    const Box3d& b = input.info.bounds;
    if (!b.empty()) {
      double n = 1;
      for (double e : {b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z}) n *= std::floor(e / tile_side) + 1;
      est_tiles = std::size_t(std::min(n, 1e6));
    }
    // Blocks beyond 32 KiB buy nothing: larger buffers ran no faster and only raised
    // the peak memory.
    const std::size_t buffer_records = std::clamp<std::size_t>(
        std::size_t(double(memory_budget) / 4 / double(est_tiles) / sizeof(TriangleRecord)), kMinBufferRecords, 1024);
    // Free space for the spill, checked before writing it, when some of it goes to the disk.
    if (spill.expected_bytes > spill.allow.triangles + spill.allow.vertex_blocks)
      require_free_space(spill.dir, spill.expected_bytes, "the tile spill");
    out_.triangles = std::make_unique<StreamSpill>(spill.dir, "tiles", sizeof(TriangleRecord), buffer_records,
                                                   spill.compress, spill.allow.triangles);
    out_.triangles->set_expected_bytes(spill.expected_bytes);
  }

  // The id of the tile at `c`, numbered as it comes first.
  std::uint32_t tile_id(const GridCoord& c) {
    const std::int64_t id = out_.grid.find(c);
    if (id >= 0) return std::uint32_t(id);
    out_.triangles->add_stream();  // stream `tile` holds the tile's triangles
    kept_.push_back(!keep_ || keep_(c));
    met_.push_back(0);
    return out_.grid.add(c);
  }

  // A run of records of one tile that it does not keep.
  using AwaySink = std::function<void(std::uint32_t tile, const TriangleRecord* records, std::size_t count)>;

  // Bins the triangles of `stream`, numbered from `first`: every triangle goes to the
  // tile of each of its corners. Returns the triangles read.
  std::uint64_t bin(TriangleStream& stream, std::uint64_t first, ProgressPhase& phase, const AwaySink& away = nullptr) {
    std::uint64_t next = first;
    StreamSpill& triangles = *out_.triangles;
    run_ordered_pipeline<BinChunk>(
        2 * std::size_t(std::max(1, tbb::this_task_arena::max_concurrency())),
        [&](BinChunk& c) {
          c.count = stream.read(c.tris.data(), kBinChunk);
          c.first = next;
          next += c.count;
          phase.set(stream.bytes_consumed());
          return c.count > 0;
        },
        [&](BinChunk& c) { file_records(c); },
        [&](BinChunk& c) {
          for (std::size_t g = 0; g + 1 < c.group_start.size(); ++g) {
            const std::uint32_t id = tile_id(c.tiles.key(g));
            if (!met_[id]) {
              met_[id] = 1;
              met_order_.push_back(out_.grid.coord(id));
            }
            const TriangleRecord* records = &c.records[c.group_start[g]];
            const std::size_t count = c.group_start[g + 1] - c.group_start[g];
            if (kept_[id])
              triangles.append(id, records, count);
            else if (away)
              away(id, records, count);
          }
        });
    return next - first;
  }

  // The tiles in the order bin() met them first (tiles only added by tile_id after
  // another part's records left out).
  const std::vector<GridCoord>& met_order() const { return met_order_; }

  /// The tiles binned so far.
  BinnedTiles& result() { return out_; }
  /// The binned tiles, handed over: the binner is done.
  BinnedTiles take() { return std::move(out_); }

 private:
  // A chunk's records, grouped by tile.
  void file_records(BinChunk& c) const {
    c.filed.clear();
    c.tiles.clear();
    for (std::size_t i = 0; i < c.count; ++i) {
      const std::uint64_t t = c.first + i;
      TriangleRecord r{t, {c.tris[3 * i], c.tris[3 * i + 1], c.tris[3 * i + 2]}};
      GridCoord k[3];
      for (int j = 0; j < 3; ++j) k[j] = out_.grid.of(pos_.get(r.v[j]));
      for (int j = 0; j < 3; ++j) {
        if ((j >= 1 && k[j] == k[0]) || (j == 2 && k[2] == k[1])) continue;  // tile already has it
        std::uint64_t mask = 0;
        for (int m = 0; m < 3; ++m) mask |= std::uint64_t(k[m] == k[j]) << m;
        r.tm = t | mask << TriangleRecord::kMaskShift;
        c.filed.push_back({c.local_tile(k[j]), r});
      }
    }
    c.group();
  }

  const PositionArray& pos_;
  TileFilter keep_;
  BinnedTiles out_;
  std::vector<char> kept_;  // per tile, whether it keeps its records
  std::vector<char> met_;   // per tile, whether bin() has met it
  std::vector<GridCoord> met_order_;
};

}  // namespace

BinnedTiles bin_triangles(MeshInput& input, double tile_side, std::uint64_t memory_budget, const SpillSettings& spill,
                          const ProgressCallback& progress, const TileFilter& keep) {
  TileBinner binner(input, tile_side, memory_budget, spill, keep);
  TriangleStream& stream = *input.triangles;
  ProgressPhase phase(progress, "bin tiles", input.file_size, "B");
  const std::uint64_t triangles = binner.bin(stream, 0, phase);
  BinnedTiles out = binner.take();
  out.triangle_count = triangles;
  out.triangles->flush();
  out.skipped = stream.skipped();
  out.faces_read = input.info.face_count;
  return out;
}

namespace {

// A part's message of records for another part's tiles: runs of one tile's records,
// each after its tile's coordinates and count.
struct AwayRun {
  GridCoord tile;
  std::uint64_t count = 0;
};

void append_bytes(std::vector<unsigned char>& to, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  to.insert(to.end(), p, p + bytes);
}

// What a part tells the others before the parts read their ranges: its range's scan
// and what it planned, which must agree.
struct RangeScanMessage {
  std::uint64_t readable = 0;  // 1 or 0
  std::uint64_t triangles = 0, short_faces = 0, non_finite = 0, repeated_index = 0;
  std::uint64_t faces = 0, vertices = 0;  // the input's, as this part opened it
  double tile_side = 0;
  std::uint64_t step = 0;  // faces it would bin between two sends
};

// What a part learns from the others' range scans: whether every range can be read
// alone, the triangle index its range starts at, and the whole input's counts.
struct RangePlan {
  bool readable = true;
  std::uint64_t first_triangle = 0, triangles = 0;
  std::uint64_t step = 0;  // faces a part bins between two sends: the least any part asked
  SkippedFaces skipped;
};

RangePlan plan_ranges(const MeshInput& input, const TileShare& share, std::uint64_t first, std::uint64_t end,
                      double tile_side, std::uint64_t step) {
  const FaceRangeScan scan = scan_face_range(input, first, end);
  RangeScanMessage mine;
  mine.readable = scan.readable ? 1 : 0;
  mine.triangles = scan.triangles;
  mine.short_faces = scan.skipped.short_faces;
  mine.non_finite = scan.skipped.non_finite;
  mine.repeated_index = scan.skipped.repeated_index;
  mine.faces = input.fixed_faces.count;
  mine.vertices = input.positions.count;
  mine.tile_side = tile_side;
  mine.step = step;
  RangePlan plan;
  plan.step = step;
  const std::vector<std::vector<unsigned char>> all = share.exchange(record_bytes(&mine, 1));
  for (std::size_t p = 0; p < all.size(); ++p) {
    const std::vector<RangeScanMessage> sent = records_of_bytes<RangeScanMessage>(all[p]);
    const RangeScanMessage theirs = sent.size() == 1 ? sent[0] : RangeScanMessage();
    // Any range that cannot be read alone, or a part that opened another input or
    // tiled otherwise (another --mem), and every part bins the whole stream: that
    // reports a bad face as one process does, and the tilings are compared after.
    plan.readable = plan.readable && theirs.readable == 1 && theirs.faces == mine.faces &&
                    theirs.vertices == mine.vertices && theirs.tile_side == tile_side;
    plan.step = std::min(plan.step, std::max<std::uint64_t>(theirs.step, 1));
    if (p < share.part) plan.first_triangle += theirs.triangles;
    plan.triangles += theirs.triangles;
    plan.skipped.short_faces += theirs.short_faces;
    plan.skipped.non_finite += theirs.non_finite;
    plan.skipped.repeated_index += theirs.repeated_index;
  }
  return plan;
}

// Every part's tiles in the order its range met them, joined: the order one process
// meets them in the whole stream.
std::vector<GridCoord> tiles_in_input_order(const TileShare& share, const std::vector<GridCoord>& met) {
  FlatHashSet<GridCoord, GridCoordHash> listed;  // numbered in the order first listed
  for (const std::vector<unsigned char>& theirs : share.exchange(record_bytes(met.data(), met.size())))
    for (const GridCoord& c : records_of_bytes<GridCoord>(theirs)) listed.insert(c);
  std::vector<GridCoord> order(listed.size());
  for (std::size_t t = 0; t < order.size(); ++t) order[t] = listed.key(t);
  return order;
}

}  // namespace

std::optional<BinnedTiles> bin_own_face_range(MeshInput& input, double tile_side, std::uint64_t memory_budget,
                                              const SpillSettings& spill, const ProgressCallback& progress,
                                              const TileOwners& owners, const TileShare& share) {
  const std::uint64_t faces = input.fixed_faces.count;
  const std::uint64_t first = even_split_start(faces, share.part, share.parts);
  const std::uint64_t end = even_split_start(faces, share.part + 1, share.parts);
  // The range in steps, the other parts' records sent after each, so that what is
  // on its way takes a sixteenth of the budget (sent and received; through the
  // exchange, every part receives every part's messages). Every part takes as many
  // steps as the longest range.
  const std::uint64_t on_the_way = share.deliver ? 2 : std::uint64_t(share.parts) + 1;
  const RangePlan plan = plan_ranges(
      input, share, first, end, tile_side,
      std::max<std::uint64_t>(kBinChunk, memory_budget / 16 / on_the_way / (sizeof(TriangleRecord) + sizeof(AwayRun))));
  if (!plan.readable) return std::nullopt;
  const std::uint64_t step = plan.step;

  TileBinner binner(input, tile_side, memory_budget, spill,
                    [&](const GridCoord& c) { return tile_owner(owners, c) == share.part; });
  StreamSpill& triangles = *binner.result().triangles;
  const std::uint64_t longest = even_split_start(faces, 1, share.parts) + 1;
  const std::uint64_t steps = (longest + step - 1) / step;
  std::vector<std::vector<unsigned char>> to_each(share.parts);
  const TileBinner::AwaySink away = [&](std::uint32_t tile, const TriangleRecord* records, std::size_t count) {
    const GridCoord& c = binner.result().grid.coord(tile);
    std::vector<unsigned char>& message = to_each[tile_owner(owners, c)];
    const AwayRun run{c, count};
    append_bytes(message, &run, sizeof run);
    append_bytes(message, records, count * sizeof *records);
  };
  ProgressPhase phase(progress, "bin tiles", (end - first) * FixedFaceTable::kStride, "B");
  std::uint64_t next = plan.first_triangle;
  for (std::uint64_t s = 0; s < steps; ++s) {
    const std::uint64_t from = std::min(end, first + s * step), to = std::min(end, from + step);
    const std::unique_ptr<TriangleStream> stream = open_face_range(input, from, to, first);
    next += binner.bin(*stream, next, phase, away);
    const std::vector<std::vector<unsigned char>> received = share.send(to_each);
    for (std::vector<unsigned char>& message : to_each) message.clear();
    for (const std::vector<unsigned char>& message : received) {
      for (std::size_t at = 0; at + sizeof(AwayRun) <= message.size();) {
        AwayRun run;
        std::memcpy(&run, message.data() + at, sizeof run);
        at += sizeof run;
        if (run.count > (message.size() - at) / sizeof(TriangleRecord))
          throw std::runtime_error("a part sent a damaged run of triangle records");
        triangles.append(binner.tile_id(run.tile), message.data() + at, std::size_t(run.count));
        at += std::size_t(run.count) * sizeof(TriangleRecord);
      }
    }
  }
  // Renumbered as one process numbers the tiles: by first use in the whole stream.
  const std::vector<GridCoord> order = tiles_in_input_order(share, binner.met_order());
  BinnedTiles out = binner.take();
  std::vector<std::uint32_t> old_of_new(order.size(), StreamSpill::kNewStream);
  TileGrid grid;
  grid.side = tile_side;
  for (std::size_t t = 0; t < order.size(); ++t) {
    const std::int64_t old = out.grid.find(order[t]);
    if (old >= 0) old_of_new[t] = std::uint32_t(old);
    grid.add(order[t]);
  }
  out.triangles->flush();
  out.triangles->renumber_streams(old_of_new);
  out.grid = std::move(grid);
  out.triangle_count = plan.triangles;
  out.skipped = plan.skipped;
  out.faces_read = end - first;
  return out;
}

}  // namespace oocsimp
