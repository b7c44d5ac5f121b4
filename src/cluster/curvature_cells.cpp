// Curvature-adaptive cells (Hua et al. §3.4) and their connected parts; see
// curvature_cells.hpp. What the paper leaves open (the cell's curvature, the
// tolerance, the depth, the parts) is in docs/curvature.md.
#include "cluster/curvature_cells.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "grid/cell_map.hpp"
#include "oocsimp/error.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

constexpr std::uint32_t kNoLeaf = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kUndecided = kNoLeaf - 1;
constexpr std::uint64_t kCheckEvery = 1 << 20;  // vertices between budget checks
constexpr std::size_t kTriangleChunk = 65536;

// What the octree sums in a cell: its vertices' curvatures (for the means) and their
// range (for the match), and, once decided, the leaf it is.
struct CellCurvatures {
  double sum1 = 0, sum2 = 0;
  float min1 = std::numeric_limits<float>::max(), max1 = -std::numeric_limits<float>::max();
  float min2 = std::numeric_limits<float>::max(), max2 = -std::numeric_limits<float>::max();
  std::uint32_t n = 0;
  std::uint32_t leaf = kNoLeaf;

  void add(float k1, float k2) {
    sum1 += k1;
    sum2 += k2;
    min1 = std::min(min1, k1);
    max1 = std::max(max1, k1);
    min2 = std::min(min2, k2);
    max2 = std::max(max2, k2);
    ++n;
  }
  float mean1() const { return n ? float(sum1 / n) : 0.f; }
  float mean2() const { return n ? float(sum2 / n) : 0.f; }
  // Every vertex within `within` of the means, in both curvatures.
  bool all_match(double within) const {
    const double m1 = sum1 / n, m2 = sum2 / n;
    return std::max({max1 - m1, m1 - min1, max2 - m2, m2 - min2}) <= within;
  }
};

// The cell at `depth` below the grid's cells that holds the relative point p, packed
// as GridSpec::key_relative: the grid's cell coordinate scaled by 2^depth, exactly
// (a power of two), so a cell's children hold exactly the points it holds.
std::uint64_t octree_key(const GridSpec& grid, const Vec3d& p, std::uint32_t depth) {
  const double scale = double(std::uint64_t(1) << depth);
  auto axis = [&](double d, int a) -> std::uint64_t {
    const double q = d / grid.cell * scale;
    const std::uint64_t n = std::uint64_t(grid.dims[a]) << depth;
    if (!(q > 0)) return 0;
    if (q >= double(n)) return n - 1;
    return std::uint64_t(q);
  };
  return axis(p.x, 0) | (axis(p.y, 1) << 21) | (axis(p.z, 2) << 42);
}

constexpr std::uint64_t kAxisMask = (std::uint64_t(1) << 21) - 1;

// The side of a cell `depth` splits below the grid's.
double side_at(const GridSpec& grid, std::uint32_t depth) { return std::ldexp(grid.cell, -int(depth)); }

// The deepest split of `grid` whose cells still pack into a key (21 bits an axis), at
// most `wanted`.
std::uint32_t usable_depth(const GridSpec& grid, std::uint32_t wanted) {
  const std::uint64_t widest = std::max({grid.dims[0], grid.dims[1], grid.dims[2]});
  std::uint32_t depth = 0;
  while (depth < wanted && (widest << (depth + 1)) <= kAxisMask) ++depth;
  return depth;
}

}  // namespace

VertexClusters::VertexClusters(const GridSpec& grid, const CurvatureCellSettings& settings, std::uint64_t vertices,
                               const std::string& temp_dir)
    : grid_(grid), settings_(settings), vertices_(vertices), temp_dir_(temp_dir) {
  settings_.max_depth = usable_depth(grid, settings.max_depth);
  if (vertices >= std::uint64_t(kUndecided))
    throw UsageError("curvature clustering names vertices by 32-bit indices, and the mesh has 2^32 or more");
}

VertexClusters::~VertexClusters() = default;

void VertexClusters::find_leaves(const PositionArray& positions, const float* k, const MemoryBudget& budget,
                                 const ProgressCallback& progress) {
  const std::uint32_t depths = settings_.max_depth + 1;
  const std::uint64_t held = budget.held();
  leaf_of_ = std::make_unique<MappedScratch>(temp_dir_, "curvature-leaves", 4 * vertices_);
  std::uint32_t* leaf_of = reinterpret_cast<std::uint32_t*>(leaf_of_->data());
  std::fill(leaf_of, leaf_of + vertices_, kUndecided);
  // Depth by depth, over the vertices not yet in a leaf: the sums of the cells at this
  // depth that hold them, then each such vertex's cell becomes its leaf when all its
  // vertices match (or at the deepest), and the rest go one depth down. One depth's
  // sums are held at a time, of the cells that split above it only.
  std::uint64_t undecided = positions.count;
  ProgressPhase phase(progress, "curvature cells", depths * positions.count, "vtx");
  for (std::uint32_t d = 0; d < depths && undecided > 0; ++d) {
    const double side = side_at(grid_, d);
    CellMap<CellCurvatures> cells(1 << 12);
    for (std::uint64_t v = 0; v < positions.count; ++v) {
      if (leaf_of[v] != kUndecided) continue;
      const Vec3d q = positions.get(v);
      if (!is_finite(q)) {
        leaf_of[v] = kNoLeaf;
        continue;
      }
      cells.value(cells.insert(octree_key(grid_, grid_.relative(q), d))).add(k[2 * v], k[2 * v + 1]);
      if ((v + 1) % kCheckEvery == 0) {
        budget.check(held, cells.bytes(),
                     std::to_string(cells.size()) + " curvature cells at depth " + std::to_string(d),
                     "give more memory, a coarser grid or a smaller options.curvature.max_depth");
        phase.set(d * positions.count + v + 1);
      }
    }
    undecided = 0;
    for (std::uint64_t v = 0; v < positions.count; ++v) {
      if (leaf_of[v] != kUndecided) continue;
      const std::uint64_t key = octree_key(grid_, grid_.relative(positions.get(v)), d);
      CellCurvatures& c = cells.value(std::size_t(cells.find(key)));
      if (d + 1 < depths && !c.all_match(settings_.tolerance / side)) {
        ++undecided;
        continue;
      }
      if (c.leaf == kNoLeaf) {
        c.leaf = std::uint32_t(leaves_.size());
        leaves_.push_back(LeafCell{key, d, c.mean1(), c.mean2()});
      }
      leaf_of[v] = c.leaf;
    }
    phase.set((d + 1) * positions.count);
  }
}

void VertexClusters::join_components(MeshInput& input, const ProgressCallback& progress) {
  const std::uint32_t* leaf_of = reinterpret_cast<const std::uint32_t*>(leaf_of_->data());
  parts_ = std::make_unique<MappedScratch>(temp_dir_, "curvature-parts", 4 * vertices_);
  std::uint32_t* parent = reinterpret_cast<std::uint32_t*>(parts_->data());
  for (std::uint64_t v = 0; v < vertices_; ++v) parent[v] = std::uint32_t(v);
  // Union-find where a part's root is its least vertex: the parts, and so the
  // numbering below, do not depend on the order the sides are met in. Path halving
  // keeps every parent below its child.
  auto find = [parent](std::uint32_t v) {
    while (parent[v] != v) {
      parent[v] = parent[parent[v]];
      v = parent[v];
    }
    return v;
  };
  auto join = [&](std::uint32_t a, std::uint32_t b) {
    if (leaf_of[a] != leaf_of[b] || leaf_of[a] == kNoLeaf) return;
    a = find(a);
    b = find(b);
    if (a < b) parent[b] = a;
    if (b < a) parent[a] = b;
  };
  {
    ProgressPhase phase(progress, "curvature parts", input.file_size, "B");
    std::vector<std::uint64_t> corners(3 * kTriangleChunk);
    TriangleStream& stream = *input.triangles;
    while (const std::size_t n = stream.read(corners.data(), kTriangleChunk)) {
      for (std::size_t t = 0; t < n; ++t) {
        const std::uint32_t a = std::uint32_t(corners[3 * t]), b = std::uint32_t(corners[3 * t + 1]),
                            c = std::uint32_t(corners[3 * t + 2]);
        join(a, b);
        join(b, c);
        join(c, a);
      }
      phase.set(stream.bytes_consumed());
    }
    input.restart_triangles();
  }
  // In increasing order each vertex's parent is already numbered: a root takes the
  // next cluster, any other vertex its parent's (the same part's) cluster.
  for (std::uint64_t v = 0; v < vertices_; ++v) {
    if (parent[v] == v) {
      parent[v] = std::uint32_t(cluster_leaf_.size());
      cluster_leaf_.push_back(leaf_of[v]);
    } else {
      parent[v] = parent[parent[v]];
    }
  }
  labels_ = parent;
  leaf_of_.reset();
}

Vec3d VertexClusters::cell_min_relative(std::uint32_t c) const {
  const std::uint32_t leaf = cluster_leaf_[c];
  if (leaf == kNoLeaf) return Vec3d{};
  const LeafCell& l = leaves_[leaf];
  const double side = side_at(grid_, l.depth);
  return {side * double(l.key & kAxisMask), side * double((l.key >> 21) & kAxisMask),
          side * double((l.key >> 42) & kAxisMask)};
}

double VertexClusters::cell_side(std::uint32_t c) const {
  const std::uint32_t leaf = cluster_leaf_[c];
  return leaf == kNoLeaf ? grid_.cell : side_at(grid_, leaves_[leaf].depth);
}

bool VertexClusters::matches(std::uint32_t c, float k1, float k2) const {
  const std::uint32_t leaf = cluster_leaf_[c];
  if (leaf == kNoLeaf) return false;
  const LeafCell& l = leaves_[leaf];
  const double within = settings_.tolerance / side_at(grid_, l.depth);
  return std::abs(double(k1) - l.k1) <= within && std::abs(double(k2) - l.k2) <= within;
}

}  // namespace oocsimp
