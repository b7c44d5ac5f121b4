// Floating-cell clustering out of core: tiles, rounds of border decisions,
// partition-independent sums and a stitch of the cross-tile triangles.
// floating_cells_design.md explains why the result equals the sequential algorithm.
//
//   pass 1  bin: every triangle goes to the tile of each of its corners
//   pass 2  per tile: grade the owned vertices (Low & Tan §3.1), sort them (§3.2),
//           spill them, run the greedy; then rounds with the neighbours' border
//           centres until no border changes
//   pass 3  per tile: assign vertices to centres, add vertex quadrics to clusters
//           in fixed point, keep the triangles that span three clusters; the
//           triangles that cross tiles are grouped by index through a bucket spill
//   solve   representatives; output triangles in input order of first occurrence
#include "cluster/floating_clusterer.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <unordered_map>

#include "cluster/floating_cells.hpp"
#include "cluster/ordered_pipeline.hpp"
#include "grid/grid_coord.hpp"
#include "grid/occupancy.hpp"
#include "grid/tile_spill_file.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/progress.hpp"
#include "oocsimp/quadric.hpp"

namespace oocsimp {

namespace {

// --- records on disk ---

struct TriangleRecord {
  std::uint64_t t;     // input triangle index (file order)
  std::uint64_t v[3];  // input vertex indices
};

// One corner of a cross-tile triangle, with the cluster its owner tile gave it.
struct CornerRecord {
  std::uint64_t t_and_slot;  // t << 2 | corner slot
  std::uint64_t cluster;     // input index of the cluster's centre
};

// --- partition-independent sums ---

// A sum of doubles in 64.64 fixed point: integer addition is associative, so the
// total does not depend on how the terms were grouped into tiles or threads.
struct Fixed {
  __int128 v = 0;
  static constexpr double kScale = 18446744073709551616.0;  // 2^64
  void add(double x) { v += static_cast<__int128>(x * kScale); }
  void add(const Fixed& o) { v += o.v; }
  double value() const { return static_cast<double>(v) / kScale; }
};

// Everything a cluster accumulates, in coordinates relative to its centre and in
// units of the cell size (so magnitudes stay near 1 and the fixed-point resolution
// is relative to the cell, not to the bounding box).
struct ClusterSum {
  Fixed a00, a01, a02, a11, a12, a22, b0, b1, b2;  // quadric (the constant is not needed)
  Fixed mx, my, mz;                                // sum of member positions
  std::uint64_t members = 0;
  void add(const ClusterSum& o) {
    Fixed* d = &a00;
    const Fixed* s = &o.a00;
    for (int i = 0; i < 12; ++i) d[i].add(s[i]);
    members += o.members;
  }
};

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

// The first centre (in precedes order) present in one of two precedes-sorted lists
// but not the other, or null when they hold the same centres.
const GradedVertex* first_difference(const std::vector<GradedVertex>& a, const std::vector<GradedVertex>& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i].index == b[j].index) {
      ++i;
      ++j;
    } else {
      return precedes(a[i], b[j]) ? &a[i] : &b[j];
    }
  }
  if (i < a.size()) return &a[i];
  if (j < b.size()) return &b[j];
  return nullptr;
}

constexpr std::size_t kBinChunk = 1 << 15;

struct BinChunk {
  std::vector<std::uint64_t> tris = std::vector<std::uint64_t>(3 * kBinChunk);
  std::size_t count = 0;
  std::uint64_t first = 0;  // input index of the first triangle
  // (tile coordinate, record) pairs, sorted by tile so each tile gets one append.
  std::vector<std::pair<GridCoord, TriangleRecord>> out;
};

class FloatingRun {
 public:
  FloatingRun(MeshInput& input, const SimplifyOptions& options, double cell, SimplifyStats* stats)
      : input_(input), options_(options), cell_{cell, options.cell_shape}, half_(0.5 * cell), stats_(stats) {}

  SimplifiedMesh run() {
    double t0 = now_seconds();
    plan_tiles();
    bin_triangles();
    double t1 = now_seconds();
    grade_and_choose();
    double t2 = now_seconds();
    assign_and_accumulate();
    double t3 = now_seconds();
    stitch_cross_tile_triangles();
    double t4 = now_seconds();
    SimplifiedMesh m = assemble();
    double t5 = now_seconds();
    if (std::getenv("OOCSIMP_DEBUG_ROUNDS"))
      std::fprintf(stderr, "bin %.3f grade+rounds %.3f (rounds %.3f) cluster %.3f stitch %.3f assemble %.3f\n", t1 - t0,
                   t2 - t1, rounds_seconds_, t3 - t2, t4 - t3, t5 - t4);
    return m;
  }

 private:
  // Tile side from the memory budget: a tile's working set is about kBytesPerTriangle
  // per triangle and `threads` tiles are in memory at once; use half the budget.
  void plan_tiles() {
    constexpr double kBytesPerTriangle = 400;
    std::uint64_t budget = options_.memory_budget;
    unsigned threads = unsigned(std::max(1, tbb::this_task_arena::max_concurrency()));
    double side = options_.tile_side;
    if (side <= 0) {
      double per_tile = std::max(1.0, double(budget) / 2 / threads / kBytesPerTriangle);
      double tiles_needed = std::max(1.0, double(input_.info.face_count) / per_tile);
      const Box3d& b = input_.info.bounds;
      double longest = b.empty() ? 1 : std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z});
      if (tiles_needed <= 1 || longest <= 0) {
        side = std::max(longest, cell_.size);
      } else {
        std::vector<std::uint64_t> occ = count_occupancy(input_.positions, b);
        int l = 0;
        while (l + 1 < kLevelCount && double(occ[std::size_t(l)]) < tiles_needed) ++l;
        double divisions = double(kLevels[l]);
        if (double(occ[std::size_t(l)]) < tiles_needed)  // beyond the finest level: surfaces scale as n^2
          divisions *= std::sqrt(tiles_needed / double(std::max<std::uint64_t>(occ[std::size_t(l)], 1)));
        side = longest / divisions;
      }
    }
    // A tile is at least one floating cell wide, so a cell reaches only into the
    // adjacent tiles.
    tiles_.side = std::max(side, cell_.size);
  }

  std::uint32_t tile_id(const GridCoord& c) {
    auto it = tile_ids_.find(c);
    if (it != tile_ids_.end()) return it->second;
    std::uint32_t id = triangles_->add_tile();
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
    std::size_t buffer_records =
        std::clamp<std::size_t>(std::size_t(double(budget) / 4 / double(est_tiles) / sizeof(TriangleRecord)), 256, 8192);
    triangles_ = std::make_unique<TileSpillFile>(temp_dir(), "tiles", sizeof(TriangleRecord), buffer_records, true);

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
          c.out.clear();
          for (std::size_t i = 0; i < c.count; ++i) {
            TriangleRecord r{c.first + i, {c.tris[3 * i], c.tris[3 * i + 1], c.tris[3 * i + 2]}};
            GridCoord k[3];
            for (int j = 0; j < 3; ++j) k[j] = tiles_.of(pos.get(r.v[j]));
            c.out.push_back({k[0], r});
            if (k[1] != k[0]) c.out.push_back({k[1], r});
            if (k[2] != k[0] && k[2] != k[1]) c.out.push_back({k[2], r});
          }
          std::stable_sort(c.out.begin(), c.out.end(),
                           [](const auto& a, const auto& b) { return a.first < b.first; });
        },
        [&](BinChunk& c) {
          for (std::size_t i = 0; i < c.out.size();) {
            std::size_t j = i;
            std::vector<TriangleRecord>& run = run_buffer_;
            run.clear();
            while (j < c.out.size() && c.out[j].first == c.out[i].first) run.push_back(c.out[j++].second);
            triangles_->append(tile_id(c.out[i].first), run.data(), run.size());
            i = j;
          }
        });
    triangles_->flush();
    if (progress) progress->end();
    triangle_count_ = next;
    centres_.resize(triangles_->tile_count());
    border_.resize(triangles_->tile_count());
    vertices_ = std::make_unique<TileSpillFile>(temp_dir(), "vertices", sizeof(GradedVertex), 4096, true);
    for (std::uint32_t i = 0; i < triangles_->tile_count(); ++i) vertices_->add_tile();
  }

  std::string temp_dir() const { return options_.temp_dir.empty() ? default_temp_dir() : options_.temp_dir; }

  // The tile's triangles, sorted by input index (the spill order depends on nothing
  // but the input, but sorting makes that obvious).
  std::vector<TriangleRecord> load_triangles(std::uint32_t tile) const {
    std::vector<unsigned char> bytes;
    triangles_->read(tile, &bytes);
    std::vector<TriangleRecord> t(bytes.size() / sizeof(TriangleRecord));
    std::memcpy(t.data(), bytes.data(), bytes.size());
    std::sort(t.begin(), t.end(), [](const TriangleRecord& a, const TriangleRecord& b) { return a.t < b.t; });
    return t;
  }

  std::vector<GradedVertex> load_vertices(std::uint32_t tile) const {
    std::vector<unsigned char> bytes;
    vertices_->read(tile, &bytes);
    std::vector<GradedVertex> v(bytes.size() / sizeof(GradedVertex));
    std::memcpy(v.data(), bytes.data(), bytes.size());
    return v;
  }

  bool owns(std::uint32_t tile, std::uint64_t vertex) const {
    return tiles_.of(input_.positions.get(vertex)) == tile_coords_[tile];
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

  std::vector<GradedVertex> external_centres(std::uint32_t tile) const {
    std::vector<GradedVertex> ext;
    for (std::uint32_t n : neighbours(tile)) ext.insert(ext.end(), border_[n].begin(), border_[n].end());
    return ext;
  }

  std::vector<GradedVertex> border_of(std::uint32_t tile) const {
    Box3d box = tiles_.box(tile_coords_[tile]);
    std::vector<GradedVertex> b;
    for (const GradedVertex& c : centres_[tile])
      if (near_border(c.p, box, half_)) b.push_back(c);
    return b;
  }

  void grade_and_choose() {
    std::uint32_t n = triangles_->tile_count();
    ProgressReporter* progress = options_.progress;
    if (progress) progress->begin("grade tiles", n, "tile");
    std::atomic<std::uint32_t> done{0};
    // Round 1: grade, sort and spill every tile's vertices; greedy without
    // external centres.
    tbb::parallel_for(std::uint32_t(0), n, [&](std::uint32_t tile) {
      std::vector<TriangleRecord> tris = load_triangles(tile);
      std::vector<std::uint64_t> owned, flat;
      flat.reserve(3 * tris.size());
      for (const TriangleRecord& r : tris)
        for (std::uint64_t v : r.v) {
          flat.push_back(v);
          if (owns(tile, v)) owned.push_back(v);
        }
      std::sort(owned.begin(), owned.end());
      owned.erase(std::unique(owned.begin(), owned.end()), owned.end());
      std::vector<GradedVertex> graded = grade_vertices(owned, flat.data(), tris.size(), input_.positions);
      std::sort(graded.begin(), graded.end(), precedes);
      vertices_->append(tile, graded.data(), graded.size());
      centres_[tile] = choose_centres(graded, {}, cell_);
      if (progress) progress->set(++done);
    });
    vertices_->flush();
    if (progress) progress->end();

    // Rounds: a tile runs again when the external centres it sees changed. Its
    // decisions for vertices that precede every changed centre stand (they depend
    // only on what precedes them), so the greedy resumes at the first vertex that
    // does not.
    double rounds_start = now_seconds();
    std::vector<std::vector<GradedVertex>> seen(n);  // external input of each tile's last run
    std::uint64_t rounds = 1;
    for (;;) {
      for (std::uint32_t t = 0; t < n; ++t) border_[t] = border_of(t);
      std::vector<std::pair<std::uint32_t, GradedVertex>> dirty;  // tile, heaviest changed centre
      for (std::uint32_t t = 0; t < n; ++t) {
        std::vector<GradedVertex> ext = external_centres(t);
        std::sort(ext.begin(), ext.end(), precedes);
        const GradedVertex* first_change = first_difference(seen[t], ext);
        if (first_change) dirty.push_back({t, *first_change});
      }
      if (dirty.empty()) break;
      ++rounds;
      if (std::getenv("OOCSIMP_DEBUG_ROUNDS"))
        std::fprintf(stderr, "round %llu: %zu dirty tiles\n", (unsigned long long)rounds, dirty.size());
      tbb::parallel_for(std::size_t(0), dirty.size(), [&](std::size_t i) {
        std::uint32_t tile = dirty[i].first;
        const GradedVertex& changed = dirty[i].second;
        std::vector<GradedVertex> ext = external_centres(tile);
        std::sort(ext.begin(), ext.end(), precedes);
        std::vector<GradedVertex> verts = load_vertices(tile);
        std::size_t start = std::size_t(
            std::partition_point(verts.begin(), verts.end(), [&](const GradedVertex& v) { return precedes(v, changed); }) -
            verts.begin());
        std::vector<GradedVertex>& own = centres_[tile];
        own.erase(std::partition_point(own.begin(), own.end(), [&](const GradedVertex& c) { return precedes(c, changed); }),
                  own.end());
        own = choose_centres(verts, start, std::move(own), ext, cell_);
        seen[tile] = std::move(ext);
      });
    }
    rounds_seconds_ = now_seconds() - rounds_start;
    if (stats_) stats_->rounds = rounds;
  }

  // Per tile: assignment, vertex quadrics into cluster sums, surviving triangles.
  void assign_and_accumulate() {
    std::uint32_t n = triangles_->tile_count();
    std::size_t buckets = std::max<std::size_t>(1, std::size_t(triangle_count_ / (1 << 22)) + 1);
    bucket_span_ = std::max<std::uint64_t>(1, (triangle_count_ + buckets - 1) / buckets);
    corners_ = std::make_unique<TileSpillFile>(temp_dir(), "stitch", sizeof(CornerRecord), 4096, true);
    for (std::size_t b = 0; b < buckets; ++b) corners_->add_tile();
    ProgressReporter* progress = options_.progress;
    if (progress) progress->begin("cluster tiles", n, "tile");
    std::atomic<std::uint32_t> done{0};
    std::mutex merge;
    tbb::parallel_for(std::uint32_t(0), n, [&](std::uint32_t tile) {
      std::vector<TriangleRecord> tris = load_triangles(tile);
      std::vector<GradedVertex> owned = load_vertices(tile);
      std::vector<GradedVertex> near = centres_[tile];
      std::vector<GradedVertex> ext = external_centres(tile);
      near.insert(near.end(), ext.begin(), ext.end());
      std::vector<std::uint64_t> cluster = assign_to_centres(owned, near, cell_, options_.assign);
      // Owned vertex -> (cluster, centre position), looked up by vertex index.
      std::unordered_map<std::uint64_t, std::size_t> slot;
      slot.reserve(owned.size());
      for (std::size_t i = 0; i < owned.size(); ++i) slot.emplace(owned[i].index, i);
      std::unordered_map<std::uint64_t, Vec3d> centre_pos;
      for (const GradedVertex& c : near) centre_pos.emplace(c.index, c.p);

      std::unordered_map<std::uint64_t, ClusterSum> sums;
      for (std::size_t i = 0; i < owned.size(); ++i) {
        const Vec3d& c = centre_pos.at(cluster[i]);
        ClusterSum& s = sums[cluster[i]];
        s.mx.add((owned[i].p.x - c.x) / cell_.size);
        s.my.add((owned[i].p.y - c.y) / cell_.size);
        s.mz.add((owned[i].p.z - c.z) / cell_.size);
        ++s.members;
      }
      std::vector<std::array<std::uint64_t, 4>> kept;  // (t, clusters in file orientation)
      std::vector<CornerRecord> corners;
      for (const TriangleRecord& r : tris) {
        std::int64_t local[3];
        int owned_count = 0;
        for (int k = 0; k < 3; ++k) {
          auto it = slot.find(r.v[k]);
          local[k] = it == slot.end() ? -1 : std::int64_t(it->second);
          owned_count += local[k] >= 0;
        }
        Vec3d p[3] = {input_.positions.get(r.v[0]), input_.positions.get(r.v[1]), input_.positions.get(r.v[2])};
        // The vertex quadric of each owned corner takes this face (Garland &
        // Heckbert), expressed relative to the corner's cluster centre.
        for (int k = 0; k < 3; ++k) {
          if (local[k] < 0) continue;
          std::uint64_t cl = cluster[std::size_t(local[k])];
          const Vec3d& c = centre_pos.at(cl);
          Vec3d q[3];
          for (int m = 0; m < 3; ++m)
            q[m] = {(p[m].x - c.x) / cell_.size, (p[m].y - c.y) / cell_.size, (p[m].z - c.z) / cell_.size};
          Quadric face;
          face.add_triangle(q[0], q[1], q[2]);
          ClusterSum& s = sums[cl];
          s.a00.add(face.a00);
          s.a01.add(face.a01);
          s.a02.add(face.a02);
          s.a11.add(face.a11);
          s.a12.add(face.a12);
          s.a22.add(face.a22);
          s.b0.add(face.b0);
          s.b1.add(face.b1);
          s.b2.add(face.b2);
        }
        if (owned_count == 3) {
          std::uint64_t c0 = cluster[std::size_t(local[0])], c1 = cluster[std::size_t(local[1])],
                        c2 = cluster[std::size_t(local[2])];
          if (c0 != c1 && c1 != c2 && c0 != c2) kept.push_back({r.t, c0, c1, c2});
        } else {
          for (int k = 0; k < 3; ++k)
            if (local[k] >= 0) corners.push_back({r.t << 2 | std::uint64_t(k), cluster[std::size_t(local[k])]});
        }
      }
      for (const CornerRecord& c : corners) corners_->append(std::uint32_t((c.t_and_slot >> 2) / bucket_span_), &c, 1);
      std::lock_guard<std::mutex> lock(merge);
      for (auto& kv : sums) clusters_[kv.first].add(kv.second);
      for (const auto& k : kept) keep(k);
      for (const GradedVertex& c : centres_[tile]) centre_of_.emplace(c.index, c.p);
      if (progress) progress->set(++done);
    });
    corners_->flush();
    if (progress) progress->end();
  }

  // Keeps the triangle over three distinct clusters with the smallest input index:
  // its orientation and its place in the output order. A minimum does not depend
  // on the order in which tiles report.
  void keep(const std::array<std::uint64_t, 4>& k) {
    std::array<std::uint64_t, 3> key = {k[1], k[2], k[3]};
    std::sort(key.begin(), key.end());
    auto it = kept_.find(key);
    if (it == kept_.end() || k[0] < it->second[0]) kept_[key] = k;
  }

  // Cross-tile triangles: their corners' clusters were written by the tiles owning
  // the corners into buckets by triangle index; a bucket fits in memory.
  void stitch_cross_tile_triangles() {
    for (std::uint32_t b = 0; b < corners_->tile_count(); ++b) {
      std::vector<unsigned char> bytes;
      corners_->read(b, &bytes);
      std::vector<CornerRecord> rec(bytes.size() / sizeof(CornerRecord));
      std::memcpy(rec.data(), bytes.data(), bytes.size());
      std::sort(rec.begin(), rec.end(), [](const CornerRecord& a, const CornerRecord& c) { return a.t_and_slot < c.t_and_slot; });
      for (std::size_t i = 0; i < rec.size();) {
        std::uint64_t t = rec[i].t_and_slot >> 2;
        if (i + 2 >= rec.size() || (rec[i + 2].t_and_slot >> 2) != t)
          throw std::logic_error("stitch: triangle " + std::to_string(t) + " lacks a corner");
        std::uint64_t c0 = rec[i].cluster, c1 = rec[i + 1].cluster, c2 = rec[i + 2].cluster;
        if (c0 != c1 && c1 != c2 && c0 != c2) keep({t, c0, c1, c2});
        i += 3;
      }
    }
    if (stats_) {
      stats_->spill_bytes = triangles_->bytes_on_disk() + vertices_->bytes_on_disk() + corners_->bytes_on_disk();
      stats_->spill_raw_bytes =
          triangles_->bytes_appended() + vertices_->bytes_appended() + corners_->bytes_appended();
    }
  }

  Vec3d representative(std::uint64_t centre) const {
    const Vec3d& c = centre_of_.at(centre);
    const ClusterSum& s = clusters_.at(centre);
    double m = double(std::max<std::uint64_t>(s.members, 1));
    Vec3d mean{s.mx.value() / m, s.my.value() / m, s.mz.value() / m};  // relative, in cells
    Vec3d x;
    switch (options_.representative) {
      case RepresentativeRule::centre: return c;
      case RepresentativeRule::mean: x = mean; break;
      case RepresentativeRule::quadric: {
        Quadric q;
        q.a00 = s.a00.value(); q.a01 = s.a01.value(); q.a02 = s.a02.value();
        q.a11 = s.a11.value(); q.a12 = s.a12.value(); q.a22 = s.a22.value();
        q.b0 = s.b0.value(); q.b1 = s.b1.value(); q.b2 = s.b2.value();
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
    std::vector<std::array<std::uint64_t, 4>> tris;
    tris.reserve(kept_.size());
    for (const auto& kv : kept_) tris.push_back(kv.second);
    std::sort(tris.begin(), tris.end());  // by input index of first occurrence
    std::unordered_map<std::uint64_t, std::uint32_t> index;
    std::vector<std::uint64_t> order;
    SimplifiedMesh mesh;
    mesh.triangles.reserve(3 * tris.size());
    for (const auto& t : tris)
      for (int k = 1; k <= 3; ++k) {
        auto it = index.try_emplace(t[std::size_t(k)], std::uint32_t(order.size())).first;
        if (it->second == order.size()) order.push_back(t[std::size_t(k)]);
        mesh.triangles.push_back(it->second);
      }
    mesh.positions.resize(3 * order.size());
    tbb::parallel_for(std::size_t(0), order.size(), [&](std::size_t i) {
      Vec3d p = representative(order[i]);
      mesh.positions[3 * i] = float(p.x);
      mesh.positions[3 * i + 1] = float(p.y);
      mesh.positions[3 * i + 2] = float(p.z);
    });
    if (stats_) {
      stats_->input_triangles = triangle_count_;
      stats_->skipped_faces = input_.triangles->skipped_faces();
      stats_->occupied_cells = centre_of_.size();
      stats_->output_vertices = order.size();
      stats_->output_triangles = tris.size();
      stats_->tiles = triangles_->tile_count();
    }
    return mesh;
  }

  MeshInput& input_;
  const SimplifyOptions& options_;
  FloatingCellShape cell_;
  double half_;
  SimplifyStats* stats_;
  TileGeometry tiles_;
  std::unique_ptr<TileSpillFile> triangles_, vertices_, corners_;
  std::unordered_map<GridCoord, std::uint32_t, GridCoordHash> tile_ids_;
  std::vector<GridCoord> tile_coords_;
  std::vector<TriangleRecord> run_buffer_;
  std::uint64_t triangle_count_ = 0;
  double rounds_seconds_ = 0;
  std::uint64_t bucket_span_ = 1;
  std::vector<std::vector<GradedVertex>> centres_, border_;
  std::unordered_map<std::uint64_t, ClusterSum> clusters_;
  std::unordered_map<std::uint64_t, Vec3d> centre_of_;
  std::map<std::array<std::uint64_t, 3>, std::array<std::uint64_t, 4>> kept_;
};

}  // namespace

SimplifiedMesh cluster_floating(MeshInput& input, const SimplifyOptions& options, double cell, SimplifyStats* stats) {
  FloatingRun run(input, options, cell, stats);
  return run.run();
}

}  // namespace oocsimp
