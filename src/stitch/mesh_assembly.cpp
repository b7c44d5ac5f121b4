#include "stitch/mesh_assembly.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <mutex>
#include <utility>

#include "cluster/cluster_accumulation.hpp"
#include "cluster/fixed_point_sums.hpp"
#include "cluster/thick_primitives.hpp"
#include "runtime/memory_budget.hpp"
#include "common/flat_hash_map.hpp"
#include "cluster/quadric.hpp"

namespace oocsimp {

namespace {

// The output alone must fit in --mem (the budget bounds the whole process, output
// included): the spills are done or hold their allowance, so what is left of the
// budget is the output's; when `bytes` more do not fit next to what the process holds,
// the run stops (exit 2) before allocating them.
void check_output_fits(const MemoryBudget& budget, std::uint64_t bytes, const std::string& what) {
  budget.check(budget.held(), bytes, "the output (" + what + ")",
               "the output alone cannot fit: give a larger options.memory_budget or a coarser grid "
               "(options.sizing.grid, options.sizing.ratio)");
}

// The most records one stream of `spill` holds: a bucket read whole.
std::uint64_t largest_bucket(const StreamSpill& spill) {
  std::uint64_t most = 0;
  for (std::uint32_t b = 0; b < spill.stream_count(); ++b) most = std::max(most, spill.record_count(b));
  return most;
}

// The output vertices' numbers by cluster, in order of first numbering: a table with
// a slot per input vertex (a cluster is named by its centre's input index), placed as
// the output's arrays are, so that it needs no heap for a large input.
class ClusterNumbering {
 public:
  ClusterNumbering(std::uint64_t span, const ArrayPlace& place) { slots_.assign_zeroed(span, place, "numbering"); }
  /// The number of `cluster`, given the next one if it has none yet.
  std::uint32_t insert(std::uint64_t cluster) {
    std::uint32_t& slot = slots_[cluster];
    if (slot == 0) {
      if (count_ == std::numeric_limits<std::uint32_t>::max() - 1)
        throw std::length_error("more than 2^32 - 2 output vertices");
      slot = ++count_;
    }
    return slot - 1;
  }
  /// The number of `cluster`, or -1 when it has none.
  std::int64_t find(std::uint64_t cluster) const { return std::int64_t(slots_[cluster]) - 1; }
  std::size_t size() const { return count_; }

 private:
  LargeArray<std::uint32_t> slots_;  // per cluster its number + 1, 0 when unnumbered
  std::uint32_t count_ = 0;
};

// Each used cluster's attribute values from its shares, a cluster bucket at a time;
// `index` numbers the output vertices by centre. The shares of one centre are summed
// in fixed point, so in any order.
void assemble_attributes(StreamSpill& shares, const AttributeLayout& layout, const ClusterNumbering& index,
                         const ArrayPlace& place, OutputMesh* out) {
  const std::size_t width = layout.width(), n = layout.count(), record = 1 + width;
  out->attributes = layout.attributes();
  out->attribute_values.assign_zeroed(n * index.size(), place, "attributes");
  double* values = out->attribute_values.data();
  for (std::uint32_t b = 0; b < shares.stream_count(); ++b) {
    std::vector<std::int64_t> records;
    records.resize(std::size_t(shares.record_count(b)) * record);
    shares.read_into(b, records.data(), records.size() * sizeof(std::int64_t));
    const std::size_t count = records.size() / record;
    std::vector<std::uint32_t> order(count);  // records by centre
    for (std::size_t i = 0; i < count; ++i) order[i] = std::uint32_t(i);
    auto centre = [&](std::size_t i) { return std::uint64_t(records[i * record]); };
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t c) { return centre(a) < centre(c); });
    std::vector<Fixed> sum(width);
    std::vector<double> value(width);
    for (std::size_t i = 0; i < count;) {
      const std::uint64_t c = centre(order[i]);
      std::fill(sum.begin(), sum.end(), Fixed());
      for (; i < count && centre(order[i]) == c; ++i)
        for (std::size_t k = 0; k < width; ++k) sum[k].add(records[order[i] * record + 1 + k]);
      const std::int64_t id = index.find(c);
      if (id < 0) continue;  // a cluster no output triangle uses
      for (std::size_t k = 0; k < width; ++k) value[k] = sum[k].value();
      layout.finish(value.data(), &values[n * std::size_t(id)]);
    }
  }
}

using ClusterPair = std::pair<std::uint64_t, std::uint64_t>;
struct ClusterPairHash {
  std::uint64_t operator()(const ClusterPair& p) const { return p.first * 0x9E3779B97F4A7C15ull ^ p.second; }
};

// The thick edges that survive (Low & Tan 1997 §2 step 5, as select_thick_primitives):
// per bucket of edge shares, each pair's shares summed (fixed point: in any order),
// those no kept triangle has as a side kept with their thickness (edge_thickness, in
// cell units about the second centre, then scaled), sorted by pair. Pairs of one
// cluster (cross-tile triangles collapsed into it) go to `stitched_points`.
std::vector<EdgeCandidate> surviving_edges(const LargeArray<KeptTriangle>& tris, const ThickAssembly& thick,
                                           const FloatingCellShape& cell, const MemoryBudget& budget,
                                           FlatHashSet<std::uint64_t>* stitched_points,
                                           std::vector<ClusterPair>* pairs) {
  check_output_fits(budget,
                    3 * tris.size() * (sizeof(ClusterPair) + 4 * sizeof(std::uint32_t)) +
                        largest_bucket(*thick.edge_shares) * sizeof(EdgeShare),
                    "the sides of " + std::to_string(tris.size()) + " output triangles and a bucket of edges");
  FlatHashSet<ClusterPair, ClusterPairHash> sides(6 * tris.size() + 16);
  for (std::size_t i = 0; i < tris.size(); ++i) {  // t.c ascending
    const KeptTriangle& t = tris[i];
    sides.insert({t.c[0], t.c[1]});
    sides.insert({t.c[0], t.c[2]});
    sides.insert({t.c[1], t.c[2]});
  }
  std::vector<EdgeCandidate> out;
  std::vector<EdgeShare> shares;
  for (std::uint32_t b = 0; b < thick.edge_shares->stream_count(); ++b) {
    thick.edge_shares->read(b, &shares);
    std::sort(shares.begin(), shares.end(),
              [](const EdgeShare& x, const EdgeShare& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    for (std::size_t i = 0; i < shares.size();) {
      EdgeShare sum = shares[i];
      std::size_t j = i + 1;
      for (; j < shares.size() && shares[j].a == sum.a && shares[j].b == sum.b; ++j) {
        sum.in_a.add(shares[j].in_a);
        sum.in_b.add(shares[j].in_b);
      }
      i = j;
      if (sum.point()) {
        stitched_points->insert(sum.a);
        continue;
      }
      if (sides.find({sum.a, sum.b}) >= 0) continue;
      const Vec3d offset = (thick.positions->get(sum.a) - thick.positions->get(sum.b)) * (1.0 / cell.size);
      const double t = edge_thickness(moments_value(sum.in_a), offset, moments_value(sum.in_b), Vec3d{});
      out.push_back({0, 0, float(t * cell.size)});
      pairs->push_back({sum.a, sum.b});
    }
  }
  return out;
}

// A thick point found among the clusters no triangle or edge uses.
struct PointCluster {
  std::uint64_t centre;
  Vec3d position;
  float width;
};

}  // namespace

// Cross-tile triangles: their corners' clusters were written by the tiles owning
// the corners into buckets by triangle index; a bucket fits in memory.
LargeArray<KeptTriangle> stitch_kept_triangles(StreamSpill& inside, StreamSpill& corners, const ArrayPlace& place,
                                               const MemoryBudget& budget, const CrossTileEdges* edges) {
  // At most: every triangle decided in a tile, and one per three stitch corners.
  const std::uint64_t most =
      inside.bytes_appended() / sizeof(KeptTriangle) + corners.bytes_appended() / sizeof(CornerRecord) / 3;
  // The list where it is in the heap, and a stitch bucket's corners with the
  // triangles they join.
  const std::uint64_t bucket = largest_bucket(corners);
  // With thick edges, a bucket's cross-tile triangles over two clusters become edge
  // shares (with their table's slots) before they go to their spill.
  const std::uint64_t edge_shares = edges ? bucket / 3 * (sizeof(EdgeShare) + 4 * sizeof(std::uint32_t) + 16) : 0;
  check_output_fits(budget,
                    place.heap_bytes(most * sizeof(KeptTriangle)) + bucket * sizeof(CornerRecord) +
                        bucket / 3 * sizeof(KeptTriangle) + edge_shares,
                    "up to " + std::to_string(most) + " kept triangles");
  LargeArray<KeptTriangle> kept;
  kept.assign_zeroed(most, place, "kept");
  std::size_t count = 0;
  for (std::uint32_t b = 0; b < inside.stream_count(); ++b) {
    const std::size_t n = inside.record_count(b);
    inside.read_into(b, kept.data() + count, n * sizeof(KeptTriangle));
    count += n;
  }
  stitch_cross_tile_corners(
      corners,
      [&](const KeptTriangle* t, std::size_t n) {
        if (n) std::memcpy(static_cast<void*>(kept.data() + count), t, n * sizeof(KeptTriangle));
        count += n;
      },
      edges);
  kept.resize(count);
  return kept;
}

Vec3d representative(const ClusterRecord& s, const FloatingCellShape& cell, RepresentativeRule rule) {
  const Vec3d& c = s.centre;
  const Vec3d mean = s.mean();  // relative, in cells
  Vec3d x;
  switch (rule) {
    case RepresentativeRule::centre:
    case RepresentativeRule::vertex:  // refused for floating (api/simplify.cpp): the centre is its vertex
      return c;
    case RepresentativeRule::mean:
      x = mean;
      break;
    case RepresentativeRule::quadric: {
      // Kept inside the floating cell: the cube around the centre, then (for a
      // spherical cell) pulled back onto the sphere.
      x = minimize_quadric(s.quadric(), mean, {-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
      if (cell.shape == CellShape::sphere) {
        double r = length(x);
        if (r > 0.5) x = x * 0.5 / r;
      }
      break;
    }
  }
  return c + x * cell.size;
}

Quadric multiphase_quadric(const ClusterRecord& s, const FloatingCellShape& cell, const Vec3d& origin) {
  const Quadric q = s.quadric();
  const double s1 = cell.size, s2 = s1 * s1, s3 = s2 * s1, s4 = s2 * s2;
  const Vec3d t = s.centre - origin;
  const Vec3d at{q.a00 * t.x + q.a01 * t.y + q.a02 * t.z, q.a01 * t.x + q.a11 * t.y + q.a12 * t.z,
                 q.a02 * t.x + q.a12 * t.y + q.a22 * t.z};
  Quadric out;
  out.a00 = s2 * q.a00;
  out.a01 = s2 * q.a01;
  out.a02 = s2 * q.a02;
  out.a11 = s2 * q.a11;
  out.a12 = s2 * q.a12;
  out.a22 = s2 * q.a22;
  out.b0 = s2 * at.x + s3 * q.b0;
  out.b1 = s2 * at.y + s3 * q.b1;
  out.b2 = s2 * at.z + s3 * q.b2;
  out.c = s2 * dot(t, at) + 2 * s3 * (q.b0 * t.x + q.b1 * t.y + q.b2 * t.z) + s4 * q.c;
  return out;
}

namespace {

// The kept triangles once each, in input order of first occurrence, sorted where
// they are.
void order_kept_triangles(LargeArray<KeptTriangle>& tris) {
  tris.resize(dedupe_kept_triangles(tris.data(), tris.data() + tris.size()));
  tbb::parallel_sort(tris.data(), tris.data() + tris.size(), [](const KeptTriangle& a, const KeptTriangle& b) {
    return a.index() < b.index();  // input order of first occurrence
  });
}

// The triangles' corners as output vertices: the clusters in order of first use.
// Checked first: the triangle array, where it goes in the heap.
ClusterNumbering number_triangle_vertices(const LargeArray<KeptTriangle>& tris, const AssemblySettings& settings,
                                          const std::string& output, OutputMesh* mesh) {
  const ArrayPlace& place = settings.place;
  check_output_fits(settings.budget,
                    place.heap_bytes(settings.cluster_span * sizeof(std::uint32_t)) +
                        place.heap_bytes(3 * sizeof(std::uint32_t) * tris.size()),
                    output);
  ClusterNumbering index(settings.cluster_span, place);
  mesh->triangles.assign_zeroed(3 * tris.size(), place, "triangles");
  std::uint32_t* out = mesh->triangles.data();
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (std::uint64_t c : tris[t].corners()) *out++ = index.insert(c);
  return index;
}

// Thick edges (Low & Tan 1997 §3.3): their clusters numbered after the triangles';
// `stitched_points` gets the clusters a triangle collapsed into.
void number_thick_edges(const LargeArray<KeptTriangle>& tris, const ThickAssembly& thick,
                        const AssemblySettings& settings, FlatHashSet<std::uint64_t>* stitched_points,
                        ClusterNumbering* index, ThickPrimitives* p) {
  std::vector<ClusterPair> pairs;
  std::vector<EdgeCandidate> edges =
      surviving_edges(tris, thick, settings.cell, settings.budget, stitched_points, &pairs);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    p->edges.push_back(index->insert(pairs[e].first));
    p->edges.push_back(index->insert(pairs[e].second));
    p->edge_thickness.push_back(edges[e].thickness);
  }
}

// The positions, and the largest cluster bucket with its centre starts, must fit.
void check_positions_fit(const StreamSpill& partials, const AssemblySettings& settings, std::size_t vertices,
                         const std::string& output) {
  const std::uint64_t bucket = largest_bucket(partials);
  const AttributeLayout* const attributes = settings.attributes;
  const std::size_t attribute_count = attributes && settings.attribute_shares ? attributes->count() : 0;
  const std::uint64_t attribute_bucket =
      attribute_count ? largest_bucket(*settings.attribute_shares) * (attribute_record_bytes(*attributes) + 4) : 0;
  const ArrayPlace& place = settings.place;
  check_output_fits(settings.budget,
                    place.heap_bytes(3 * sizeof(double) * vertices) +
                        place.heap_bytes(attribute_count * sizeof(double) * vertices) +
                        bucket * (sizeof(PartialCluster) + sizeof(std::size_t)) + attribute_bucket,
                    output + " and " + std::to_string(vertices) + " vertices");
}

// Where the representatives go: the output's positions (and quadrics) by vertex
// number, and the thick points found among the clusters no triangle or edge uses.
struct Representatives {
  const ClusterNumbering& index;
  const FlatHashSet<std::uint64_t>& stitched_points;
  double* positions;  // 3 per output vertex
  std::vector<Quadric>* quadrics;
  std::vector<PointCluster>* points;
  std::mutex* points_lock;
};

// One cluster bucket: each centre's shares merged (in fixed point, so in any order)
// and solved for, where some triangle uses the cluster or a triangle collapsed into it
// (a thick point). A locked centre's cluster is placed where the centre is. Counts
// into `locked` the clusters of locked centres, and the used ones. Returns the
// clusters the bucket holds.
std::uint64_t place_bucket(std::vector<PartialCluster>& shares, const AssemblySettings& settings,
                           const Representatives& out, std::atomic<std::uint64_t> locked[2]) {
  const FloatingCellShape& cell = settings.cell;
  // Shares of one centre in any order: they are summed in fixed point.
  tbb::parallel_sort(shares.begin(), shares.end(),
                     [](const PartialCluster& a, const PartialCluster& c) { return a.centre < c.centre; });
  std::vector<std::size_t> starts;  // first share of each centre
  for (std::size_t i = 0; i < shares.size(); ++i)
    if (i == 0 || shares[i].centre != shares[i - 1].centre) starts.push_back(i);
  const std::uint64_t clusters = starts.size();
  starts.push_back(shares.size());
  tbb::parallel_for(std::size_t(0), starts.size() - 1, [&](std::size_t k) {
    const std::uint64_t centre = shares[starts[k]].centre;
    const std::int64_t id = out.index.find(centre);
    if (shares[starts[k]].sums.locked) ++locked[0];  // every share of a cluster says so
    if (id < 0 && !settings.thick) return;           // a cluster no output triangle uses
    ClusterRecord sum = shares[starts[k]].sums;
    for (std::size_t i = starts[k] + 1; i < starts[k + 1]; ++i) sum.add(shares[i].sums);
    // No triangle or edge uses it: a thick point when a triangle collapsed into it.
    if (id < 0 && sum.collapsed == 0 && out.stitched_points.find(centre) < 0) return;
    Vec3d p = sum.locked ? sum.centre : representative(sum, cell, settings.rule);
    if (sum.locked) ++locked[1];  // an output vertex, or a thick point
    if (id < 0) {
      const double width =
          point_width(double(sum.members), sum.offset_sum.value(), sum.offset_squares.value()) * cell.size;
      std::lock_guard<std::mutex> hold(*out.points_lock);
      out.points->push_back({centre, p, float(width)});
      return;
    }
    if (out.quadrics) (*out.quadrics)[std::size_t(id)] = multiphase_quadric(sum, cell, settings.origin);
    double* positions = out.positions;
    positions[3 * std::size_t(id)] = p.x;
    positions[3 * std::size_t(id) + 1] = p.y;
    positions[3 * std::size_t(id) + 2] = p.z;
  });
  return clusters;
}

// The thick points in centre order, numbered after everything else.
void append_points(std::vector<PointCluster>& points, ClusterNumbering* index, OutputMesh* mesh) {
  std::sort(points.begin(), points.end(),
            [](const PointCluster& a, const PointCluster& b) { return a.centre < b.centre; });
  std::size_t at = mesh->positions.size();
  mesh->positions.resize(at + 3 * points.size());
  for (const PointCluster& pc : points) {
    mesh->primitives.points.push_back(index->insert(pc.centre));
    mesh->primitives.point_thickness.push_back(pc.width);
    for (double x : {pc.position.x, pc.position.y, pc.position.z}) mesh->positions[at++] = x;
  }
}

}  // namespace

OutputMesh assemble_mesh(LargeArray<KeptTriangle> kept, StreamSpill& partials, const AssemblySettings& settings,
                         AssemblyCounts* counts, std::vector<Quadric>* quadrics) {
  order_kept_triangles(kept);
  const std::string output = std::to_string(kept.size()) + " output triangles";
  OutputMesh mesh;
  ClusterNumbering index = number_triangle_vertices(kept, settings, output, &mesh);
  FlatHashSet<std::uint64_t> stitched_points;
  if (settings.thick) number_thick_edges(kept, *settings.thick, settings, &stitched_points, &index, &mesh.primitives);
  kept.clear();
  check_positions_fit(partials, settings, index.size(), output);
  mesh.positions.assign_zeroed(3 * index.size(), settings.place, "positions");
  if (quadrics) quadrics->assign(index.size(), Quadric());
  // Representatives, a cluster bucket at a time.
  std::vector<PointCluster> points;
  std::mutex points_lock;
  const Representatives out{index, stitched_points, mesh.positions.data(), quadrics, &points, &points_lock};
  std::uint64_t clusters = 0;
  std::atomic<std::uint64_t> locked[2] = {{0}, {0}};  // clusters of locked centres, and the used ones
  for (std::uint32_t b = 0; b < partials.stream_count(); ++b) {
    std::vector<PartialCluster> shares;
    partials.read(b, &shares);
    clusters += place_bucket(shares, settings, out, locked);
  }
  append_points(points, &index, &mesh);
  if (settings.attribute_shares && settings.attributes && !settings.attributes->empty())
    assemble_attributes(*settings.attribute_shares, *settings.attributes, index, settings.place, &mesh);
  if (counts) {
    counts->clusters = clusters;
    counts->locked = locked[0];
    counts->locked_used = locked[1];
  }
  return mesh;
}

}  // namespace oocsimp
