// The passes of the out-of-core collapse. Each pass:
//  1. cuts space into tiles (the first from the input's bounds, each later one coarser
//     as the mesh thins, every other one shifted by half a tile, so that a border of
//     one pass lies inside a tile of the next);
//  2. takes the error threshold for the whole pass from a sample of its tiles: the
//     error at which the sample, collapsed in order of cost, is left with the share
//     of its faces that the pass aims at (a global threshold, so that error stays even
//     across tiles, where a count per tile would spend it unevenly);
//  3. collapses every tile up to that threshold, its border held (refine/pass_tile),
//     as many at once as the budget holds;
//  4. bins what comes out into the next pass's tiles.
// The passes stop when at most kFinalShare times the target is left: the last
// collapse, in core and in strict order of cost, takes that to the exact count.
//
// Everything the passes decide follows from the input and the target: the tiles, the
// sample, the thresholds. Tiles run in any order on any thread, and each tile sorts
// what it reads (faces by input index, vertices by id), so the result is the same
// for any thread count and any budget that runs.
#include "methods/qem_passes.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "common/huge_pages.hpp"
#include "common/radix_sort.hpp"
#include "common/vec3_math.hpp"
#include "grid/grid_coord.hpp"
#include "grid/occupancy.hpp"
#include "grid/tile_binning.hpp"
#include "grid/tile_memory_gate.hpp"
#include "grid/work_share.hpp"
#include "grid/tile_plan.hpp"
#include "io/attribute_array.hpp"
#include "io/temp_file.hpp"
#include "oocsimp/error.hpp"
#include "refine/pass_tile.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/phase_timer.hpp"
#include "runtime/progress_phase.hpp"
#include "spill/stream_spill.hpp"

namespace oocsimp {

namespace {

// A piece's working set per face: its face records, its mesh for the collapse and
// the collapse's state, and what it gives out. The figure is the peak anonymous
// memory a piece added to an idle process, over its faces, rounded up (measured in
// docs/benchmarks.md, "Memory of the passes"); each carried attribute adds its value
// in the piece's three copies of a vertex, about half a vertex a face.
constexpr std::uint64_t kTileBytesPerFace = 448;
constexpr std::uint64_t kTileBytesPerAttribute = 16;
// The passes stop at this many times the target; the last collapse, in strict order
// of cost, takes the rest. Each pass aims a little below it, as the sample's
// threshold is an estimate and the borders held add to what is left.
constexpr double kFinalShare = 1.25;
constexpr double kAimShare = 1.1;
// A pass that removes less than this share of its faces makes way too slowly: the
// next raises the threshold further.
constexpr double kSlowPass = 0.05;
constexpr int kMaxPasses = 12;
// Tiles collapsed in full to choose a pass's threshold, spread over the pass's tiles.
constexpr std::size_t kSampleTiles = 16;
// The first pass's fullest tile holds at most this many times the average asked for
// (its face records: a face in each tile holding a corner); tiles shrink by this
// factor until it does.
constexpr double kFullestTileShare = 6;
constexpr double kTileShrink = 1.25;
constexpr double kMostTilesShare = 4;
// What a tile holds in work at most, on average, in times the average asked for: a
// first-pass tile fuller than that (a dense spot) is worked on in parts, at most
// kMostParts (first_pass_tile), and a later pass's blocks of tiles (choose_block) stay
// below it. Two such pieces fit the tiles' share of the budget (half of it) from
// 2 * 2 * 1.5 * tile_faces * kTileBytesPerFace on (168 MiB by default), so that two
// threads work at once; one from half that.
constexpr double kPieceShare = 1.5;
constexpr std::uint32_t kMostParts = 64;
// Later passes work on blocks of at most this many binned tiles a side.
constexpr std::int64_t kLargestBlock = 64;
constexpr std::size_t kLeastSampleTiles = 4;
constexpr std::size_t kSampleEvery = 8;  // a sample tile per this many tiles, between the two
// Records per buffer of the next pass's bins: at most the first, at least the second,
// as the budget's share for the buffers (a sixteenth) allows for the tiles expected.
constexpr std::size_t kMostBinRecords = 512;
constexpr std::size_t kLeastBinRecords = 16;
// The next pass's tiles are sized for this many times the faces the pass aims at (the
// borders held add to them), never more than the pass's own: smaller tiles only make
// more of them to join into blocks (choose_block), larger ones could overfill.
constexpr double kExpectedShare = 16;

std::size_t vertex_record_bytes(std::size_t attributes) { return sizeof(PassVertex) + attributes * sizeof(double); }

// Faces by ascending input index, each once: the order a tile takes them in,
// whichever tiles and threads binned them.
void sort_faces(std::vector<PassFace>* faces) {
  auto by_index = [](const PassFace& a, const PassFace& b) { return a.index < b.index; };
  std::sort(faces->begin(), faces->end(), by_index);
  faces->erase(std::unique(faces->begin(), faces->end(),
                           [](const PassFace& a, const PassFace& b) { return a.index == b.index; }),
               faces->end());
}

// Vertices by ascending id, their `k` attribute values each moved with them.
void sort_vertices(std::vector<PassVertex>* owned, std::vector<double>* attributes, std::size_t k) {
  std::vector<std::uint32_t> order;
  resize_filled(&order, owned->size());
  std::iota(order.begin(), order.end(), 0u);
  radix_sort(&order, [&](std::uint32_t a) { return (*owned)[a].id; });
  std::vector<PassVertex> sorted;
  resize_filled(&sorted, order.size());
  std::vector<double> values;
  resize_filled(&values, attributes->size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    sorted[i] = (*owned)[order[i]];
    std::copy(attributes->begin() + std::ptrdiff_t(order[i] * k),
              attributes->begin() + std::ptrdiff_t((order[i] + 1) * k), values.begin() + std::ptrdiff_t(i * k));
  }
  *owned = std::move(sorted);
  *attributes = std::move(values);
}

// A pass's tiles: cubes of side `side` over the run's frame, moved by `shift`.
struct PassTiling {
  double side = 1;
  double shift = 0;
  GridCoord of(const Vec3d& p) const { return GridCoord::of(p + Vec3d{shift, shift, shift}, side); }
};

// The faces and vertices handed to a pass, by tile: a face in each tile holding one
// of its corners, a vertex in the tile holding its position. Tiles add from any
// thread; a tile reads its records back sorted, so their order does not matter.
class PassBins {
 public:
  /// `buffer_records`: records each tile buffers before they become a block.
  PassBins(const std::string& dir, const PassTiling& tiling, std::size_t attributes, std::uint64_t allowance,
           std::size_t buffer_records)
      : tiling_(tiling),
        attributes_(attributes),
        faces_(dir, "qem-faces", sizeof(PassFace), buffer_records, false, allowance / 2),
        vertices_(dir, "qem-vertices", vertex_record_bytes(attributes), buffer_records, false, allowance / 2) {}

  void add(const TileOutput& out) {
    std::map<GridCoord, std::vector<PassFace>> faces;
    for (const PassFace& f : out.faces) {
      const GridCoord c[3] = {tiling_.of(f.p[0]), tiling_.of(f.p[1]), tiling_.of(f.p[2])};
      faces[c[0]].push_back(f);
      if (c[1] != c[0]) faces[c[1]].push_back(f);
      if (c[2] != c[0] && c[2] != c[1]) faces[c[2]].push_back(f);
    }
    const std::size_t record = vertex_record_bytes(attributes_);
    std::map<GridCoord, std::vector<unsigned char>> vertices;
    for (std::size_t i = 0; i < out.owned.size(); ++i) {
      std::vector<unsigned char>& bytes = vertices[tiling_.of(out.owned[i].position)];
      const std::size_t at = bytes.size();
      bytes.resize(at + record);
      std::memcpy(&bytes[at], &out.owned[i], sizeof(PassVertex));
      if (attributes_)
        std::memcpy(&bytes[at + sizeof(PassVertex)], &out.attributes[i * attributes_], attributes_ * sizeof(double));
    }
    for (const auto& g : faces) faces_.append(stream_of(g.first), g.second.data(), g.second.size());
    for (const auto& g : vertices) vertices_.append(stream_of(g.first), g.second.data(), g.second.size() / record);
    std::lock_guard<std::mutex> lock(mutex_);
    face_count_ += out.faces.size();
  }

  /// The tiles, ordered by their coordinates.
  std::vector<std::uint32_t> tiles() const {
    std::vector<std::uint32_t> out;
    for (const auto& t : streams_) out.push_back(t.second);
    return out;
  }
  std::uint64_t faces_in(std::uint32_t tile) const { return faces_.record_count(tile); }
  /// The vertices handed on (each owned by one tile).
  std::uint64_t vertex_count() const { return vertices_.bytes_appended() / vertex_record_bytes(attributes_); }
  /// The distinct faces handed on.
  std::uint64_t face_count() const { return face_count_; }

  /// The pass's tiles: blocks of `k` x `k` x `k` of these tiles (the next pass's
  /// tiling is chosen once its faces are counted), each as its tiles' streams, the
  /// blocks in order of their coordinates.
  std::vector<std::vector<std::uint32_t>> blocks(std::int64_t k) const {
    std::map<GridCoord, std::vector<std::uint32_t>> by_block;
    auto down = [k](std::int64_t x) { return x >= 0 ? x / k : -((-x + k - 1) / k); };
    for (const auto& t : streams_) by_block[{down(t.first.x), down(t.first.y), down(t.first.z)}].push_back(t.second);
    std::vector<std::vector<std::uint32_t>> out;
    for (auto& b : by_block) out.push_back(std::move(b.second));
    return out;
  }

  /// The faces of a block of tiles (each once, by ascending index) and its owned
  /// vertices (by id).
  TileMesh load_block(const std::vector<std::uint32_t>& tiles) const {
    if (tiles.size() == 1) return load(tiles[0]);
    TileMesh m;
    m.attribute_count = attributes_;
    std::size_t faces = 0, vertices = 0;
    for (std::uint32_t t : tiles) {
      faces += std::size_t(faces_.record_count(t));
      vertices += std::size_t(vertices_.record_count(t));
    }
    reserve_filled(&m.faces, faces);
    reserve_filled(&m.owned, vertices);
    reserve_filled(&m.attributes, vertices * attributes_);
    for (std::uint32_t t : tiles) {
      TileMesh part = load(t);
      m.faces.insert(m.faces.end(), part.faces.begin(), part.faces.end());
      m.owned.insert(m.owned.end(), part.owned.begin(), part.owned.end());
      m.attributes.insert(m.attributes.end(), part.attributes.begin(), part.attributes.end());
    }
    sort_faces(&m.faces);  // a face reaching two of the block's tiles is in both
    sort_vertices(&m.owned, &m.attributes, attributes_);
    return m;
  }

  /// Whether `tile` holds position p.
  bool holds(std::uint32_t tile, const Vec3d& p) const { return tiling_.of(p) == coords_[tile]; }

  /// The tile's faces (sorted by index) and owned vertices (sorted by id), or only
  /// the one or the other.
  TileMesh load(std::uint32_t tile, bool with_faces = true, bool with_vertices = true) const {
    TileMesh m;
    m.attribute_count = attributes_;
    if (with_faces) {
      reserve_filled(&m.faces, std::size_t(faces_.record_count(tile)));
      faces_.read(tile, &m.faces);
      sort_faces(&m.faces);
    }
    if (!with_vertices) return m;
    std::vector<unsigned char> bytes;
    vertices_.read(tile, &bytes);
    const std::size_t record = vertex_record_bytes(attributes_), n = bytes.size() / record;
    resize_filled(&m.owned, n);
    resize_filled(&m.attributes, n * attributes_);
    for (std::size_t i = 0; i < n; ++i) {
      std::memcpy(&m.owned[i], &bytes[i * record], sizeof(PassVertex));
      if (attributes_)
        std::memcpy(&m.attributes[i * attributes_], &bytes[i * record + sizeof(PassVertex)],
                    attributes_ * sizeof(double));
    }
    sort_vertices(&m.owned, &m.attributes, attributes_);
    return m;
  }

 private:
  std::uint32_t stream_of(const GridCoord& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = streams_.find(c);
    if (it != streams_.end()) return it->second;
    const std::uint32_t id = faces_.add_stream();
    vertices_.add_stream();
    streams_.emplace(c, id);
    coords_.push_back(c);
    return id;
  }

  PassTiling tiling_;
  std::size_t attributes_;
  StreamSpill faces_, vertices_;
  std::map<GridCoord, std::uint32_t> streams_;  // guarded by mutex_ while tiles add
  std::vector<GridCoord> coords_;               // each stream's tile
  std::uint64_t face_count_ = 0;
  std::mutex mutex_;
};

// The parts a tile of `records` face records is cut into: the fewest that bring the
// records per part to `most` on average.
std::uint32_t parts_of(std::uint64_t records, std::uint64_t most) {
  return std::uint32_t(std::clamp<std::uint64_t>((records + most - 1) / most, 1, kMostParts));
}

// The first pass's tile `t` from the binned input: positions and attributes from the
// input, quadrics still to sum.
//
// A tile that holds more than `most` face records is worked on in parts: n slabs of
// it along x (n the fewest that bring the records per part to `most` on average),
// each owning the tile's vertices that fall in it, with the faces around them; `part`
// says which (0 to n - 1). Slabs, not cubes: the fewest parts, each of which reads
// the whole tile. The parts follow from the tile's records alone.
TileMesh first_pass_tile(const BinnedTiles& bins, std::uint32_t t, const MeshInput& input, const Vec3d& origin,
                         std::uint64_t most, std::uint32_t part) {
  const auto records = bins.load(t);
  const std::uint32_t n = parts_of(records.size(), most);
  const Box3d box = bins.grid.box(t);
  auto part_of = [&](const Vec3d& p) {
    const double side = bins.grid.side / double(n);
    return std::uint32_t(std::clamp<std::int64_t>(GridCoord::axis(p.x - box.min.x, side), 0, std::int64_t(n) - 1));
  };
  TileMesh m;
  m.first_pass = true;
  const std::size_t k = input.attributes.size();
  m.attribute_count = k;
  // Its faces, and its owned corners a corner at a time: no regrowth. Whole, the tile
  // keeps every record (each has a corner in it) and owns nearly three corners a
  // record, so the room is filled; in parts, a share of it.
  std::vector<std::uint64_t> owned;
  if (n == 1) {
    reserve_filled(&m.faces, records.size());
    reserve_filled(&owned, 3 * records.size());
  } else {
    reserve_huge(&m.faces, records.size());
    owned.reserve(3 * records.size());
  }
  for (const TriangleRecord& r : records) {
    // The corners this part owns: the tile's, and in the part's slab.
    bool mine[3];
    Vec3d absolute[3];
    for (int c = 0; c < 3; ++c) {
      absolute[c] = input.positions.get(r.v[c]);
      mine[c] = r.owned(c) && (n == 1 || part_of(absolute[c]) == part);
    }
    if (!mine[0] && !mine[1] && !mine[2]) continue;
    PassFace f;
    f.index = r.index();
    for (int c = 0; c < 3; ++c) {
      f.v[c] = r.v[c];
      f.p[c] = absolute[c] - origin;
      if (mine[c]) owned.push_back(r.v[c]);
    }
    f.normal = unit_normal(cross(f.p[1] - f.p[0], f.p[2] - f.p[0]));
    m.faces.push_back(f);
  }
  radix_sort(&owned, [](std::uint64_t id) { return id; });
  owned.erase(std::unique(owned.begin(), owned.end()), owned.end());
  resize_filled(&m.owned, owned.size());
  resize_filled(&m.attributes, owned.size() * k);
  for (std::size_t i = 0; i < owned.size(); ++i) {
    m.owned[i].id = owned[i];
    m.owned[i].position = input.positions.get(owned[i]) - origin;
    for (std::size_t j = 0; j < k; ++j) m.attributes[i * k + j] = attribute_value(input.attributes, owned[i], j);
  }
  return m;
}

// The faces of each part of first-pass tile `t` as first_pass_tile cuts it: a face
// goes to each part owning one of its corners. The slabs are of one width, not of one
// count: around a dense spot (a sphere's pole) one may hold most of the tile.
std::vector<std::uint64_t> first_pass_part_faces(const BinnedTiles& bins, std::uint32_t t, const MeshInput& input,
                                                 std::uint64_t most) {
  const auto records = bins.load(t);
  const std::uint32_t n = parts_of(records.size(), most);
  const Box3d box = bins.grid.box(t);
  const double side = bins.grid.side / double(n);
  std::vector<std::uint64_t> faces(n, 0);
  for (const TriangleRecord& r : records) {
    std::uint32_t in[3];
    int k = 0;
    for (int c = 0; c < 3; ++c) {
      if (!r.owned(c)) continue;
      const double x = input.positions.get(r.v[c]).x - box.min.x;
      const auto part = std::uint32_t(std::clamp<std::int64_t>(GridCoord::axis(x, side), 0, std::int64_t(n) - 1));
      if (std::find(in, in + k, part) == in + k) in[k++] = part;
    }
    for (int i = 0; i < k; ++i) ++faces[in[i]];
  }
  return faces;
}

// The faces a tile gives out: those whose first corner it owns.
std::uint64_t faces_given(const TileMesh& tile) {
  std::uint64_t n = 0;
  for (const PassFace& f : tile.faces) {
    auto it = std::lower_bound(tile.owned.begin(), tile.owned.end(), f.v[0],
                               [](const PassVertex& v, std::uint64_t id) { return v.id < id; });
    n += it != tile.owned.end() && it->id == f.v[0];
  }
  return n;
}

// The faces a tile keeps at least: those it does not give out (another tile's, held),
// and `share` of those it does (see run_pass).
std::uint64_t tile_floor(const TileMesh& tile, std::uint64_t given, double share) {
  return std::max<std::uint64_t>(4, (tile.faces.size() - given) + std::uint64_t(std::ceil(share * double(given))));
}

// A pass's tiles as it reads them: the binned input or the previous pass's bins.
struct PassSource {
  std::vector<std::uint32_t> order;                            // the tiles, in an order that follows from the input
  std::function<TileMesh(std::uint32_t, std::uint32_t)> load;  // tile, part
  std::function<std::uint64_t(std::uint32_t)> faces;           // a tile's face records
  std::function<std::uint32_t(std::uint32_t)> parts;           // the parts it is worked on in
  std::function<std::uint64_t(std::uint32_t, std::uint32_t)> bytes;  // a tile's or part's working set
};

// A tile, or a part of one, to collapse, with its face records and its working set.
struct TileWork {
  std::uint32_t tile = 0, part = 0;
  std::uint64_t faces = 0;
  std::size_t slot = 0;  // its place in the caller's list
  std::uint64_t bytes = 0;
};

// f(w) for each w of `work` on every thread, the fullest first (ties in the list's
// order), each taken by the next thread free: a dense tile (a sphere's pole) started
// last would run alone at the end. Which thread takes which changes no output.
template <class F>
void for_each_largest_first(std::vector<TileWork> work, const F& f) {
  std::stable_sort(work.begin(), work.end(), [](const TileWork& a, const TileWork& b) { return a.faces > b.faces; });
  std::atomic<std::size_t> next{0};
  const int threads = std::max(1, tbb::this_task_arena::max_concurrency());
  tbb::parallel_for(
      0, threads,
      [&](int) {
        for (std::size_t i = next++; i < work.size(); i = next++) f(work[i]);
      },
      tbb::simple_partitioner());
}

// The sample of a pass's tiles that chooses its threshold: spread over them, part 0
// of a tile worked on in parts.
std::vector<TileWork> sample_work(const PassSource& source) {
  const std::size_t n = source.order.size();
  const std::size_t m = std::min(n, std::clamp(n / kSampleEvery, kLeastSampleTiles, kSampleTiles));
  std::vector<TileWork> work;
  for (std::size_t i = 0; i < m; ++i) {
    const std::uint32_t t = source.order[(2 * i + 1) * n / (2 * m)];
    work.push_back({t, 0, source.faces(t) / source.parts(t), i, source.bytes(t, 0)});
  }
  return work;
}

// Step 2: the pass's threshold, a quadric cost. A sample of its tiles, spread over
// them, collapses in order of cost (every vertex free, as an open patch) to below
// `keep` of its faces, and the costs of its collapses are pooled: the threshold is
// the cost at which the sample keeps `keep` of its faces, each collapse removing two.
// Every tile of the pass then takes what the strict order of cost would take in the
// whole mesh up to that cost.
double sample_threshold(const PassSource& source, const CollapseSettings& settings, double keep, double share,
                        TileMemoryGate& gate, ProgressPhase* progress) {
  const std::vector<TileWork> work = sample_work(source);
  const std::size_t m = work.size();
  std::vector<std::vector<double>> logs(m);
  std::vector<std::uint64_t> given(m, 0);
  for_each_largest_first(work, [&](const TileWork& w) {
    gate.run(w.bytes, [&] {
      TileMesh tile = source.load(w.tile, 0);
      tile.hold_border = false;
      given[w.slot] = faces_given(tile);
      CollapseSettings sample = settings;
      sample.max_cost = std::numeric_limits<double>::infinity();
      // Down to the same count as the pass's tile (run_pass): the collapses then come
      // in the same batches (PassDriver) until the threshold stops the tile.
      sample.target_triangles = tile_floor(tile, given[w.slot], share);
      collapse_pass_tile(tile, sample, &logs[w.slot]);
    });
    if (progress) progress->advance(w.faces);
  });
  // A tile of the pass stops at its first collapse above the threshold, but costs do
  // not rise steadily along a collapse (an edge the collapses make may cost less than
  // one before): the threshold that lets a sample tile take k collapses is the
  // largest cost among its first k.
  std::vector<double> pooled;
  for (std::vector<double>& log : logs) {
    for (std::size_t j = 1; j < log.size(); ++j) log[j] = std::max(log[j], log[j - 1]);
    pooled.insert(pooled.end(), log.begin(), log.end());
  }
  std::sort(pooled.begin(), pooled.end());
  const double total = double(std::accumulate(given.begin(), given.end(), std::uint64_t(0)));
  const std::size_t wanted = std::size_t(std::ceil(std::max(0.0, total * (1 - keep)) / 2));
  const std::size_t taken = std::min(wanted, pooled.size());
  return taken ? pooled[taken - 1] : 0.0;
}

// The share of a pass's work one process of a distributed run takes: `part` of `parts`.
struct WorkShare {
  std::uint32_t part = 0, parts = 1;
};

// The pass's work: each tile, or each part of a dense one, with its face records.
std::vector<TileWork> pass_work(const PassSource& source) {
  std::vector<TileWork> work;
  for (std::uint32_t t : source.order) {
    const std::uint32_t parts = source.parts(t);
    for (std::uint32_t part = 0; part < parts; ++part)
      work.push_back({t, part, source.faces(t) / parts, work.size(), source.bytes(t, part)});
  }
  return work;
}

// `work` dealt to `parts` processes by face records (deal_by_weight); each work's
// process. It follows from the counts alone.
std::vector<std::uint32_t> deal_work(const std::vector<TileWork>& work, std::uint32_t parts) {
  std::vector<std::uint64_t> faces(work.size());
  for (const TileWork& w : work) faces[w.slot] = w.faces;
  return deal_by_weight(faces, parts);
}

// Steps 3 and 4: every tile collapsed up to settings.max_error and binned for the
// next pass.
//
// A tile keeps at least its share of the target, in proportion to the faces it
// gives out of the `faces` of the pass: where the threshold would take a flat part
// past the target (costs near zero, ties everywhere), which of its collapses go is
// for the last collapse, in strict order, to say. The shares sum to the target, so
// no pass takes the mesh below it.
//
// Only `mine` of the work runs here (deal_work); each tile goes to `next`.
void run_pass(const PassSource& source, const CollapseSettings& settings, double share, TileMemoryGate& gate,
              const TileOutputSink& next, CollapseStats* stats, ProgressPhase* progress,
              const WorkShare& mine = WorkShare()) {
  std::vector<TileWork> work = pass_work(source);
  if (mine.parts > 1) {
    const std::vector<std::uint32_t> owner = deal_work(work, mine.parts);
    work.erase(std::remove_if(work.begin(), work.end(), [&](const TileWork& w) { return owner[w.slot] != mine.part; }),
               work.end());
  }
  std::mutex mutex;
  for_each_largest_first(work, [&](const TileWork& w) {
    gate.run(w.bytes, [&] {
      const TileMesh tile = source.load(w.tile, w.part);
      CollapseSettings s = settings;
      s.target_triangles = tile_floor(tile, faces_given(tile), share);
      TileOutput out = collapse_pass_tile(tile, s);
      next(out);
      std::lock_guard<std::mutex> lock(mutex);
      stats->collapses += out.stats.collapses;
      stats->largest_cost = std::max(stats->largest_cost, out.stats.largest_cost);
      stats->largest_error = std::max(stats->largest_error, out.stats.largest_error);
    });
    if (progress) progress->advance(w.faces);
  });
}

// The remainder whole, for the last collapse: vertices numbered by id, faces in input
// order, each face once (from the tile owning its first corner), the vertices of
// `locked_ids` (sorted; may be null) locked. Built tile by tile, so that no more than
// one tile's records is held beside the mesh.
QuadricMesh gather(const PassBins& bins, std::size_t attributes, const std::vector<std::uint64_t>* locked_ids) {
  // In order of id: the order of the vertices whatever the tiles.
  std::vector<PassVertex> owned;
  std::vector<double> values;
  reserve_filled(&owned, std::size_t(bins.vertex_count()));
  reserve_filled(&values, std::size_t(bins.vertex_count()) * attributes);
  for (std::uint32_t t : bins.tiles()) {
    const TileMesh tile = bins.load(t, false, true);
    owned.insert(owned.end(), tile.owned.begin(), tile.owned.end());
    values.insert(values.end(), tile.attributes.begin(), tile.attributes.end());
  }
  sort_vertices(&owned, &values, attributes);
  QuadricMesh m;
  m.attribute_count = attributes;
  m.attributes = std::move(values);
  std::vector<std::uint64_t> ids;
  resize_filled(&ids, owned.size());
  resize_filled(&m.positions, owned.size());
  resize_filled(&m.quadrics, owned.size());
  for (std::size_t i = 0; i < owned.size(); ++i) {
    ids[i] = owned[i].id;
    m.positions[i] = owned[i].position;
    m.quadrics[i] = owned[i].quadric;
  }
  if (locked_ids) {
    m.locked.resize(owned.size());
    for (std::size_t i = 0; i < owned.size(); ++i)
      m.locked[i] = std::binary_search(locked_ids->begin(), locked_ids->end(), ids[i]);
  }
  std::vector<PassVertex>().swap(owned);
  struct Face {
    std::uint64_t index;
    std::uint32_t v[3];
    UnitNormal normal;
  };
  std::vector<Face> faces;
  reserve_filled(&faces, std::size_t(bins.face_count()));  // each face once, from one tile
  auto local = [&](std::uint64_t id) {
    return std::uint32_t(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin());
  };
  for (std::uint32_t t : bins.tiles()) {
    const TileMesh tile = bins.load(t, true, false);
    for (const PassFace& f : tile.faces)
      if (bins.holds(t, f.p[0])) faces.push_back({f.index, {local(f.v[0]), local(f.v[1]), local(f.v[2])}, f.normal});
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.index < b.index; });
  resize_filled(&m.triangles, 3 * faces.size());
  resize_filled(&m.face_normals, faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    std::copy(faces[f].v, faces[f].v + 3, m.triangles.begin() + std::ptrdiff_t(3 * f));
    m.face_normals[f] = faces[f].normal;
  }
  return m;
}

// The first pass's tile side: about `tile_faces` faces per occupied tile, from a sample
// of the vertices.
double first_tile_side(const MeshInput& input, double tile_faces) {
  const Box3d& b = input.info.bounds;
  const Vec3d size = b.max - b.min;
  const double longest = std::max({size.x, size.y, size.z});
  if (!(longest > 0)) return 1;
  const OccupancyGrowth growth = sampled_occupancy_growth(input.positions, b);
  const double tiles = std::max(1.0, double(input.info.face_count) / tile_faces);
  double side = longest / std::max(1.0, growth.resolution_for(tiles));
  // Occupancy counts the tiles a surface touches, many of them barely: the fullest
  // tile may hold many times the average. Smaller tiles until it holds at most
  // kFullestTileShare times the average asked for, by a sample of the vertices.
  // Not past kMostTilesShare times the tiles planned, whose binning buffers would
  // outgrow the budget: a dense spot (a generated sphere's poles) keeps a full tile,
  // which runs alone (TileMemoryGate).
  const double most_tiles = kMostTilesShare * tiles;
  for (int i = 0; i < 16 && double(estimate_fullest_tile_records(input, side)) > kFullestTileShare * tile_faces &&
                  growth.cells_at(longest / (side / kTileShrink)) <= most_tiles;
       ++i)
    side /= kTileShrink;
  return side;
}

// The tiles pass p (p >= 1) bins into, for `expected` of the previous pass's `faces`
// on a surface: as large as the previous pass's scaled by sqrt(faces / expected) (a
// tile of the same share of the surface then holds as many faces), shifted by an
// irrational share of a tile so that no border of one pass stays a border in the
// next. The pass then works on blocks of them (choose_block).
PassTiling pass_tiling(int p, double previous_side, double faces, double expected) {
  PassTiling t;
  t.side = previous_side * std::sqrt(std::max(1.0, faces / std::max(expected, 1.0)));
  const double golden = 0.6180339887498949;
  t.shift = t.side * (double(p) * golden - std::floor(double(p) * golden));
  return t;
}

// The side, in binned tiles, of the blocks a pass works on: the largest whose blocks
// hold about `tile_faces` face records on average and at most kFullestTileShare times
// that, counted from the bins (the faces are known by then: the tiling follows from
// the input and the target alone).
std::int64_t choose_block(const PassBins& bins, double tile_faces) {
  std::int64_t best = 1;
  for (std::int64_t k = 2; k <= kLargestBlock; ++k) {
    const std::vector<std::vector<std::uint32_t>> blocks = bins.blocks(k);
    std::uint64_t total = 0, fullest = 0;
    for (const std::vector<std::uint32_t>& b : blocks) {
      std::uint64_t records = 0;
      for (std::uint32_t t : b) records += bins.faces_in(t);
      total += records;
      fullest = std::max(fullest, records);
    }
    if (double(total) / double(blocks.size()) > tile_faces || double(fullest) > kPieceShare * tile_faces) break;
    best = k;
    if (blocks.size() == 1) break;
  }
  return best;
}

}  // namespace

bool collapses_in_passes(std::uint64_t faces, std::uint64_t target, const PassSizes& sizes) {
  return faces >= sizes.from_faces && double(faces) > kFinalShare * double(target);
}

namespace {

// The passes of one run, as the file comment lists their steps.
class PassRun {
 public:
  PassRun(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t target, const PassSizes& sizes,
          SimplifyStats* stats)
      : input_(input),
        plan_(plan),
        origin_(origin),
        target_(target),
        sizes_(sizes),
        stats_(stats),
        budget_(plan.budget_bytes),
        attributes_(input.attributes.size()),
        final_faces_(kFinalShare * double(target)),
        memory_(budget_, plan.budget_counts_process) {
    settings_.target_triangles = 4;
    settings_.exact_count = false;
    if (plan.target.max_error > 0) settings_.max_error = plan.target.max_error;
    settings_.lock_boundary = plan.lock_boundary;
    settings_.lock_coincident = carries_texture_coordinates(input.attributes.attributes);
    // A hole is judged against the input and the run's target, as in the whole mesh
    // (a tile's own count is not the mesh's); with no count asked, there are none.
    settings_.soften_holes = asks_count(plan);
    settings_.hole_faces = input.info.face_count;
    settings_.hole_target = target;
    if (!plan.locked_vertices.empty()) settings_.locked_ids = &plan.locked_vertices;  // sorted by the plan
  }

  QuadricMesh run() {
    check_last_collapse_fits();
    bin_input();
    return passes();
  }

  // Part `mine` of the first pass of a distributed run: the input binned and the
  // threshold chosen as one process does, then the part's share of the tiles
  // collapsed into `out`, one call at a time.
  FirstPassPlan first_pass_part(const WorkShare& mine, const TileOutputSink& out) {
    check_last_collapse_fits();
    bin_input();
    if (!(faces_ > final_faces_)) throw std::logic_error("first_pass_part: no pass runs");
    begin_pass_progress();
    choose_threshold();
    std::mutex mutex;
    run_pass(
        source_, settings_, share(), *gate_,
        [&](const TileOutput& tile) {
          std::lock_guard<std::mutex> lock(mutex);
          out(tile);
        },
        &collapse_stats_, progress_.get(), mine);
    progress_.reset();
    FirstPassPlan first_pass;
    first_pass.input_triangles = binned_.triangle_count;
    first_pass.skipped = binned_.skipped;
    first_pass.tiles = source_.order.size();
    first_pass.side = side_;
    first_pass.threshold = threshold_;
    first_pass.collapses = collapse_stats_.collapses;
    first_pass.largest_cost = collapse_stats_.largest_cost;
    first_pass.largest_error = collapse_stats_.largest_error;
    return first_pass;
  }

  // The passes after a first pass that the parts of a distributed run did: the state
  // one process has after its first pass, from their plan and tiles.
  QuadricMesh after_first_pass(const FirstPassPlan& first_pass, const TileOutputSource& tiles) {
    check_last_collapse_fits();
    side_ = first_pass.side;
    faces_ = double(first_pass.input_triangles);
    stats_->input_triangles = first_pass.input_triangles;
    stats_->skipped = first_pass.skipped;
    const TileSettings tiling{budget_, side_, false, plan_.floating.spill_compression, plan_.temp_dir};
    spill_ = spill_settings(input_, tiling, sizeof(PassVertex), 0, work_share());
    gate_ = std::make_unique<TileMemoryGate>(spill_.work_share, &memory_, plan_.release_memory);
    threshold_ = first_pass.threshold;
    settings_.max_cost = threshold_;
    collapse_stats_.collapses = first_pass.collapses;
    collapse_stats_.largest_cost = first_pass.largest_cost;
    collapse_stats_.largest_error = first_pass.largest_error;
    start_next_bins(double(first_pass.tiles));
    tiles([this](const TileOutput& out) { next_->add(out); });
    ++passes_;
    take_next_tiles();
    return passes();
  }

 private:
  // The passes from the present one until the remainder is small enough, then that
  // remainder whole.
  QuadricMesh passes() {
    while (faces_ > final_faces_ && passes_ < kMaxPasses && !held_) {
      begin_pass_progress();
      choose_threshold();
      collapse_tiles();
      take_next_tiles();
      end_pass_progress();
    }
    clock_.end("passes");
    clock_.move_to(&stats_->phases);
    stats_->refine.passes = std::uint32_t(passes_);
    stats_->refine.collapses = collapse_stats_.collapses;
    stats_->refine.largest_collapse_error = collapse_stats_.largest_error;
    if (!bins_) throw std::logic_error("reduce_in_passes: no pass ran");
    return gather(*bins_, attributes_, settings_.locked_ids);
  }

  // The last collapse holds the remainder whole: refused up front when it cannot.
  void check_last_collapse_fits() const {
    const MemoryBudget memory(budget_, plan_.budget_counts_process);
    const std::uint64_t last =
        collapse_memory_bytes(std::uint64_t(final_faces_ / 2), std::uint64_t(final_faces_), attributes_);
    memory.check(memory.held(), last,
                 "the last collapse of about " + std::to_string(std::uint64_t(final_faces_)) + " triangles",
                 "give options.memory_budget " + whole_mib(memory.held() + last) + " MiB or more, or a smaller target");
  }

  // The face records of a piece of work (a tile, a part of one, a block of tiles) on
  // average: what the budget must hold.
  std::uint64_t piece_faces() const {
    return sizes_.part_above ? sizes_.part_above : std::uint64_t(kPieceShare * sizes_.tile_faces);
  }

  // The working set of a piece of `faces` face records.
  std::uint64_t piece_bytes(std::uint64_t faces) const {
    return faces * (kTileBytesPerFace + kTileBytesPerAttribute * attributes_);
  }

  // The tiles' share of the budget (TileMemoryGate): half of it, which holds one piece
  // at least, or the run is refused up front.
  std::uint64_t work_share() const {
    const std::uint64_t piece = piece_bytes(piece_faces());
    if (piece > budget_ / 2)
      throw UsageError("options.memory_budget", "options.memory_budget " + whole_mib(budget_) +
                                                    " MiB cannot hold a tile of the collapse in passes (about " +
                                                    std::to_string(piece_faces()) + " face records, " +
                                                    whole_mib(piece) + " MiB); give options.memory_budget " +
                                                    whole_mib(2 * piece) + " MiB or more");
    return budget_ / 2;
  }

  // The first pass's tiles: the input binned, each face in the tile of each corner.
  void bin_input() {
    side_ = first_tile_side(input_, sizes_.tile_faces);
    const TileSettings tiling{budget_, side_, false, plan_.floating.spill_compression, plan_.temp_dir};
    spill_ = spill_settings(input_, tiling, sizeof(PassVertex), 0, work_share());
    input_.restart_triangles();
    binned_ = bin_triangles(input_, side_, budget_, spill_, plan_.progress);
    stats_->input_triangles = binned_.triangle_count;
    stats_->skipped = binned_.skipped;
    faces_ = double(binned_.triangle_count);
    gate_ = std::make_unique<TileMemoryGate>(spill_.work_share, &memory_, plan_.release_memory);
    for (std::uint32_t t = 0; t < binned_.count(); ++t) source_.order.push_back(t);
    std::sort(source_.order.begin(), source_.order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return binned_.grid.coord(a) < binned_.grid.coord(b); });
    const std::uint64_t most = piece_faces();
    source_.load = [this, most](std::uint32_t t, std::uint32_t part) {
      return first_pass_tile(binned_, t, input_, origin_, most, part);
    };
    source_.faces = [this](std::uint32_t t) { return binned_.triangles->record_count(t); };
    source_.parts = [this, most](std::uint32_t t) { return parts_of(binned_.triangles->record_count(t), most); };
    // The binning buffers were freed on several threads: give them back (see
    // SimplifyOptions::release_memory).
    if (plan_.release_memory) plan_.release_memory();
    count_part_faces();
    source_.bytes = [this](std::uint32_t t, std::uint32_t part) {
      const std::uint64_t records = binned_.triangles->record_count(t);
      const auto parts = part_faces_.find(t);
      if (parts == part_faces_.end()) return piece_bytes(records);
      // A part reads its whole tile's records, then keeps the faces around its own
      // vertices.
      return piece_bytes(parts->second[part]) + records * sizeof(TriangleRecord);
    };
    check_largest_piece_fits();
    clock_.end("bin");
  }

  // The faces of each part of the first pass's tiles that are worked on in parts,
  // counted from their records (first_pass_part_faces).
  void count_part_faces() {
    std::vector<TileWork> dense;
    for (std::uint32_t t : source_.order)
      if (source_.parts(t) > 1) {
        const std::uint64_t records = source_.faces(t);
        dense.push_back({t, 0, records, dense.size(), records * sizeof(TriangleRecord)});
        part_faces_[t];  // every entry made here: the threads below only fill them
      }
    for_each_largest_first(dense, [&](const TileWork& w) {
      gate_->run(w.bytes, [&] { part_faces_[w.tile] = first_pass_part_faces(binned_, w.tile, input_, piece_faces()); });
    });
  }

  // A piece of work larger than the tiles' share runs alone: refused up front when
  // even alone it would not fit next to what the run holds and the next pass's bin
  // buffers.
  void check_largest_piece_fits() const {
    std::uint64_t largest = 0;
    std::uint32_t largest_tile = 0, largest_part = 0;
    for (std::uint32_t t : source_.order)
      for (std::uint32_t part = 0; part < source_.parts(t); ++part)
        if (source_.bytes(t, part) > largest) {
          largest = source_.bytes(t, part);
          largest_tile = t;
          largest_part = part;
        }
    const std::uint64_t held = memory_.held() + next_bin_buffers();
    // The smallest budget that holds it: what the run holds beside the spill's
    // records in memory stays, while the spill's allowance (an eighth of the budget
    // here) and the bin buffers (a sixteenth) grow with the budget.
    const std::uint64_t fixed = memory_.held() - std::min(memory_.held(), binned_.triangles->bytes_kept_in_memory());
    const std::uint64_t least = std::max(2 * piece_bytes(piece_faces()), (fixed + largest) / 13 * 16 + 1);
    memory_.check(held, largest,
                  "the fullest piece of the collapse in passes (part " + std::to_string(largest_part + 1) + " of " +
                      std::to_string(source_.parts(largest_tile)) + " of a tile of " +
                      std::to_string(source_.faces(largest_tile)) + " face records: a dense spot of the mesh)",
                  "give options.memory_budget " + whole_mib(std::max(least, held + largest)) + " MiB or more");
  }

  // Step 2: the pass's threshold, from a sample of its tiles; never lower than the last.
  void choose_threshold() {
    const double aim = std::min(1.0, kAimShare * double(target_) / faces_);
    threshold_ = std::max(threshold_, sample_threshold(source_, settings_, aim, share(), *gate_, progress_.get()));
    settings_.max_cost = threshold_;
  }

  // Steps 3 and 4: every tile collapsed and binned into the next pass's tiles.
  void collapse_tiles() {
    start_next_bins(double(source_.order.size()));
    run_pass(
        source_, settings_, share(), *gate_, [this](const TileOutput& out) { next_->add(out); }, &collapse_stats_,
        progress_.get());
    ++passes_;
    // The tiles' buffers were freed on several threads: give them back (see
    // SimplifyOptions::release_memory).
    if (plan_.release_memory) plan_.release_memory();
  }

  // The next pass's tiles, to bin this pass's `tiles` tiles into.
  void start_next_bins(double tiles_now) {
    const double aim = std::min(1.0, kAimShare * double(target_) / faces_);
    next_tiling_ = pass_tiling(passes_ + 1, side_, faces_, kExpectedShare * aim * faces_);
    // About as many tiles as this pass's, fewer by the square of the sides' ratio.
    const double ratio = side_ / next_tiling_.side;
    const double tiles = std::max(1.0, tiles_now * ratio * ratio);
    const std::size_t record = sizeof(PassFace) + vertex_record_bytes(attributes_);
    const std::size_t buffer =
        std::clamp(std::size_t(double(budget_ / 16) / (tiles * double(record))), kLeastBinRecords, kMostBinRecords);
    next_ = std::make_unique<PassBins>(spill_.dir, next_tiling_, attributes_, spill_.allow.buckets * 3, buffer);
  }

  // The next pass reads what this one binned, in blocks of tiles chosen from its counts.
  void take_next_tiles() {
    const double left = double(next_->face_count());
    stats_->refine.pass_triangles.push_back(next_->face_count());
    if (passes_ == 1) binned_.triangles.reset();  // the input's spill is done with
    bins_ = std::move(next_);
    const std::int64_t block = choose_block(*bins_, sizes_.tile_faces);
    auto blocks = std::make_shared<std::vector<std::vector<std::uint32_t>>>(bins_->blocks(block));
    source_.order.resize(blocks->size());
    std::iota(source_.order.begin(), source_.order.end(), 0u);
    source_.load = [b = bins_.get(), blocks](std::uint32_t t, std::uint32_t) { return b->load_block((*blocks)[t]); };
    source_.parts = [](std::uint32_t) { return std::uint32_t(1); };
    source_.faces = [b = bins_.get(), blocks](std::uint32_t t) {
      std::uint64_t records = 0;
      for (std::uint32_t tile : (*blocks)[t]) records += b->faces_in(tile);
      return records;
    };
    source_.bytes = [this](std::uint32_t t, std::uint32_t) { return piece_bytes(source_.faces(t)); };
    side_ = next_tiling_.side * double(block);
    const bool slow = left > (1 - kSlowPass) * faces_;
    faces_ = left;
    // Two slow passes in a row: held by the maximum error or by the topology; the
    // last collapse says which. One: the sample found more below the threshold than
    // the tiles did, and the next pass raises it.
    held_ = slow && slow_before_;
    slow_before_ = slow;
    if (slow) threshold_ = threshold_ > 0 ? 2 * threshold_ : std::numeric_limits<double>::min();
  }

  // The share of the target a tile keeps at least (run_pass).
  double share() const { return double(target_) / faces_; }

  // What the next pass's bins take in buffers (start_next_bins), planned.
  std::uint64_t next_bin_buffers() const { return budget_ / 16; }

  // A pass as a phase of its own: its sample's and its tiles' face records counted,
  // the triangles it starts from told at its start, and those it leaves at its end.
  void begin_pass_progress() {
    std::uint64_t total = 0;
    for (const TileWork& w : sample_work(source_)) total += w.faces;
    for (std::uint32_t t : source_.order) total += source_.faces(t);
    const std::string in = std::to_string(std::uint64_t(faces_));
    progress_ = std::make_unique<ProgressPhase>(plan_.progress, "collapse pass " + std::to_string(passes_ + 1), total,
                                                "tri", in + " triangles in");
    pass_in_ = in;
  }
  void end_pass_progress() {
    progress_->set_detail(pass_in_ + " -> " + std::to_string(std::uint64_t(faces_)) + " triangles");
    progress_.reset();
  }

  MeshInput& input_;
  const RunPlan& plan_;
  const Vec3d origin_;
  const std::uint64_t target_;
  const PassSizes sizes_;
  SimplifyStats* stats_;
  const std::uint64_t budget_;
  const std::size_t attributes_;
  const double final_faces_;
  const MemoryBudget memory_;
  PhaseTimer clock_;
  std::unique_ptr<ProgressPhase> progress_;  // the pass in work
  std::string pass_in_;
  std::map<std::uint32_t, std::vector<std::uint64_t>> part_faces_;  // first-pass tiles in parts: each part's faces
  CollapseSettings settings_;
  CollapseStats collapse_stats_;
  SpillSettings spill_;
  BinnedTiles binned_;
  std::unique_ptr<TileMemoryGate> gate_;
  PassSource source_;
  PassTiling next_tiling_;
  std::unique_ptr<PassBins> next_, bins_;
  double faces_ = 0, threshold_ = 0, side_ = 0;
  int passes_ = 0;
  bool slow_before_ = false, held_ = false;
};

}  // namespace

QuadricMesh reduce_in_passes(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t target,
                             SimplifyStats* stats, const PassSizes& sizes) {
  QuadricMesh rest = PassRun(input, plan, origin, target, sizes, stats).run();
  // The passes' bins and buffers, freed on several threads, go back before the last
  // collapse.
  if (plan.release_memory) plan.release_memory();
  return rest;
}

FirstPassPlan first_pass_part(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t target,
                              std::uint32_t part, std::uint32_t parts, const TileOutputSink& out,
                              const PassSizes& sizes) {
  SimplifyStats stats;
  return PassRun(input, plan, origin, target, sizes, &stats).first_pass_part({part, parts}, out);
}

QuadricMesh reduce_after_first_pass(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t target,
                                    const FirstPassPlan& first_pass, const TileOutputSource& tiles,
                                    SimplifyStats* stats, const PassSizes& sizes) {
  QuadricMesh rest = PassRun(input, plan, origin, target, sizes, stats).after_first_pass(first_pass, tiles);
  if (plan.release_memory) plan.release_memory();
  return rest;
}

}  // namespace oocsimp
