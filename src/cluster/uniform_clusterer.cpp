// Uniform-grid vertex clustering with quadric representatives: Lindstrom,
// "Out-of-Core Simplification of Large Polygonal Models" (SIGGRAPH 2000), OoCS.
//
// Two streaming passes over the input, each cut into fixed-size chunks that all
// threads process into private cell tables, merged in input order:
//   1. vertices: per cell, the sum and count of the vertex positions in it (the
//      anchor of the quadric solve);
//   2. triangles: per cell, the sum of the area-weighted plane quadrics of every
//      triangle with a corner in it; triangles whose corners fall in three different
//      cells survive, each unordered cell triple once.
// Then every surviving cell gets the point that minimises its quadric (see
// minimize_quadric). Memory holds the occupied cells and the surviving triangles,
// never the input, and stays within --mem (TableBudget) or the run stops.
#include "cluster/uniform_clusterer.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "cluster/attribute_sums.hpp"
#include "cluster/triangle_set.hpp"
#include "common/memory_budget.hpp"
#include "common/vec3_math.hpp"
#include "grid/cell_map.hpp"
#include "grid/occupancy.hpp"
#include "io/ordered_pipeline.hpp"
#include "oocsimp/error.hpp"
#include "report/memory_usage.hpp"
#include "report/progress_phase.hpp"
#include "cluster/quadric.hpp"

namespace oocsimp {

namespace {

struct VertexSum {
  Vec3d sum;
  std::uint64_t n = 0;
};

struct CellRecord {
  Quadric q;
  VertexSum vertices;
};

// Chunk sizes are constants: they fix the order of floating-point sums, so they
// must not depend on the thread count.
constexpr std::uint64_t kVertexChunk = 1 << 16;
constexpr std::size_t kFaceChunk = 1 << 15;

struct VertexChunk {
  std::uint64_t begin = 0, end = 0;
  CellMap<VertexSum> cells{4096};
};

struct FaceChunk {
  std::vector<std::uint64_t> tris = std::vector<std::uint64_t>(3 * kFaceChunk);
  std::size_t count = 0;
  CellMap<Quadric> cells{4096};
  std::vector<std::uint32_t> kept;     // local cell indices, 3 per surviving triangle
  std::vector<double> attribute_sums;  // AttributeLayout::width() per local cell
};

// The attribute sums of every cell, AttributeLayout::width() per cell, in the cells'
// table order; added in input order (chunks merge in order), so deterministic.
struct CellAttributeSums {
  AttributeLayout layout;
  std::vector<double> sums;
  std::size_t width() const { return layout.width(); }
  double* of(std::vector<double>& table, std::uint32_t cell) const {
    if (table.size() < (std::size_t(cell) + 1) * width()) table.resize((std::size_t(cell) + 1) * width(), 0.0);
    return &table[std::size_t(cell) * width()];
  }
};

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

std::uint32_t grid_resolution(const GridSpec& g) { return std::max({g.dims[0], g.dims[1], g.dims[2]}); }

// Bytes an occupied cell takes at least in its table (key, record and the two slots
// of a half-full index).
constexpr std::uint64_t kCellEntryBytes = sizeof(std::uint64_t) + sizeof(CellRecord) + 2 * sizeof(std::uint32_t);
// And what a whole run needs per occupied cell, for the advice: a closed surface keeps
// about two triangles per cell (Euler, as choose_grid assumes), each in the kept list
// and the output (3 indices each), and the cell's output number, order and position.
constexpr std::uint64_t kRunBytesPerCell =
    kCellEntryBytes + 2 * 2 * 3 * sizeof(std::uint32_t) + 2 * sizeof(std::uint32_t) + 3 * sizeof(double);

// The uniform method's tables within --mem (issue 10, "the budget is the process's"):
// the occupied cells and kept triangles in their hash tables, the pipeline's per-chunk
// tables and, at the end, the output arrays, on top of what the process held when the
// run began (its buffers, the libraries). A run that would need more stops with a
// UsageError (exit 2) naming --mem and what would fit, rather than exceed it.
class TableBudget {
 public:
  TableBudget(const MemoryBudget& budget, const GridSpec& grid, const OccupancyGrowth& occupancy,
              std::uint64_t vertices)
      : budget_(budget),
        held_(budget.held()),
        resolution_(grid_resolution(grid)),
        occupancy_(occupancy),
        vertices_(vertices) {}

  /// Throws UsageError unless tables of `bytes` fit next to what was held at the
  /// start; `what` names what they hold ("about 3000000 occupied cells").
  void check(std::uint64_t bytes, const std::string& what) const {
    if (held_ + bytes <= budget_.bytes()) return;
    // The advice: the whole run at about kRunBytesPerCell per occupied cell, and a
    // grid with a tenth fewer cells than that fit in the budget.
    const double room = budget_.bytes() > held_ ? double(budget_.bytes() - held_) : 0.0;
    const std::uint32_t coarser = coarser_resolution(0.9 * room / double(kRunBytesPerCell));
    const double run = occupancy_.occupied_by(resolution_, vertices_) * double(kRunBytesPerCell);
    budget_.check(
        held_, bytes,
        "the uniform method's tables at options.sizing.grid " + std::to_string(resolution_) + " (" + what + ")",
        "give options.memory_budget " + whole_mib(held_ + std::max(bytes, std::uint64_t(run))) +
            " MiB or more, or a coarser grid (options.sizing.grid " + std::to_string(coarser) +
            " or less, or a smaller options.sizing.ratio)");
  }

 private:
  // The finest resolution at which about `cells` are occupied (bisection: occupancy
  // grows with the resolution).
  std::uint32_t coarser_resolution(double cells) const {
    double lo = 1, hi = resolution_;
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (lo + hi);
      (occupancy_.occupied_by(mid, vertices_) <= cells ? lo : hi) = mid;
    }
    return std::uint32_t(lo);
  }

  MemoryBudget budget_;
  std::uint64_t held_;  // when the run began: the tables come on top
  std::uint32_t resolution_;
  OccupancyGrowth occupancy_;
  std::uint64_t vertices_;
};

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

void accumulate_vertices(const PositionArray& positions, const GridSpec& grid, CellMap<CellRecord>& cells,
                         const TableBudget& budget, const ProgressCallback& progress) {
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
      [&](VertexChunk& c) {
        c.cells.clear();
        CellIndexCache<VertexSum> index(c.cells);
        for (std::uint64_t i = c.begin; i < c.end; ++i) {
          Vec3d q = positions.get(i);
          if (!is_finite(q)) continue;  // no cell holds it; its triangles were dropped by the stream
          Vec3d p = grid.relative(q);
          VertexSum& s = c.cells.value(index(grid.key_relative(p)));
          s.sum += p;
          ++s.n;
        }
      },
      [&](VertexChunk& c) {
        for (std::size_t i = 0; i < c.cells.size(); ++i) {
          VertexSum& dst = cells.value(cells.insert(c.cells.key(i))).vertices;
          const VertexSum& src = c.cells.value(i);
          dst.sum += src.sum;
          dst.n += src.n;
        }
        chunks.saw(c.cells.bytes(), c.cells.size());
        budget.check(cells.bytes_with(chunks.next_entries()) + chunks.bytes(),
                     std::to_string(cells.size()) + " occupied cells after " + std::to_string(c.end) + " vertices");
        phase.set(c.end);
      });
}

void accumulate_triangles(MeshInput& input, const GridSpec& grid, CellMap<CellRecord>& cells, TriangleSet& kept,
                          CellAttributeSums& attributes, const TableBudget& budget, std::uint64_t* triangle_count,
                          const ProgressCallback& progress) {
  const AttributeArray& attribute_array = input.attributes;
  const bool with_attributes = !attributes.layout.empty();
  const auto add_double = [](double& sum, double term) { sum += term; };
  const PositionArray& positions = input.positions;
  TriangleStream& stream = *input.triangles;
  std::vector<std::uint32_t> to_global;
  std::uint64_t total = 0;
  ChunkTables chunks(pipeline_tokens());
  ProgressPhase phase(progress, "cell quadrics", input.file_size, "B");
  run_ordered_pipeline<FaceChunk>(
      pipeline_tokens(),
      [&](FaceChunk& c) {
        c.count = stream.read(c.tris.data(), kFaceChunk);
        phase.set(stream.bytes_consumed());
        return c.count > 0;
      },
      [&](FaceChunk& c) {
        c.cells.clear();
        c.kept.clear();
        c.attribute_sums.clear();
        CellIndexCache<Quadric> index(c.cells);
        for (std::size_t t = 0; t < c.count; ++t) {
          const std::uint64_t* v = &c.tris[3 * t];
          Vec3d p0 = grid.relative(positions.get(v[0]));
          Vec3d p1 = grid.relative(positions.get(v[1]));
          Vec3d p2 = grid.relative(positions.get(v[2]));
          std::uint64_t k0 = grid.key_relative(p0), k1 = grid.key_relative(p1), k2 = grid.key_relative(p2);
          Quadric q;
          q.add_triangle(p0, p1, p2);
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
          // Only a triangle spanning three cells survives the collapse.
          if (k0 != k1 && k1 != k2 && k0 != k2) c.kept.insert(c.kept.end(), {i0, i1, i2});
          if (with_attributes) {
            // Each corner adds its values with a third of the area to its own cell.
            const double third_area = length(cross(p1 - p0, p2 - p0)) / 6;
            const std::uint32_t cell_of[3] = {i0, i1, k2 == k0 ? i0 : k2 == k1 ? i1 : i2};
            for (int k = 0; k < 3; ++k)
              attributes.layout.add_vertex(attributes.of(c.attribute_sums, cell_of[k]), attribute_array, v[k],
                                           third_area, add_double);
          }
        }
      },
      [&](FaceChunk& c) {
        total += c.count;
        to_global.resize(c.cells.size());
        for (std::size_t i = 0; i < c.cells.size(); ++i) {
          std::uint32_t g = cells.insert(c.cells.key(i));
          cells.value(g).q.add(c.cells.value(i));
          to_global[i] = g;
          if (with_attributes && c.attribute_sums.size() >= (i + 1) * attributes.width()) {
            double* dst = attributes.of(attributes.sums, g);
            const double* src = &c.attribute_sums[i * attributes.width()];
            for (std::size_t j = 0; j < attributes.width(); ++j) dst[j] += src[j];
          }
        }
        for (std::size_t t = 0; t < c.kept.size(); t += 3)
          kept.insert(to_global[c.kept[t]], to_global[c.kept[t + 1]], to_global[c.kept[t + 2]]);
        chunks.saw(
            c.cells.bytes() + c.tris.capacity() * sizeof(std::uint64_t) + c.kept.capacity() * sizeof(std::uint32_t),
            c.kept.size() / 3);
        budget.check(cells.bytes() + kept.bytes_with(chunks.next_entries()) + chunks.bytes(),
                     std::to_string(cells.size()) + " occupied cells and " + std::to_string(kept.size()) +
                         " kept triangles after " + std::to_string(total) + " triangles");
        phase.set(stream.bytes_consumed());
      });
  *triangle_count = total;
}

}  // namespace

SimplifiedMesh cluster_uniform(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                               SimplifyStats* stats, std::vector<Quadric>* quadrics) {
  const ProgressCallback& progress = options.progress;
  // Up front, before any table grows: the occupied cells alone, estimated from a
  // sample of the vertices (a lower estimate); kept triangles and output come on top.
  const OccupancyGrowth occupancy = sampled_occupancy_growth(input.positions, input.info.bounds);
  const TableBudget budget(MemoryBudget(options), grid, occupancy, input.positions.count);
  const auto estimate = std::uint64_t(occupancy.occupied_by(grid_resolution(grid), input.positions.count));
  budget.check(estimate * kCellEntryBytes, "about " + std::to_string(estimate) + " occupied cells, estimated");
  CellMap<CellRecord> cells(1 << 16);
  TriangleSet kept;

  double t0 = now_seconds();
  accumulate_vertices(input.positions, grid, cells, budget, progress);
  // The cells are known now, before the faces are read: with the fewest kept
  // triangles (none) and their output indices, do they fit?
  budget.check(cells.bytes() + 2 * sizeof(std::uint32_t) * cells.size(),
               std::to_string(cells.size()) + " occupied cells");
  double t1 = now_seconds();
  std::uint64_t triangles = 0;
  CellAttributeSums attributes{AttributeLayout(input.attributes), {}};
  if (!attributes.layout.empty()) {
    const std::uint64_t bytes = std::uint64_t(cells.size()) * attributes.width() * sizeof(double);
    budget.check(cells.bytes() + bytes, std::to_string(cells.size()) + " occupied cells with " +
                                            std::to_string(attributes.layout.count()) + " attributes each");
    attributes.sums.assign(cells.size() * attributes.width(), 0.0);
  }
  accumulate_triangles(input, grid, cells, kept, attributes, budget, &triangles, progress);
  double t2 = now_seconds();

  ProgressPhase solve_phase(progress, "solve", 0, "cell");
  // The hash indexes are not needed any more; free them before the output arrays
  // are allocated, which keeps the peak down.
  cells.release_index();
  kept.release_index();
  const std::size_t kept_count = kept.size();
  // The output tables next to the cells: numbering and triangles, then (numbering
  // freed) the positions of at most every cell.
  const std::string output =
      std::to_string(cells.size()) + " occupied cells and " + std::to_string(kept_count) + " output triangles";
  const std::uint64_t triangle_bytes = 3 * sizeof(std::uint32_t) * kept_count;
  const std::uint64_t attribute_bytes = attributes.sums.capacity() * sizeof(double);
  budget.check(
      cells.bytes() + attribute_bytes + kept.bytes() + 2 * sizeof(std::uint32_t) * cells.size() + triangle_bytes,
      output);

  // Output vertices are the cells the kept triangles use, numbered by first use.
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> out_index(cells.size(), kUnused);
  std::vector<std::uint32_t> order;
  order.reserve(cells.size());  // no doubling past the budget
  SimplifiedMesh mesh;
  mesh.triangles.resize(3 * kept_count);
  for (std::size_t t = 0; t < kept.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t c = kept[t][std::size_t(k)];
      if (out_index[c] == kUnused) {
        out_index[c] = std::uint32_t(order.size());
        order.push_back(c);
      }
      mesh.triangles[3 * t + k] = out_index[c];
    }
  std::vector<std::uint32_t>().swap(out_index);
  kept = TriangleSet();
  const std::size_t attribute_count = attributes.layout.count();
  budget.check(cells.bytes() + attribute_bytes + sizeof(std::uint32_t) * order.capacity() + triangle_bytes +
                   (3 + attribute_count) * sizeof(double) * order.size(),
               output);
  mesh.attributes.attributes = attributes.layout.attributes();
  mesh.attributes.values.resize(attribute_count * order.size());
  if (attribute_count > 0) attributes.sums.resize(cells.size() * attributes.width(), 0.0);  // before the parallel reads

  mesh.positions.resize(3 * order.size());
  if (quadrics) quadrics->resize(order.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const CellRecord& rec = cells.value(order[i]);
                        Vec3d lo = grid.cell_min_relative(cells.key(order[i]));
                        Vec3d hi = lo + Vec3d{grid.cell, grid.cell, grid.cell};
                        const VertexSum& s = rec.vertices;
                        const double half = 0.5 * grid.cell;
                        Vec3d mean = s.n ? s.sum / double(s.n) : lo + Vec3d{half, half, half};
                        Vec3d x = minimize_quadric(rec.q, mean, lo, hi) + grid.origin;
                        if (quadrics) (*quadrics)[i] = rec.q;  // already relative to grid.origin
                        mesh.positions[3 * i] = x.x;
                        mesh.positions[3 * i + 1] = x.y;
                        mesh.positions[3 * i + 2] = x.z;
                        if (attribute_count > 0)
                          attributes.layout.finish(&attributes.sums[std::size_t(order[i]) * attributes.width()],
                                                   &mesh.attributes.values[attribute_count * i]);
                      }
                    });
  double t3 = now_seconds();

  if (stats) {
    stats->input_triangles = triangles;
    stats->skipped = input.triangles->skipped();
    stats->occupied_cells = cells.size();
    stats->output_vertices = order.size();
    stats->output_triangles = kept_count;
    stats->phases.push_back({"vertices", t1 - t0});
    stats->phases.push_back({"faces", t2 - t1});
    stats->phases.push_back({"solve", t3 - t2});
  }
  return mesh;
}

}  // namespace oocsimp
