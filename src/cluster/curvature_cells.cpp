// Curvature-adaptive cells (Hua et al. §3.4) and their connected parts; see
// curvature_cells.hpp. What the paper leaves open (the cell's curvature, the
// tolerance, the depth, the parts) is in docs/curvature.md.
#include "cluster/curvature_cells.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "cluster/cell_moments.hpp"
#include "grid/cell_map.hpp"
#include "oocsimp/error.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

constexpr std::uint32_t kNoLeaf = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kUndecided = kNoLeaf - 1;  // an index no mesh reaches
constexpr std::uint64_t kCheckEvery = 1 << 20;     // vertices between budget checks
constexpr std::size_t kTriangleChunk = 65536;

// The cells `depth` splits below the grid's: side grid.cell / 2^depth, exactly (a
// power of two), so a cell's children hold exactly the points it holds.
MomentLattice lattice_at(const GridSpec& grid, std::uint32_t depth) {
  MomentLattice l;
  l.origin = grid.origin;
  l.side = std::ldexp(grid.cell, -int(depth));  // side_at
  for (int a = 0; a < 3; ++a) l.dims[a] = std::uint64_t(grid.dims[a]) << depth;
  return l;
}

constexpr std::uint64_t kAxisMask = MomentLattice::kAxisMask;

// The cell one depth up that holds cell `key`, and where `key`'s corner lies from its.
std::uint64_t parent_key(std::uint64_t key) {
  return ((key & kAxisMask) >> 1) | ((((key >> 21) & kAxisMask) >> 1) << 21) | ((((key >> 42) & kAxisMask) >> 1) << 42);
}
Vec3d offset_in_parent(std::uint64_t key, double side) {
  return {side * double(key & 1), side * double((key >> 21) & 1), side * double((key >> 42) & 1)};
}

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

void VertexClusters::find_leaves(MeshInput& input, const float* k, const MemoryBudget& budget,
                                 const ProgressCallback& progress) {
  const PositionArray& positions = input.positions;
  const std::uint32_t depth_limit = settings_.max_depth;
  const std::uint64_t held = budget.held();
  const std::uint64_t triangles = std::max<std::uint64_t>(input.info.face_count, 1);
  // split[d]: the cells at depth d that split. Depth by depth, one pass over the faces
  // sums the moments of the cells one depth down (the children) where the cell above
  // is undecided; a cell's sums are its children's. A cell splits when the curvature
  // of one of its children, from the child's sums, differs from its own, from its
  // sums, by more than the tolerance over its side (Hua et al. §3.4: "go on
  // subdividing"). A child whose faces give no slope (one face, no area) says nothing.
  std::vector<FlatHashSet<std::uint64_t>> split(depth_limit);
  FlatHashSet<std::uint64_t> undecided;  // at depth d, for d > 0
  std::uint64_t split_bytes = 0;
  const std::string advice = "give more memory, a coarser grid or a smaller options.curvature.max_depth";
  const Box3d& bounds = input.info.bounds;
  OccupancyGrowth occupancy;
  if (depth_limit > 0) occupancy = sampled_occupancy_growth(positions, bounds);
  for (std::uint32_t d = 0; d < depth_limit; ++d) {
    if (d > 0 && undecided.size() == 0) break;
    const MomentLattice child_lattice = lattice_at(grid_, d + 1);
    // Up front, before the pass reads a face: the children its faces will fill (from
    // the vertices' occupancy at their side; below the first depth, at most eight for
    // each undecided cell) in the pass's table and chunks, then beside their parents,
    // with both's estimates.
    std::uint64_t expected = estimated_moment_cells(occupancy, bounds, child_lattice, triangles);
    std::uint64_t parents_expected = estimated_moment_cells(occupancy, bounds, lattice_at(grid_, d), triangles);
    if (d > 0) {
      expected = std::min<std::uint64_t>(expected, 8 * undecided.size());
      parents_expected = std::min<std::uint64_t>(parents_expected, undecided.size());
    }
    parents_expected = std::min(parents_expected, expected);
    // Refused when even the least of it does not fit; the advice holds the most.
    const std::uint64_t after = moment_table_bytes(expected) + moment_table_bytes(parents_expected) +
                                expected * (sizeof(std::uint32_t) + sizeof(PatchCurvature)) +
                                parents_expected * (sizeof(PatchCurvature) + 1);
    const std::uint64_t decided_bytes = split_bytes + undecided.bytes();
    const std::uint64_t least = decided_bytes + std::max(moment_pass_bytes(expected, false), after);
    const std::uint64_t most = decided_bytes + std::max(moment_pass_bytes(expected, true), after);
    budget.check(
        held, least,
        "about " + std::to_string(expected) + " cells of curvature moments at depth " + std::to_string(d + 1) +
            ", estimated",
        "give at least " + whole_mib(held + most) + " MiB, a coarser grid or a smaller options.curvature.max_depth");
    CellMap<PatchMoments> children(1 << 12);
    sum_cell_moments(
        input, child_lattice,
        d == 0 ? MomentFilter() : MomentFilter([&](std::uint64_t key) { return undecided.find(parent_key(key)) >= 0; }),
        &children,
        [&](std::uint64_t bytes, std::uint64_t read) {
          const std::uint64_t more = bytes + split_bytes + undecided.bytes();
          if (budget.fits(held, more)) return;
          // The table grows with the faces read: what the whole pass would take.
          const double whole = double(bytes) * double(triangles) / double(std::max<std::uint64_t>(read, 1));
          budget.check(held, more,
                       std::to_string(children.size()) + " cells of curvature moments at depth " +
                           std::to_string(d + 1) + " after " + std::to_string(read) + " triangles",
                       "give at least " + whole_mib(held + split_bytes + undecided.bytes() + std::uint64_t(whole)) +
                           " MiB, " + advice);
        },
        progress, "curvature moments");
    // Each parent's sums, and its children in a list after it (in the children's order).
    CellMap<PatchMoments> parents(1 << 12);
    std::vector<std::uint32_t> parent_of(children.size());
    for (std::size_t i = 0; i < children.size(); ++i) {
      const std::uint64_t key = children.key(i);
      parent_of[i] = parents.insert(parent_key(key));
      parents.value(parent_of[i]).add(children.value(i), offset_in_parent(key, child_lattice.side));
    }
    budget.check(held, children.bytes() + parents.bytes() + split_bytes + undecided.bytes(),
                 std::to_string(parents.size()) + " curvature cells at depth " + std::to_string(d), advice);
    std::vector<PatchCurvature> own(parents.size()), child(children.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, parents.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i < r.end(); ++i) own[i] = patch_curvature(parents.value(i));
                      });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, children.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i < r.end(); ++i) child[i] = patch_curvature(children.value(i));
                      });
    const double within = settings_.tolerance / lattice_at(grid_, d).side;
    std::vector<std::uint8_t> splits(parents.size(), 0);
    for (std::size_t i = 0; i < children.size(); ++i) {
      const PatchCurvature& k = child[i];
      const PatchCurvature& p = own[parent_of[i]];
      if (k.fit == PatchFit::empty || k.fit == PatchFit::single) continue;
      if (std::abs(k.k1 - p.k1) > within || std::abs(k.k2 - p.k2) > within) splits[parent_of[i]] = 1;
    }
    // The next depth's undecided cells: the children of the cells that split.
    undecided = FlatHashSet<std::uint64_t>(1 << 10);
    for (std::size_t i = 0; i < parents.size(); ++i)
      if (splits[i]) split[d].insert(parents.key(i));
    split_bytes += split[d].bytes();
    for (std::size_t i = 0; i < children.size(); ++i)
      if (splits[parent_of[i]]) undecided.insert(children.key(i));
  }
  // Each vertex to its leaf: down from its grid cell while its cell split. Leaves are
  // numbered by their first vertex.
  leaf_of_ = std::make_unique<MappedScratch>(temp_dir_, "curvature-leaves", 4 * vertices_);
  std::uint32_t* leaf_of = reinterpret_cast<std::uint32_t*>(leaf_of_->data());
  std::vector<CellMap<std::uint32_t>> leaf_cells;
  for (std::uint32_t d = 0; d <= depth_limit; ++d) leaf_cells.emplace_back(1 << 10);
  std::vector<double> sums;  // with `k`: per leaf, the sums of its vertices' k1 and k2 and their count
  std::vector<MomentLattice> lattices;
  for (std::uint32_t d = 0; d <= depth_limit; ++d) lattices.push_back(lattice_at(grid_, d));
  ProgressPhase phase(progress, "curvature cells", positions.count, "vtx");
  for (std::uint64_t v = 0; v < positions.count; ++v) {
    const Vec3d q = positions.get(v);
    if (!is_finite(q)) {
      leaf_of[v] = kNoLeaf;
      continue;
    }
    const Vec3d rel = grid_.relative(q);
    std::uint32_t d = 0;
    std::uint64_t key = lattices[0].key_relative(rel);
    while (d < depth_limit && split[d].find(key) >= 0) key = lattices[++d].key_relative(rel);
    const auto [slot, added] = leaf_cells[d].try_insert(key);
    if (added) {
      leaf_cells[d].value(slot) = std::uint32_t(leaves_.size());
      leaves_.push_back(LeafCell{key, d, 0.f, 0.f});
      if (k) sums.insert(sums.end(), {0.0, 0.0, 0.0});
    }
    const std::uint32_t leaf = leaf_cells[d].value(slot);
    leaf_of[v] = leaf;
    if (k) {
      sums[3 * leaf] += k[2 * v];
      sums[3 * leaf + 1] += k[2 * v + 1];
      sums[3 * leaf + 2] += 1;
    }
    if ((v + 1) % kCheckEvery == 0) {
      std::uint64_t bytes = split_bytes + sums.capacity() * sizeof(double) + leaves_.capacity() * sizeof(LeafCell);
      for (const auto& m : leaf_cells) bytes += m.bytes();
      budget.check(held, bytes, std::to_string(leaves_.size()) + " curvature cells",
                   "give more memory, a coarser grid or a smaller options.curvature.max_depth");
      phase.set(v + 1);
    }
  }
  // With the vertices' own curvatures (RepresentativeRule::vertex), a leaf's are their
  // means, which the vertices are matched against.
  if (k)
    for (std::size_t l = 0; l < leaves_.size(); ++l) {
      leaves_[l].k1 = float(sums[3 * l] / sums[3 * l + 2]);
      leaves_[l].k2 = float(sums[3 * l + 1] / sums[3 * l + 2]);
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
