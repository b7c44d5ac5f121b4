// The per-cell machinery of OoCS (Lindstrom 2000); see uniform_cells.hpp. Memory
// holds the occupied cells and the surviving triangles, never the input, and stays
// within --mem (TableBudget) or the run stops.
#include "cluster/uniform_cells.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cluster/attribute_sums.hpp"
#include "cluster/curvature_cells.hpp"
#include "cluster/plane_quadric.hpp"
#include "cluster/thick_primitives.hpp"
#include "common/huge_pages.hpp"
#include "common/vec3_math.hpp"
#include "io/attribute_array.hpp"
#include "runtime/ordered_pipeline.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

// Chunk sizes are constants: they fix the order of floating-point sums, so they
// must not depend on the thread count.
constexpr std::uint64_t kVertexChunk = 1 << 16;
constexpr std::size_t kFaceChunk = 1 << 15;
// How many entries ahead the serial merges ask for a table's slot: far enough that the
// fetch is done when the entry comes, near enough that it is still in the cache.
constexpr std::size_t kPrefetchAhead = 8;

struct VertexChunk {
  std::uint64_t begin = 0, end = 0;
  CellMap<VertexSum> cells{4096};
};

// Per input vertex of a window of indices: the weight its corners in a face chunk
// carry, and its cell there (kNoCell before its first corner).
struct VertexWeights {
  static constexpr std::uint32_t kNoCell = ~std::uint32_t(0);
  struct Slot {
    double weight = 0;
    std::uint32_t cell = kNoCell;
  };
  std::uint64_t first = 0;
  std::vector<Slot> slots;
  std::uint64_t bytes() const { return slots.capacity() * sizeof(Slot); }
};

// The most vertex indices a face chunk's weights window spans (16 bytes each): a
// chunk of a file whose vertices are numbered along its surface references a few rows
// of them; corners past the window add to their cells directly.
constexpr std::uint64_t kVertexWindow = 2 * kFaceChunk;

// The least and the greatest of `count` indices (0, 0 for none), in four lanes whose
// comparisons do not wait on each other.
std::pair<std::uint64_t, std::uint64_t> index_range(const std::uint64_t* index, std::size_t count) {
  if (count == 0) return {0, 0};
  std::uint64_t lo[4], hi[4];
  for (int l = 0; l < 4; ++l) lo[l] = hi[l] = index[0];
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4)
    for (int l = 0; l < 4; ++l) {
      lo[l] = std::min(lo[l], index[i + l]);
      hi[l] = std::max(hi[l], index[i + l]);
    }
  for (; i < count; ++i) {
    lo[0] = std::min(lo[0], index[i]);
    hi[0] = std::max(hi[0], index[i]);
  }
  return {std::min({lo[0], lo[1], lo[2], lo[3]}), std::max({hi[0], hi[1], hi[2], hi[3]})};
}

// Resizes an empty `table` to `count` zeros, over huge pages.
void resize_zeroed(std::vector<double>& table, std::size_t count) {
  reserve_huge(&table, count);
  table.resize(count, 0.0);
}

// Remembers the last cells looked up: neighbouring vertices and triangles in a file
// mostly fall in the same few cells, so this skips most hash probes.
template <class Record>
class CellIndexCache {
 public:
  explicit CellIndexCache(CellMap<Record>& map) : map_(map) {}
  std::uint32_t operator()(std::uint64_t key) {
    if (key == key_[0]) return idx_[0];
    if (key == key_[1]) {
      std::swap(key_[0], key_[1]);
      std::swap(idx_[0], idx_[1]);
      return idx_[0];
    }
    key_[1] = key_[0];
    idx_[1] = idx_[0];
    key_[0] = key;
    idx_[0] = map_.insert(key);
    return idx_[0];
  }

 private:
  CellMap<Record>& map_;
  std::uint64_t key_[2] = {~std::uint64_t(0), ~std::uint64_t(0)};
  std::uint32_t idx_[2] = {0, 0};
};

// What a whole run needs per occupied cell, for the advice: a closed surface keeps
// about two triangles per cell (Euler, as choose_grid assumes), each in the kept list
// and the output (3 indices each), and the cell's output number, order and position.
constexpr std::uint64_t kRunBytesPerCell =
    kCellEntryBytes + 2 * 2 * 3 * sizeof(std::uint32_t) + 2 * sizeof(std::uint32_t) + 3 * sizeof(double);

// The largest per-chunk table seen so far, times the chunks in flight: the
// pipeline's share of the budget.
class ChunkTables {
 public:
  explicit ChunkTables(std::size_t tokens) : tokens_(tokens) {}
  void saw(std::uint64_t bytes, std::uint64_t entries) {
    largest_bytes_ = std::max(largest_bytes_, bytes);
    largest_entries_ = std::max(largest_entries_, entries);
  }
  std::uint64_t bytes() const { return tokens_ * largest_bytes_; }
  /// Entries the next merge may add to the global table.
  std::uint64_t next_entries() const { return largest_entries_; }

 private:
  std::uint64_t tokens_, largest_bytes_ = 0, largest_entries_ = 0;
};

std::size_t pipeline_tokens() { return 2 * std::max<std::size_t>(1, tbb::this_task_arena::max_concurrency()); }

}  // namespace

// With thick edges (Low & Tan 1997 §3.3): per cluster pair the moments of the
// corners of the triangles that collapse to an edge between them (EdgeMoments, `a` in
// the lower-numbered cell, each relative to its cell's corner), and the cells some
// triangle collapsed into (a point there).
struct ThickSums {
  FlatHashMap<std::uint64_t, EdgeMoments> edges{64};
  std::vector<std::uint8_t> collapsed;  // per cell

  void clear() {
    edges.clear();
    std::fill(collapsed.begin(), collapsed.end(), 0);
  }
  void mark_point(std::uint32_t cell) {
    if (cell >= collapsed.size()) collapsed.resize(std::size_t(cell) + 1024, 0);
    collapsed[cell] = 1;
  }
  // Adds the triangle's corners u[k] (relative to their cells' corners) in cells c[k]
  // to the edge between its two cells.
  void add_edge(const std::uint32_t c[3], const Vec3d u[3]) {
    const std::uint32_t lo = std::min({c[0], c[1], c[2]});
    const std::uint32_t hi = std::max({c[0], c[1], c[2]});
    EdgeMoments& e = edges.value(edges.insert(cluster_pair_key(lo, hi)));
    for (int k = 0; k < 3; ++k) (c[k] == lo ? e.a : e.b).add(u[k]);
  }
  std::uint64_t bytes() const { return edges.bytes() + collapsed.capacity(); }
};

// The attribute sums of the uniform cells. Per cell, width() = 1 + n sums for n
// attributes: [0] W, the sum of its corners' weights, and [1 + k] sum w x_k, where
// x_k = a_k - min_k (0 for a value that is not finite: it counts as the minimum).
// A vertex's corners all lie in its cell, so a vertex can be added once with the
// weight of its corners (add_vertex) instead of once per corner: its values are then
// decoded once per chunk. The layout's [0, 1] scaling is affine, so it commutes with
// the weighted mean: finish() applies it once per cell. Doubles added in an order
// fixed by the input and the chunk size: deterministic for any thread count.
class UniformAttributeSums {
 public:
  /// The least weight a corner carries: a triangle without area (or with an area that
  /// is not finite) weighs this instead of 0, so that a cell of such triangles takes
  /// the plain mean of its corners (the method's cell policy where W = 0) without sums
  /// of its own, while next to any real area (above 2^-547, where adding it rounds
  /// away) it changes nothing. Far above the smallest normal double, so w x stays
  /// normal for x down to 2^-400.
  static constexpr double kLeastWeight = 0x1p-600;

  explicit UniformAttributeSums(const AttributeArray& array) : layout_(array) {
    const std::vector<VertexAttribute>& a = layout_.attributes();
    for (std::size_t k = 0; k < a.size(); ++k) {
      columns_.push_back({array.base[k], array.stride[k], a[k].min, 1 + k});
      const double range = a[k].max - a[k].min;
      inv_range_.push_back(range > 0 ? 1.0 / range : 0.0);
      if (runs_.empty() || a[k].type != a[runs_.back().first].type) {
        runs_.push_back({nullptr, k, 0});
        with_stored_type(a[k].type, [&](auto zero) { set_adder<decltype(zero)>(runs_.back(), array.swap); });
      }
      ++runs_.back().count;
    }
  }
  const AttributeLayout& layout() const { return layout_; }
  bool empty() const { return layout_.empty(); }
  std::size_t width() const { return width_; }

  /// A corner's weight from its triangle's third of the area.
  static double corner_weight(double third_area) { return third_area > kLeastWeight ? third_area : kLeastWeight; }

  /// Adds vertex v with weight w to the sums of local cell `cell` of `table` (width()
  /// per cell).
  void add_vertex(double* table, std::uint64_t v, std::uint32_t cell, double w) const {
    double* s = table + std::size_t(cell) * width();
    s[0] += w;
    for (const Run& run : runs_) run.add(&columns_[run.first], run.count, v, s, w);
  }

  /// Adds every vertex of the window that has a cell, with its weight, and leaves the
  /// window clean.
  void add_window(double* table, VertexWeights& window) const {
    VertexWeights::Slot* const slots = window.slots.data();
    for (std::size_t i = 0; i < window.slots.size(); ++i) {
      if (slots[i].cell == VertexWeights::kNoCell) continue;
      add_vertex(table, window.first + i, slots[i].cell, slots[i].weight);
      slots[i] = VertexWeights::Slot();
    }
  }

  /// A cell's output values (count() of them) from its merged sums.
  void finish(const double* sums, double* out) const {
    const double w = sums[0];
    for (std::size_t k = 0; k < layout_.count(); ++k) out[k] = w > 0 ? sums[1 + k] / w * inv_range_[k] : 0.0;
    layout_.finish_means(out);
  }

 private:
  struct Column {
    const unsigned char* base;
    std::size_t stride;
    double min;
    std::size_t sum;  // its sum's index in a cell's sums
  };
  using Adder = void (*)(const Column*, std::size_t, std::uint64_t, double*, double);
  // Consecutive attributes of one stored type, decoded by a function of that type (a
  // call per run and vertex rather than a switch per value).
  struct Run {
    Adder add;
    std::size_t first, count;
  };

  template <class T>
  static void set_adder(Run& run, bool swap) {
    run.add = swap ? add_values<T, true> : add_values<T, false>;
  }

  // s[c.sum] += w x for each column c of a run.
  template <class T, bool kSwap>
  static void add_values(const Column* c, std::size_t count, std::uint64_t v, double* s, double w) {
    for (const Column* end = c + count; c != end; ++c) {
      double x = double(load_stored<T>(c->base + v * c->stride, kSwap)) - c->min;
      if (std::is_floating_point_v<T> && !std::isfinite(x)) x = 0;
      s[c->sum] += w * x;
    }
  }

  AttributeLayout layout_;
  std::vector<Column> columns_;
  std::vector<Run> runs_;
  std::vector<double> inv_range_;
  std::size_t width_ = 1 + layout_.count();
};

// Pass 2's unit of work: a chunk of the triangle stream and its own cell table.
struct UniformCells::FaceChunk {
  std::vector<std::uint64_t> tris = std::vector<std::uint64_t>(3 * kFaceChunk);
  std::size_t count = 0;
  std::uint64_t number = 0;  // the how-manieth read of the stream
  bool summed = true;        // false for a chunk another part sums
  CellMap<Quadric> cells{4096};
  std::vector<std::uint32_t> kept;     // local cell indices, 3 per surviving triangle
  std::vector<double> attribute_sums;  // UniformAttributeSums::width() per local cell
  VertexWeights vertex_weights;
  ThickSums thick;  // with thick edges: over local cells
};

namespace {

// Adds a chunk's thick sums (over its local cells) to the run's (over global cells).
void merge_thick_sums(const ThickSums& chunk, const std::vector<std::uint32_t>& to_global, ThickSums* run) {
  for (std::size_t i = 0; i < chunk.edges.size(); ++i) {
    const std::uint64_t key = chunk.edges.key(i);
    const std::uint32_t a = to_global[key >> 32], b = to_global[key & 0xFFFFFFFFu];
    EdgeMoments sums = chunk.edges.value(i);
    if (a > b) std::swap(sums.a, sums.b);  // `a` goes with the lower global cell
    run->edges.value(run->edges.insert(cluster_pair_key(a, b))).add(sums);
  }
  const std::size_t cells = std::min(chunk.collapsed.size(), to_global.size());
  for (std::size_t i = 0; i < cells; ++i)
    if (chunk.collapsed[i]) run->mark_point(to_global[i]);
}

// The thick edges and points that survive (select_thick_primitives), over the
// cells' numbers: thicknesses from the edges' corner moments (relative to each cell's
// corner) and the points' widths from their cells' vertex sums.
ThickPrimitives thick_primitives(const ThickSums& thick, const TriangleSet& kept, const CellMap<CellRecord>& cells,
                                 const CellKeys& keys) {
  std::vector<std::uint32_t> triangles(3 * kept.size());
  for (std::size_t t = 0; t < kept.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) triangles[3 * t + k] = kept[t][k];
  std::vector<EdgeCandidate> edges(thick.edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const std::uint64_t key = thick.edges.key(i);
    EdgeCandidate& e = edges[i];
    e.a = std::uint32_t(key >> 32);
    e.b = std::uint32_t(key & 0xFFFFFFFFu);
    const EdgeMoments& m = thick.edges.value(i);
    e.thickness = float(edge_thickness(m.a, keys.cell_min(cells.key(e.a)), m.b, keys.cell_min(cells.key(e.b))));
  }
  std::vector<std::pair<std::uint32_t, float>> points;
  for (std::size_t c = 0; c < thick.collapsed.size() && c < cells.size(); ++c)
    if (thick.collapsed[c]) {
      const VertexSum& v = cells.value(c).vertices;
      points.push_back({std::uint32_t(c), float(point_width(double(v.n), v.sum, v.squares))});
    }
  return select_thick_primitives(triangles, edges, points, cells.size());
}

}  // namespace

void TableBudget::check(std::uint64_t bytes, const std::string& what) const {
  if (fits(bytes)) return;
  // The advice: the whole run at about kRunBytesPerCell per occupied cell, and a
  // grid with a tenth fewer cells than that fit in the budget.
  const double room = budget_.bytes() > held_ ? double(budget_.bytes() - held_) : 0.0;
  const std::uint32_t coarser = coarser_resolution(0.9 * room / double(kRunBytesPerCell));
  const double run = occupancy_.occupied_by(resolution_, vertices_) * double(kRunBytesPerCell);
  budget_.check(held_, bytes,
                "the uniform method's tables at options.sizing.grid " + std::to_string(resolution_) + " (" + what + ")",
                "give options.memory_budget " + whole_mib(held_ + std::max(bytes, std::uint64_t(run))) +
                    " MiB or more, or a coarser grid (options.sizing.grid " + std::to_string(coarser) +
                    " or less, or a smaller options.sizing.ratio)");
}

// The finest resolution at which about `cells` are occupied (bisection: occupancy
// grows with the resolution).
std::uint32_t TableBudget::coarser_resolution(double cells) const {
  double lo = 1, hi = resolution_;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (occupancy_.occupied_by(mid, vertices_) <= cells ? lo : hi) = mid;
  }
  return std::uint32_t(lo);
}

Vec3d CellKeys::cell_min(std::uint64_t key) const {
  if (key & kLockedKey) return locked_->place(key & ~kLockedKey);
  return clusters_ ? clusters_->cell_min_relative(std::uint32_t(key)) : grid_.cell_min_relative(key);
}

double CellKeys::cell_side(std::uint64_t key) const {
  if (key & kLockedKey) return 0;
  return clusters_ ? clusters_->cell_side(std::uint32_t(key)) : grid_.cell;
}

namespace {

bool before(const Vec3d& a, const Vec3d& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

}  // namespace

LockedVertices::LockedVertices(const std::vector<std::uint64_t>& vertices, const PositionArray& positions,
                               const GridSpec& grid) {
  std::vector<std::pair<Vec3d, Vec3d>> both;  // relative, input
  both.reserve(vertices.size());
  for (std::uint64_t v : vertices) {
    const Vec3d p = positions.get(v);
    if (is_finite(p)) both.push_back({grid.relative(p), p});  // a non-finite vertex takes part in nothing
  }
  std::sort(both.begin(), both.end(), [](const auto& a, const auto& b) { return before(a.first, b.first); });
  const auto same = [](const Vec3d& a, const Vec3d& b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
  for (const auto& p : both)
    if (places_.empty() || !same(places_.back(), p.first)) {
      places_.push_back(p.first);
      input_.push_back(p.second);
    }
}

std::int64_t LockedVertices::rank_of(const Vec3d& relative) const {
  const auto at = std::lower_bound(places_.begin(), places_.end(), relative, before);
  if (at == places_.end() || at->x != relative.x || at->y != relative.y || at->z != relative.z) return -1;
  return at - places_.begin();
}

std::uint64_t CellKeys::cluster_of(std::uint64_t vertex) const { return clusters_->cluster(vertex); }

// The vertex choose_vertices keeps for a cell: matching ones before the others, then
// the least error, then the lowest index (a total order: the same choice for any
// order of the vertices).
struct UniformCells::ChosenVertex {
  Vec3d position;
  double error = std::numeric_limits<double>::infinity();
  std::uint64_t vertex = std::numeric_limits<std::uint64_t>::max();
  bool matching = false;

  bool better(bool m, double e, std::uint64_t v) const {
    if (m != matching) return m;
    if (e != error) return e < error;
    return v < vertex;
  }
};

UniformCells::UniformCells(const GridSpec& grid, const AttributeArray& attributes, const VertexClusters* clusters,
                           const LockedVertices* locked)
    : grid_(grid),
      keys_(grid, clusters, locked),
      attributes_(std::make_unique<const UniformAttributeSums>(attributes)) {}

UniformCells::~UniformCells() = default;

std::size_t UniformCells::attribute_count() const { return attributes_->layout().count(); }
std::size_t UniformCells::attribute_width() const { return attributes_->width(); }

namespace {

// A chunk's vertex sums (`n` cells: key(i), sum(i)) added to the run's cells.
template <class KeyAt, class SumAt>
void add_vertex_sums(CellMap<CellRecord>& cells, std::size_t n, KeyAt key, SumAt sum) {
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kPrefetchAhead < n) cells.prefetch(key(i + kPrefetchAhead));
    VertexSum& dst = cells.value(cells.insert(key(i))).vertices;
    const VertexSum& src = sum(i);
    dst.sum += src.sum;
    dst.squares += src.squares;
    dst.n += src.n;
  }
}

}  // namespace

// Vertices [begin, end) into their cells' sums in `cells` (cleared first).
void UniformCells::sum_vertex_chunk(const PositionArray& positions, std::uint64_t begin, std::uint64_t end,
                                    CellMap<VertexSum>* cells) const {
  const GridSpec& grid = grid_;
  const CellKeys& keys = keys_;
  cells->clear();
  CellIndexCache<VertexSum> index(*cells);
  for (std::uint64_t i = begin; i < end; ++i) {
    Vec3d q = positions.get(i);
    if (!is_finite(q)) continue;  // no cell holds it; its triangles were dropped by the stream
    Vec3d p = grid.relative(q);
    VertexSum& s = cells->value(index(keys.key(i, p)));
    s.sum += p;
    s.squares += dot(p, p);
    ++s.n;
  }
}

void UniformCells::add_vertices(const PositionArray& positions, const TableBudget& budget,
                                const ProgressCallback& progress) {
  CellMap<CellRecord>& cells = cells_;
  std::uint64_t next = 0;
  ChunkTables chunks(pipeline_tokens());
  ProgressPhase phase(progress, "cell means", positions.count, "vtx");
  run_ordered_pipeline<VertexChunk>(
      pipeline_tokens(),
      [&](VertexChunk& c) {
        if (next >= positions.count) return false;
        c.begin = next;
        c.end = std::min(positions.count, next + kVertexChunk);
        next = c.end;
        return true;
      },
      [&](VertexChunk& c) { sum_vertex_chunk(positions, c.begin, c.end, &c.cells); },
      [&](VertexChunk& c) {
        add_vertex_sums(
            cells, c.cells.size(), [&](std::size_t i) { return c.cells.key(i); },
            [&](std::size_t i) -> const VertexSum& { return c.cells.value(i); });
        chunks.saw(c.cells.bytes(), c.cells.size());
        budget.check(cells.bytes_with(chunks.next_entries()) + chunks.bytes(),
                     std::to_string(cells.size()) + " occupied cells after " + std::to_string(c.end) + " vertices");
        phase.set(c.end);
      });
}

void UniformCells::start_face_sums(bool thick_edges) {
  if (!attributes_->empty()) resize_zeroed(attribute_sums_, cells_.size() * attributes_->width());
  if (thick_edges) {
    thick_ = std::make_unique<ThickSums>();
    thick_->collapsed.assign(cells_.size(), 0);
  }
}

// One chunk of triangles into its own cell table, on any thread: each triangle's
// plane quadric to each distinct cell it touches (Lindstrom 2000), the triangles over
// three cells kept, with thick edges the others' edges and points, and with
// attributes the corners' weighted values.
void UniformCells::sum_face_chunk(const PositionArray& positions, FaceChunk& c) const {
  const GridSpec& grid = grid_;
  const CellKeys& keys = keys_;
  const UniformAttributeSums& attributes = *attributes_;
  const bool with_attributes = !attributes.empty();
  c.cells.clear();
  c.kept.clear();
  c.attribute_sums.clear();
  if (thick_) c.thick.clear();
  CellIndexCache<Quadric> index(c.cells);
  // With attributes, a window over the chunk's vertex indices: the weights of the
  // corners of each vertex, added once per vertex after the triangles.
  VertexWeights& vw = c.vertex_weights;
  if (with_attributes) {
    const auto [least, most] = index_range(c.tris.data(), 3 * c.count);
    vw.first = least;
    vw.slots.resize(std::size_t(std::min(most - least + 1, kVertexWindow)));  // clean from earlier chunks
  }
  VertexWeights::Slot* const window = vw.slots.data();
  const std::uint64_t window_first = vw.first, window_size = vw.slots.size();
  for (std::size_t t = 0; t < c.count; ++t) {
    const std::uint64_t* v = &c.tris[3 * t];
    Vec3d p0 = grid.relative(positions.get(v[0]));
    Vec3d p1 = grid.relative(positions.get(v[1]));
    Vec3d p2 = grid.relative(positions.get(v[2]));
    std::uint64_t k0 = keys.key(v[0], p0), k1 = keys.key(v[1], p1), k2 = keys.key(v[2], p2);
    // Quadric::add_triangle, with the plane kept for the attributes' weight.
    const TrianglePlane plane = triangle_plane(p1 - p0, p2 - p0);
    Quadric q;
    if (!plane.degenerate()) add_plane_quadric(&q, plane, dot(plane.m, p0));
    // The quadric goes once to each distinct cell the triangle touches.
    std::uint32_t i0 = index(k0), i1 = i0, i2 = i0;
    c.cells.value(i0).add(q);
    if (k1 != k0) {
      i1 = index(k1);
      c.cells.value(i1).add(q);
    }
    if (k2 != k0 && k2 != k1) {
      i2 = index(k2);
      c.cells.value(i2).add(q);
    }
    // Only a triangle spanning three cells survives the collapse; with thick
    // edges, one over two cells leaves an edge and one in a single cell a point.
    const bool three = k0 != k1 && k1 != k2 && k0 != k2;
    if (three) c.kept.insert(c.kept.end(), {i0, i1, i2});
    if (thick_ && !three) {
      if (k0 == k1 && k1 == k2) {
        c.thick.mark_point(i0);
      } else {
        const std::uint32_t cell_of[3] = {i0, i1, k2 == k0 ? i0 : k2 == k1 ? i1 : i2};
        const Vec3d u[3] = {p0 - keys.cell_min(k0), p1 - keys.cell_min(k1), p2 - keys.cell_min(k2)};
        c.thick.add_edge(cell_of, u);
      }
    }
    if (with_attributes) {
      // Each corner adds its values with a third of the area to its own cell:
      // through its vertex's slot in the window, or directly.
      const double w = UniformAttributeSums::corner_weight(plane.len / 6);
      const std::uint32_t cell_of[3] = {i0, i1, k2 == k0 ? i0 : k2 == k1 ? i1 : i2};
      for (int j = 0; j < 3; ++j) {
        const std::uint64_t slot = v[j] - window_first;
        if (slot < window_size) {
          window[slot].weight += w;
          window[slot].cell = cell_of[j];
        } else {
          if (c.attribute_sums.size() < c.cells.size() * attributes.width())
            c.attribute_sums.resize(c.cells.size() * attributes.width(), 0.0);
          attributes.add_vertex(c.attribute_sums.data(), v[j], cell_of[j], w);
        }
      }
    }
  }
  if (with_attributes) {
    c.attribute_sums.resize(c.cells.size() * attributes.width(), 0.0);
    attributes.add_window(c.attribute_sums.data(), vw);
  }
}

// A chunk's cells, surviving triangles and thick sums added to the run's, in input
// order (so every sum is taken in the same order for any thread count); to_global
// gets the run's number of each of the chunk's cells.
namespace {

// The two kinds of chunk merge_faces takes: a pipeline's FaceChunk and a part's sums.
std::size_t chunk_cells(const UniformCells::FaceChunk& c) { return c.cells.size(); }
std::uint64_t chunk_key(const UniformCells::FaceChunk& c, std::size_t i) { return c.cells.key(i); }
const Quadric& chunk_quadric(const UniformCells::FaceChunk& c, std::size_t i) { return c.cells.value(i); }
const ThickSums* chunk_thick(const UniformCells::FaceChunk& c) { return &c.thick; }
std::size_t chunk_cells(const FaceChunkSums& c) { return c.keys.size(); }
std::uint64_t chunk_key(const FaceChunkSums& c, std::size_t i) { return c.keys[i]; }
const Quadric& chunk_quadric(const FaceChunkSums& c, std::size_t i) { return c.quadrics[i]; }
const ThickSums* chunk_thick(const FaceChunkSums&) { return nullptr; }

}  // namespace

template <class Chunk>
void UniformCells::merge_faces(const Chunk& c, std::vector<std::uint32_t>* to_global_cells) {
  const UniformAttributeSums& attributes = *attributes_;
  const bool with_attributes = !attributes.empty();
  std::vector<std::uint32_t>& to_global = *to_global_cells;
  const std::size_t n = chunk_cells(c);
  to_global.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kPrefetchAhead < n) cells_.prefetch(chunk_key(c, i + kPrefetchAhead));
    std::uint32_t g = cells_.insert(chunk_key(c, i));
    cells_.value(g).q.add(chunk_quadric(c, i));
    to_global[i] = g;
    if (with_attributes && c.attribute_sums.size() >= (i + 1) * attributes.width()) {
      if (attribute_sums_.size() < (std::size_t(g) + 1) * attributes.width())
        attribute_sums_.resize((std::size_t(g) + 1) * attributes.width(), 0.0);
      double* dst = &attribute_sums_[std::size_t(g) * attributes.width()];
      const double* src = &c.attribute_sums[i * attributes.width()];
      for (std::size_t j = 0; j < attributes.width(); ++j) dst[j] += src[j];
    }
  }
  const std::size_t ahead = 3 * kPrefetchAhead;
  for (std::size_t t = 0; t < c.kept.size(); t += 3) {
    if (t + ahead < c.kept.size())
      kept_.prefetch(to_global[c.kept[t + ahead]], to_global[c.kept[t + ahead + 1]], to_global[c.kept[t + ahead + 2]]);
    kept_.insert(to_global[c.kept[t]], to_global[c.kept[t + 1]], to_global[c.kept[t + 2]]);
  }
  if (thick_ && chunk_thick(c)) merge_thick_sums(*chunk_thick(c), to_global, thick_.get());
}

std::uint64_t UniformCells::add_triangles(MeshInput& input, const TableBudget& budget,
                                          const ProgressCallback& progress) {
  CellMap<CellRecord>& cells = cells_;
  const TriangleSet& kept = kept_;
  const ThickSums* thick = thick_.get();
  TriangleStream& stream = *input.triangles;
  std::vector<std::uint32_t> to_global;
  std::uint64_t total = 0;
  ChunkTables chunks(pipeline_tokens());
  // A closed surface clustered to n cells keeps about 2n triangles (Euler), and no run
  // keeps more than the input has: the index grows once, where it fits, rather than
  // doubling a dozen times on the pipeline's serial stage.
  const std::size_t expected = std::size_t(std::min<std::uint64_t>(2 * cells.size(), input.info.face_count));
  if (budget.fits(cells.bytes() + kept_.bytes_with(expected))) kept_.reserve_index(expected);
  ProgressPhase phase(progress, "cell quadrics", input.file_size, "B");
  run_ordered_pipeline<FaceChunk>(
      pipeline_tokens(),
      [&](FaceChunk& c) {
        c.count = stream.read(c.tris.data(), kFaceChunk);
        phase.set(stream.bytes_consumed());
        return c.count > 0;
      },
      [&](FaceChunk& c) { sum_face_chunk(input.positions, c); },
      [&](FaceChunk& c) {
        total += c.count;
        merge_faces(c, &to_global);
        chunks.saw(c.cells.bytes() + c.tris.capacity() * sizeof(std::uint64_t) +
                       c.kept.capacity() * sizeof(std::uint32_t) + c.attribute_sums.capacity() * sizeof(double) +
                       c.vertex_weights.bytes() + c.thick.bytes(),
                   c.kept.size() / 3);
        const std::uint64_t thick_bytes = thick ? thick->bytes() : 0;
        budget.check(cells.bytes() + kept.bytes_with(chunks.next_entries()) + chunks.bytes() + thick_bytes,
                     std::to_string(cells.size()) + " occupied cells and " + std::to_string(kept.size()) +
                         " kept triangles" + (thick ? " and " + std::to_string(thick->edges.size()) + " edges" : "") +
                         " after " + std::to_string(total) + " triangles");
        phase.set(stream.bytes_consumed());
      });
  return total;
}

std::pair<std::uint64_t, std::uint64_t> UniformCells::sum_part(MeshInput& input, const ChunkPart& part,
                                                               const ProgressCallback& progress) const {
  const PositionArray& positions = input.positions;
  const std::uint64_t vertex_chunks = (positions.count + kVertexChunk - 1) / kVertexChunk;
  std::uint64_t next = part.part;
  {
    ProgressPhase phase(progress, "cell means", vertex_chunks, "chunk");
    run_ordered_pipeline<VertexChunk>(
        pipeline_tokens(),
        [&](VertexChunk& c) {
          if (next >= vertex_chunks) return false;
          c.begin = next * kVertexChunk;
          c.end = std::min(positions.count, c.begin + kVertexChunk);
          next += part.parts;
          return true;
        },
        [&](VertexChunk& c) { sum_vertex_chunk(positions, c.begin, c.end, &c.cells); },
        [&](VertexChunk& c) {
          VertexChunkSums sums;
          for (std::size_t i = 0; i < c.cells.size(); ++i) {
            sums.keys.push_back(c.cells.key(i));
            sums.sums.push_back(c.cells.value(i));
          }
          part.vertices(c.begin / kVertexChunk, sums);
          phase.set(c.begin / kVertexChunk + 1);
        });
  }
  TriangleStream& stream = *input.triangles;
  std::uint64_t face_chunks = 0;
  ProgressPhase phase(progress, "cell quadrics", input.file_size, "B");
  run_ordered_pipeline<FaceChunk>(
      pipeline_tokens(),
      [&](FaceChunk& c) {
        c.count = stream.read(c.tris.data(), kFaceChunk);
        c.number = face_chunks;
        c.summed = c.number % part.parts == part.part;
        face_chunks += c.count > 0;
        phase.set(stream.bytes_consumed());
        return c.count > 0;
      },
      [&](FaceChunk& c) {
        if (c.summed) sum_face_chunk(positions, c);
      },
      [&](FaceChunk& c) {
        if (!c.summed) return;
        FaceChunkSums sums;
        sums.triangles = c.count;
        for (std::size_t i = 0; i < c.cells.size(); ++i) {
          sums.keys.push_back(c.cells.key(i));
          sums.quadrics.push_back(c.cells.value(i));
        }
        sums.kept = c.kept;
        sums.attribute_sums = c.attribute_sums;
        part.faces(c.number, sums);
      });
  return {vertex_chunks, face_chunks};
}

void UniformCells::merge_vertex_chunk(const VertexChunkSums& chunk) {
  add_vertex_sums(
      cells_, chunk.keys.size(), [&](std::size_t i) { return chunk.keys[i]; },
      [&](std::size_t i) -> const VertexSum& { return chunk.sums[i]; });
}

void UniformCells::merge_face_chunk(const FaceChunkSums& chunk) { merge_faces(chunk, &to_global_); }

void UniformCells::choose_vertices(const PositionArray& positions, VertexMatch matches, const void* context,
                                   const ProgressCallback& progress) {
  chosen_.assign(cells_.size(), ChosenVertex());
  ProgressPhase phase(progress, "cell vertices", positions.count, "vtx");
  // In parallel over ranges of vertices, each range into its own choices, merged by
  // the total order of ChosenVertex::better: the same for any split.
  const std::size_t ranges = std::max<std::size_t>(1, tbb::this_task_arena::max_concurrency());
  std::vector<std::vector<std::pair<std::uint32_t, ChosenVertex>>> found(ranges);
  const std::uint64_t per = (positions.count + ranges - 1) / ranges;
  tbb::parallel_for(std::size_t(0), ranges, [&](std::size_t r) {
    const std::uint64_t begin = std::min<std::uint64_t>(positions.count, r * per);
    const std::uint64_t end = std::min<std::uint64_t>(positions.count, begin + per);
    FlatHashMap<std::uint64_t, ChosenVertex> best(1024);
    for (std::uint64_t v = begin; v < end; ++v) {
      const Vec3d q = positions.get(v);
      if (!is_finite(q)) continue;
      const Vec3d p = grid_.relative(q);
      const std::uint64_t key = keys_.key(v, p);
      const std::int64_t cell = cells_.find(key);
      if (cell < 0) continue;
      const bool m = (key & kLockedKey) != 0 || matches(context, v, key);
      const double e = cells_.value(std::size_t(cell)).q.error(p);
      ChosenVertex& c = best.value(best.insert(std::uint64_t(cell)));
      if (c.better(m, e, v)) c = ChosenVertex{p, e, v, m};
    }
    found[r].reserve(best.size());
    for (std::size_t i = 0; i < best.size(); ++i) found[r].push_back({std::uint32_t(best.key(i)), best.value(i)});
  });
  for (const auto& list : found)
    for (const auto& [cell, c] : list)
      if (chosen_[cell].better(c.matching, c.error, c.vertex)) chosen_[cell] = c;
  phase.set(positions.count);
}

std::size_t UniformCells::locked_output_count(const std::vector<std::uint32_t>& order) const {
  std::size_t n = 0;
  for (std::uint32_t cell : order) n += (cells_.key(cell) & kLockedKey) != 0;
  return n;
}

std::uint64_t UniformCells::chosen_bytes() const { return chosen_.capacity() * sizeof(ChosenVertex); }

void UniformCells::release_indexes() {
  cells_.release_index();
  kept_.release_index();
}

// Output vertices are the cells the kept triangles use, numbered by first use.
std::vector<std::uint32_t> UniformCells::number_output_vertices(OutputMesh* out, const ArrayPlace& place) {
  const CellMap<CellRecord>& cells = cells_;
  TriangleSet& kept = kept_;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> out_index;
  reserve_filled(&out_index, cells.size());
  out_index.assign(cells.size(), kUnused);
  std::vector<std::uint32_t> order;
  order.reserve(cells.size());  // no doubling past the budget
  OutputMesh& mesh = *out;
  mesh.triangles.assign_zeroed(3 * kept.size(), place, "triangles");
  std::uint32_t* triangles = mesh.triangles.data();
  for (std::size_t t = 0; t < kept.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t c = kept[t][std::size_t(k)];
      if (out_index[c] == kUnused) {
        out_index[c] = std::uint32_t(order.size());
        order.push_back(c);
      }
      triangles[3 * t + k] = out_index[c];
    }
  if (thick_) {
    // Their clusters not yet numbered follow the triangles'.
    mesh.primitives = thick_primitives(*thick_, kept, cells, keys_);
    thick_.reset();
    auto number = [&](std::uint32_t& c) {
      if (out_index[c] == kUnused) {
        out_index[c] = std::uint32_t(order.size());
        order.push_back(c);
      }
      c = out_index[c];
    };
    for (std::uint32_t& c : mesh.primitives.edges) number(c);
    for (std::uint32_t& c : mesh.primitives.points) number(c);
  }
  std::vector<std::uint32_t>().swap(out_index);
  kept = TriangleSet();
  return order;
}

void UniformCells::solve_representatives(const std::vector<std::uint32_t>& order, OutputMesh* out,
                                         std::vector<Quadric>* quadrics, const ArrayPlace& place) {
  const GridSpec& grid = grid_;
  const CellKeys& keys = keys_;
  const std::vector<ChosenVertex>& chosen = chosen_;
  const CellMap<CellRecord>& cells = cells_;
  const UniformAttributeSums& attributes = *attributes_;
  std::vector<double>& attribute_sums = attribute_sums_;
  OutputMesh& mesh = *out;
  const std::size_t attribute_count = attributes.layout().count();
  mesh.attributes = attributes.layout().attributes();
  mesh.attribute_values.assign_zeroed(attribute_count * order.size(), place, "attributes");
  double* values = mesh.attribute_values.data();
  if (attribute_count > 0) attribute_sums.resize(cells.size() * attributes.width(), 0.0);  // before the parallel reads

  mesh.positions.assign_zeroed(3 * order.size(), place, "positions");
  double* positions = mesh.positions.data();
  if (quadrics) quadrics->resize(order.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const CellRecord& rec = cells.value(order[i]);
                        const std::uint64_t key = cells.key(order[i]);
                        Vec3d lo = keys.cell_min(key);
                        const double side = keys.cell_side(key);
                        Vec3d hi = lo + Vec3d{side, side, side};
                        const VertexSum& s = rec.vertices;
                        const double half = 0.5 * side;
                        Vec3d mean = s.n ? s.sum / double(s.n) : lo + Vec3d{half, half, half};
                        // A locked vertex's cell is the point where it is, given back as the
                        // input has it (relative + origin may miss it by a bit).
                        const Vec3d x = (key & kLockedKey) ? keys.locked_position(key)
                                        : chosen.empty()   ? minimize_quadric(rec.q, mean, lo, hi) + grid.origin
                                                           : chosen[order[i]].position + grid.origin;
                        if (quadrics) (*quadrics)[i] = rec.q;  // already relative to grid.origin
                        positions[3 * i] = x.x;
                        positions[3 * i + 1] = x.y;
                        positions[3 * i + 2] = x.z;
                        if (attribute_count > 0)
                          attributes.finish(&attribute_sums[std::size_t(order[i]) * attributes.width()],
                                            &values[attribute_count * i]);
                      }
                    });
}

}  // namespace oocsimp
