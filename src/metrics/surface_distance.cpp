// Distance between two surfaces: the one-sided and symmetric Hausdorff, mean and RMS
// distances of Theoharis et al. 2008, "Graphics & Visualization: Principles and
// Algorithms", ch. 6 ("Model Representation and Simplification"), section "Polygonal
// Model Simplification (8)", which discretises them "by sampling a number of points on
// both surfaces" — as Metro (Cignoni, Rocchini & Scopigno, 1998) does, but with A
// streamed instead of loaded.
//
// A is the big mesh: its positions stay in the mapping open_mesh_input made, its
// triangles are only ever streamed, in fixed-size chunks through the ordered pipeline
// (io/ordered_pipeline.hpp). B is small and loaded into memory.
//
//  1. Samples. Points are spread uniformly by area with systematic sampling over the
//     cumulative area in file order (metrics/area_sampler.hpp): a first pass over A
//     sums its area, a second places the samples. B is sampled the same way in memory.
//  2. A -> B. B's non-degenerate triangles go into a box tree (metrics/box_tree.hpp);
//     every A sample finds its exact closest point on B (Ericson's closest point on a
//     triangle) by a nearest-first descent. Parallel over the samples.
//  3. B -> A, the direction whose target cannot be held in memory:
//     a. every B sample gets an upper bound u, its distance to the nearest A sample
//        (A samples lie on A), from a box tree over the A samples;
//     b. a box tree over the B samples keeps, per node, the largest u² below it (per
//        leaf, the largest current squared distance, lowered as the samples' are);
//     c. A's triangles are streamed once more; each run of 16 consecutive triangles
//        descends into the nodes its box may be closer to than that bound, then each
//        of its triangles lowers, with an atomic minimum, the squared distance of every
//        B sample in the leaves reached that its box is closer to than the sample's
//        current value. The triangle nearest to a sample is within u of it, so every
//        sample ends with its exact distance to A.
//     Triangle distances are clamped from below by the distance to the triangle's box
//     (common/triangle_geometry.hpp), so skipping a pair whose box distance is not
//     below the current value never discards a smaller computed value: each final
//     value is the minimum over a fixed set of pairs, whatever order the threads
//     visit them in.
//  4. Statistics are summed serially in a fixed order (file order for A's samples,
//     tree order for B's), so the report is byte-identical for any thread count.
//
// Memory: the samples of both sides (24 bytes each plus 8 for a distance), the trees
// over them and B; never A's triangles or vertices (see measure.hpp).
#include "oocsimp/measure.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "runtime/ordered_pipeline.hpp"
#include "metrics/area_sampler.hpp"
#include "metrics/box_tree.hpp"
#include "common/triangle_geometry.hpp"
#include "oocsimp/error.hpp"
#include "io/byte_sink.hpp"
#include "io/mesh_input.hpp"
#include "io/mesh_writer_output.hpp"
#include "io/temp_file.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/progress_phase.hpp"
#include "runtime/thread_limit.hpp"

namespace oocsimp {

using namespace metrics;

namespace {

// Chunks of A's triangle stream. A constant, so that the work does not depend on the
// thread count (the results would not either: see the top of the file).
constexpr std::size_t kChunkTriangles = 1 << 14;
constexpr std::uint32_t kTriangleLeaf = 4;  // exact triangle tests cost several box tests
constexpr std::uint32_t kPointLeaf = 8;
constexpr std::uint32_t kSampleLeaf = 4;               // B samples: their leaves are tested once per triangle
constexpr std::uint64_t kSurfaceA = 1, kSurfaceB = 2;  // separate random sequences per surface
constexpr std::size_t kQueryGrain = 1 << 12;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct TriangleCorners {
  std::uint32_t v[3];
};

// Mesh B, read whole into memory.
struct InMemoryMesh {
  std::vector<Vec3d> positions;
  std::vector<TriangleCorners> triangles;  // file order, degenerate ones included
};

// Sum of distances in a fixed order.
struct DistanceSums {
  std::uint64_t count = 0;
  double max2 = 0, sum = 0, sum2 = 0;

  void add(double distance2) {
    ++count;
    max2 = std::max(max2, distance2);
    sum += std::sqrt(distance2);
    sum2 += distance2;
  }
  void add(const DistanceSums& o) {
    count += o.count;
    max2 = std::max(max2, o.max2);
    sum += o.sum;
    sum2 += o.sum2;
  }
  DistanceStats stats() const {
    DistanceStats s;
    s.samples = count;
    if (count == 0) return s;
    s.max = std::sqrt(max2);
    s.mean = sum / double(count);
    s.rms = std::sqrt(sum2 / double(count));
    return s;
  }
};

DistanceSums sum_in_order(const std::vector<double>& distances2) {
  DistanceSums s;
  for (double d2 : distances2) s.add(d2);
  return s;
}

using Phase = ProgressPhase;

MeshInput open_input(const std::string& path, const MeasureOptions& options, const char* phase_name) {
  OpenOptions open;
  open.temp_dir = options.temp_dir;
  // The reader's "read positions", under the name of the mesh it reads.
  if (options.progress)
    open.progress = [&options, phase_name](Progress p) {
      p.phase = phase_name;
      return options.progress(p);
    };
  return open_mesh_input(path, open);
}

InMemoryMesh load_in_memory(MeshInput& input) {
  if (input.positions.count > std::numeric_limits<std::uint32_t>::max())
    throw UsageError(input.info.path +
                     ": more than 2^32 - 1 vertices; measure loads the second mesh into memory, so pass the "
                     "larger one first");
  InMemoryMesh mesh;
  mesh.triangles.reserve(input.info.face_count);  // a hint: polygons fan into more
  mesh.positions.resize(input.positions.count);
  for (std::uint64_t i = 0; i < input.positions.count; ++i) mesh.positions[i] = input.positions.get(i);
  std::vector<std::uint64_t> buffer(3 * kChunkTriangles);
  while (std::size_t n = input.triangles->read(buffer.data(), kChunkTriangles))
    for (std::size_t t = 0; t < n; ++t)
      mesh.triangles.push_back(
          {{std::uint32_t(buffer[3 * t]), std::uint32_t(buffer[3 * t + 1]), std::uint32_t(buffer[3 * t + 2])}});
  return mesh;
}

// ---------------------------------------------------------------------------------
// Surface B in memory: exact distance queries.

class InMemorySurface {
 public:
  /// Keeps the non-degenerate triangles of `mesh`, in the leaf order of their tree.
  explicit InMemorySurface(InMemoryMesh mesh) : positions_(std::move(mesh.positions)) {
    std::vector<TriangleCorners> kept;
    for (const TriangleCorners& t : mesh.triangles)
      if (triangle_area(corner(t, 0), corner(t, 1), corner(t, 2)) > 0) kept.push_back(t);
    tree_ = std::make_unique<BoxTree>(kept.size(), kTriangleLeaf, [&](std::uint32_t i) {
      return triangle_box(corner(kept[i], 0), corner(kept[i], 1), corner(kept[i], 2));
    });
    triangles_ = permuted(kept, tree_->order());
    tree_->release_order();
  }

  /// Squared distance from p to the closest point of the surface.
  double distance2(const Vec3d& p) const {
    return tree_->nearest(p, kInfinity, [&](std::uint32_t k) {
      const Vec3d &a = corner(triangles_[k], 0), &b = corner(triangles_[k], 1), &c = corner(triangles_[k], 2);
      return point_triangle_distance2(p, a, b, c, triangle_box(a, b, c));
    });
  }

 private:
  const Vec3d& corner(const TriangleCorners& t, int i) const { return positions_[t.v[i]]; }

  std::vector<Vec3d> positions_;
  std::vector<TriangleCorners> triangles_;
  std::unique_ptr<BoxTree> tree_;
};

std::vector<Vec3d> sample_in_memory(const InMemoryMesh& mesh, const MeasureOptions& options, double* total_area) {
  auto corner = [&](const TriangleCorners& t, int i) -> const Vec3d& { return mesh.positions[t.v[i]]; };
  double area = 0;
  for (const TriangleCorners& t : mesh.triangles) area += triangle_area(corner(t, 0), corner(t, 1), corner(t, 2));
  *total_area = area;
  std::vector<Vec3d> samples;
  if (!(area > 0)) return samples;
  samples.reserve(options.samples);
  SystematicAreaSampler sampler(area, options.samples, options.seed, kSurfaceB);
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    const TriangleCorners& t = mesh.triangles[k];
    const Vec3d &a = corner(t, 0), &b = corner(t, 1), &c = corner(t, 2);
    if (std::uint64_t n = sampler.take(triangle_area(a, b, c))) sampler.place(k, a, b, c, n, samples);
  }
  return samples;
}

// ---------------------------------------------------------------------------------
// Surface A, streamed.

struct StreamChunk {
  std::vector<std::uint64_t> corners = std::vector<std::uint64_t>(3 * kChunkTriangles);
  std::vector<double> areas = std::vector<double>(kChunkTriangles);
  std::size_t count = 0;
  std::uint64_t first = 0;                    // index in the stream of the chunk's first triangle
  std::vector<std::uint32_t> reached_leaves;  // scratch of the distance pass

  void corner_positions(const PositionArray& positions, std::size_t t, Vec3d* a, Vec3d* b, Vec3d* c) const {
    *a = positions.get(corners[3 * t]);
    *b = positions.get(corners[3 * t + 1]);
    *c = positions.get(corners[3 * t + 2]);
  }
  void compute_areas(const PositionArray& positions) {
    Vec3d a, b, c;
    for (std::size_t t = 0; t < count; ++t) {
      corner_positions(positions, t, &a, &b, &c);
      areas[t] = triangle_area(a, b, c);
    }
  }
};

// One pass over A's triangles: `work(chunk)` runs in parallel, `merge(chunk)` serially
// in stream order. Returns the number of triangles.
template <class Work, class Merge>
std::uint64_t stream_triangles(MeshInput& input, const ProgressCallback& progress, const char* phase_name,
                               const Work& work, const Merge& merge) {
  input.restart_triangles();
  TriangleStream& stream = *input.triangles;
  Phase phase(progress, phase_name, input.file_size, "B");
  std::uint64_t next = 0;
  std::size_t tokens = 2 * std::size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  run_ordered_pipeline<StreamChunk>(
      tokens,
      [&](StreamChunk& c) {
        c.count = stream.read(c.corners.data(), kChunkTriangles);
        c.first = next;
        next += c.count;
        return c.count > 0;
      },
      work,
      [&](StreamChunk& c) {
        merge(c);
        phase.set(stream.bytes_consumed());
      });
  return next;
}

// Sums A's area in the order the sampler will add it up again.
double streamed_area(MeshInput& input, const ProgressCallback& progress, std::uint64_t* triangles) {
  double area = 0;
  *triangles = stream_triangles(
      input, progress, "area of A", [&](StreamChunk& c) { c.compute_areas(input.positions); },
      [&](StreamChunk& c) {
        for (std::size_t t = 0; t < c.count; ++t) area += c.areas[t];
      });
  return area;
}

std::vector<Vec3d> sample_streamed(MeshInput& input, double area, const MeasureOptions& options) {
  std::vector<Vec3d> samples;
  samples.reserve(options.samples);
  SystematicAreaSampler sampler(area, options.samples, options.seed, kSurfaceA);
  stream_triangles(
      input, options.progress, "sample A", [&](StreamChunk& c) { c.compute_areas(input.positions); },
      [&](StreamChunk& c) {
        Vec3d a, b, c2;
        for (std::size_t t = 0; t < c.count; ++t) {
          if (std::uint64_t n = sampler.take(c.areas[t])) {
            c.corner_positions(input.positions, t, &a, &b, &c2);
            sampler.place(c.first + t, a, b, c2, n, samples);
          }
        }
      });
  return samples;
}

// Squared distance of every point to `surface`, in parallel.
std::vector<double> distances2_to(const InMemorySurface& surface, const std::vector<Vec3d>& points,
                                  const ProgressCallback& progress) {
  std::vector<double> result(points.size());
  Phase phase(progress, "distance A->B", points.size(), "pt");
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), kQueryGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) result[i] = surface.distance2(points[i]);
                      phase.advance(r.size());
                    });
  return result;
}

// For every query point, the squared distance to the nearest of `sites` (step 3a).
std::vector<double> nearest_site_distances2(std::vector<Vec3d> sites, const std::vector<Vec3d>& queries,
                                            const ProgressCallback& progress) {
  // The phase spans the tree's building too, a good part of its time.
  Phase phase(progress, "bound B->A", queries.size(), "pt");
  BoxTree tree(sites.size(), kPointLeaf, [&](std::uint32_t i) {
    Box3d b;
    b.min = b.max = sites[i];
    return b;
  });
  sites = permuted(sites, tree.order());
  tree.release_order();
  std::vector<double> result(queries.size());
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, queries.size(), kQueryGrain), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const Vec3d& q = queries[i];
          result[i] = tree.nearest(q, kInfinity, [&](std::uint32_t k) { return squared_distance(q, sites[k]); });
        }
        phase.advance(r.size());
      });
  return result;
}

// Step 3b-c: the samples of B in a box tree whose nodes carry the largest squared
// upper bound below them; the bounds are lowered, triangle by triangle, as A streams
// past, until each is the exact squared distance to A.
class StreamedDistanceSearch {
 public:
  struct Triangle {
    Vec3d a, b, c;
    Box3d box;
  };

  /// Takes the samples and their squared upper bounds; with `keep_order`,
  /// distances2_in_point_order() can give the distances in the points' own order.
  StreamedDistanceSearch(const std::vector<Vec3d>& points, std::vector<double> bounds2, bool keep_order = false)
      : tree_(points.size(), kSampleLeaf,
              [&](std::uint32_t i) {
                Box3d b;
                b.min = b.max = points[i];
                return b;
              }),
        points_(permuted(points, tree_.order())),
        reach2_(tree_.node_count()),
        best2_(points.size()) {
    bounds2 = permuted(bounds2, tree_.order());
    if (keep_order) order_ = tree_.order();
    tree_.release_order();
    std::vector<double> reach2 = tree_.max_per_node([&](std::uint32_t k) { return bounds2[k]; });
    for (std::size_t i = 0; i < reach2.size(); ++i) reach2_[i].store(reach2[i], std::memory_order_relaxed);
    for (std::size_t k = 0; k < bounds2.size(); ++k) best2_[k].store(bounds2[k], std::memory_order_relaxed);
  }

  /// Lowers the bound of every sample by its distance to each triangle of `chunk`.
  /// Safe to call from several threads at once; `reached_leaves` is the caller's
  /// scratch buffer.
  void lower_by(const StreamChunk& chunk, const PositionArray& positions, std::vector<std::uint32_t>& reached_leaves) {
    // Consecutive triangles of a file are mostly neighbours, and far smaller than the
    // sample spacing: a group of them reaches about the leaves one does, so the tree is
    // descended once per group and each triangle then only tests those leaves. When a
    // group is spread out (a file in no spatial order), its triangles descend alone.
    constexpr std::size_t kGroup = 16;
    constexpr std::size_t kMaxGroupLeaves = 4 * kGroup;
    Triangle group[kGroup];
    for (std::size_t first = 0; first < chunk.count; first += kGroup) {
      std::size_t n = 0;
      Box3d group_box;
      for (std::size_t t = first; t < std::min(chunk.count, first + kGroup); ++t) {
        Triangle& tri = group[n];
        chunk.corner_positions(positions, t, &tri.a, &tri.b, &tri.c);
        if (!(triangle_area(tri.a, tri.b, tri.c) > 0)) continue;  // not part of the surface
        tri.box = triangle_box(tri.a, tri.b, tri.c);
        expand(group_box, tri.box.min);
        expand(group_box, tri.box.max);
        ++n;
      }
      if (n == 0) continue;
      if (collect_leaves(group_box, kMaxGroupLeaves, reached_leaves)) {
        for (std::size_t i = 0; i < n; ++i)
          for (std::uint32_t leaf : reached_leaves)
            if (may_lower(group[i].box, leaf)) lower_leaf(leaf, group[i]);
      } else {
        for (std::size_t i = 0; i < n; ++i) {
          collect_leaves(group[i].box, std::numeric_limits<std::size_t>::max(), reached_leaves);
          for (std::uint32_t leaf : reached_leaves) lower_leaf(leaf, group[i]);
        }
      }
    }
  }

  /// The squared distances, in the tree's leaf order (fixed for given samples); call
  /// when the stream is done.
  std::vector<double> distances2() const {
    std::vector<double> result(best2_.size());
    for (std::size_t k = 0; k < best2_.size(); ++k) result[k] = best2_[k].load(std::memory_order_relaxed);
    return result;
  }

  /// The squared distances with point i's at i (built with keep_order).
  std::vector<double> distances2_in_point_order() const {
    std::vector<double> result(best2_.size());
    for (std::size_t k = 0; k < best2_.size(); ++k) result[order_[k]] = best2_[k].load(std::memory_order_relaxed);
    return result;
  }

 private:
  // Whether anything in `box` can be closer than the bound of some sample below the
  // node. The test at a sample (lower_leaf) is at least as strict, as computed, so
  // skipping a node never skips a sample that the sample test would pass.
  bool may_lower(const Box3d& box, std::size_t node) const {
    return box_box_distance2(box, tree_.node(node).box) < reach2_[node].load(std::memory_order_relaxed);
  }

  // The leaves `box` may lower a bound in, unless there are more than `max_leaves`
  // (then false).
  bool collect_leaves(const Box3d& box, std::size_t max_leaves, std::vector<std::uint32_t>& leaves) const {
    leaves.clear();
    return tree_.for_each_leaf_reached([&](std::size_t node) { return may_lower(box, node); },
                                       [&](std::size_t leaf) {
                                         leaves.push_back(std::uint32_t(leaf));
                                         return leaves.size() <= max_leaves;
                                       });
  }

  void lower_leaf(std::size_t leaf, const Triangle& tri) {
    const BoxTree::Node& node = tree_.node(leaf);
    bool lowered = false;
    for (std::uint32_t k = node.begin; k < node.end; ++k) {
      const Vec3d& p = points_[k];
      double current = best2_[k].load(std::memory_order_relaxed);
      if (point_box_distance2(p, tri.box) >= current) continue;
      double d2 = point_triangle_distance2(p, tri.a, tri.b, tri.c, tri.box);
      while (d2 < current && !best2_[k].compare_exchange_weak(current, d2, std::memory_order_relaxed)) {
      }
      lowered |= d2 < current;
    }
    if (!lowered) return;
    // The bounds only decrease, so a maximum read now bounds them from above from
    // now on, whichever thread's store lands last.
    double reach2 = 0;
    for (std::uint32_t k = node.begin; k < node.end; ++k)
      reach2 = std::max(reach2, best2_[k].load(std::memory_order_relaxed));
    reach2_[leaf].store(reach2, std::memory_order_relaxed);
  }

  BoxTree tree_;
  std::vector<Vec3d> points_;  // leaf order
  // Per node the largest squared bound below it: the initial bounds for inner nodes,
  // the current ones (lowered as the samples' bounds are) for leaves.
  std::vector<std::atomic<double>> reach2_;
  std::vector<std::atomic<double>> best2_;
  std::vector<std::uint32_t> order_;  // the points' leaf order, when kept
};

// Step 3: the exact squared distance to streamed surface A of every point, given
// `bounds2`, squared distances to points on A; in an order fixed by the points.
std::vector<double> distances2_to_streamed(MeshInput& input, std::vector<Vec3d> points, std::vector<double> bounds2,
                                           const ProgressCallback& progress, bool in_point_order = false,
                                           const char* phase_name = "distance B->A") {
  std::optional<Phase> indexing(std::in_place, progress, "index samples of B", 0, "pt");
  StreamedDistanceSearch search(points, std::move(bounds2), in_point_order);
  std::vector<Vec3d>().swap(points);
  indexing.reset();
  stream_triangles(
      input, progress, phase_name, [&](StreamChunk& c) { search.lower_by(c, input.positions, c.reached_leaves); },
      [](StreamChunk&) {});
  return in_point_order ? search.distances2_in_point_order() : search.distances2();
}

// Whether `path` names a PLY file (.ply, or .ply.zst compressed), any case.
bool is_ply_name(const std::string& path) {
  std::string name = path;
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  const auto ends_with = [&](const std::string& e) {
    return name.size() >= e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
  };
  return ends_with(".ply") || ends_with(".ply.zst");
}

// B with each vertex's distance to A as float "quality" and its colour on the ramp
// (0 to the largest of them) as uchar red, green, blue. The header's comments carry
// the ramp's end and A's diagonal, for render's legend.
void write_error_colours(OutputFile& out, const InMemoryMesh& b, const std::vector<double>& distance, double top,
                         double a_diagonal, ScalarType precision, const std::string& a_path) {
  ByteSink sink(out.fd(), out.path(), has_zst_suffix(out.path()));
  const std::vector<VertexAttribute> attributes = {
      VertexAttribute{"quality", AttributeType::f32, 0, 0}, VertexAttribute{"red", AttributeType::u8, 0, 0},
      VertexAttribute{"green", AttributeType::u8, 0, 0}, VertexAttribute{"blue", AttributeType::u8, 0, 0}};
  char ramp[160];
  std::snprintf(ramp, sizeof ramp, "%s %.9g %s %.9g", kErrorRampComment, top, kErrorDiagonalWord, a_diagonal);
  // A comment is one header line.
  std::string a_name = a_path;
  std::replace(a_name.begin(), a_name.end(), '\n', ' ');
  std::replace(a_name.begin(), a_name.end(), '\r', ' ');
  const std::vector<std::string> comments = {"quality: each vertex's distance to the surface of " + a_name, ramp};
  PlyStreamWriter ply(sink, false, precision, b.positions.size(), b.triangles.size(), attributes, 0, 0, comments);
  for (std::size_t v = 0; v < b.positions.size(); ++v) {
    const std::uint32_t c = error_ramp_colour(top > 0 ? distance[v] / top : 0);
    const double values[4] = {distance[v], double(c >> 16), double((c >> 8) & 0xFF), double(c & 0xFF)};
    ply.vertex(b.positions[v], values);
  }
  for (const TriangleCorners& t : b.triangles) ply.triangle(t.v);
  ply.finish();
  sink.finish();
}

}  // namespace

DistanceStats DistanceReport::fraction_of_diagonal(const DistanceStats& stats) const {
  DistanceStats f;
  f.samples = stats.samples;
  if (!(a_diagonal > 0)) return f;
  f.max = stats.max / a_diagonal;
  f.mean = stats.mean / a_diagonal;
  f.rms = stats.rms / a_diagonal;
  return f;
}

DistanceReport measure_surface_distance(const std::string& a_path, const std::string& b_path,
                                        const MeasureOptions& options) {
  if (options.samples == 0 || options.samples > std::numeric_limits<std::uint32_t>::max())
    throw UsageError("options.samples", "options.samples must be between 1 and 2^32 - 1");
  const bool colours = !options.error_colours.empty();
  if (colours && !is_ply_name(options.error_colours))
    throw UsageError("options.error_colours", options.error_colours +
                                                  ": the error colours are written as PLY: give a name ending in "
                                                  ".ply or .ply.zst");
  if (colours && (same_file(options.error_colours, a_path) || same_file(options.error_colours, b_path)))
    throw UsageError("options.error_colours", options.error_colours + ": the error colours would overwrite an input");
  const auto thread_limit = limit_threads(options.threads);
  const PeakAnonSampler memory;
  const double t0 = now_seconds();
  DistanceReport report;
  // Opened first, so that a bad folder fails before the work.
  std::unique_ptr<OutputFile> colour_file = colours ? std::make_unique<OutputFile>(options.error_colours) : nullptr;

  MeshInput a = open_input(a_path, options, "open A");
  report.a_diagonal = a.info.bounds.diagonal();
  InMemoryMesh b_mesh;
  ScalarType b_precision = ScalarType::f32;
  {
    MeshInput b = open_input(b_path, options, "open B");
    b_mesh = load_in_memory(b);
    b_precision = b.info.double_precision ? ScalarType::f64 : ScalarType::f32;
  }
  // B's own copy for the coloured output, which the surface below takes apart.
  InMemoryMesh b_kept;
  if (colours) b_kept = b_mesh;
  report.b_triangles = b_mesh.triangles.size();
  std::vector<Vec3d> b_samples = sample_in_memory(b_mesh, options, &report.b_area);
  if (b_samples.empty()) throw InputError(b_path + ": no triangle with nonzero area to sample");

  report.a_area = streamed_area(a, options.progress, &report.a_triangles);
  if (!(report.a_area > 0)) throw InputError(a_path + ": no triangle with nonzero area to sample");
  std::vector<Vec3d> a_samples = sample_streamed(a, report.a_area, options);

  DistanceSums a_to_b;
  {
    InMemorySurface b_surface(std::move(b_mesh));
    a_to_b = sum_in_order(distances2_to(b_surface, a_samples, options.progress));
  }
  std::vector<Vec3d> a_sites;
  if (colours) a_sites = a_samples;
  std::vector<double> b_bounds2 = nearest_site_distances2(std::move(a_samples), b_samples, options.progress);
  DistanceSums b_to_a =
      sum_in_order(distances2_to_streamed(a, std::move(b_samples), std::move(b_bounds2), options.progress));
  if (colours) {
    // B's vertices are bounded and measured as its samples are; a vertex that is not
    // finite is drawn by no face and gets 0.
    std::vector<Vec3d> vertices = b_kept.positions;
    for (Vec3d& v : vertices)
      if (!is_finite(v)) v = a_sites.front();
    std::vector<double> bounds2 = nearest_site_distances2(std::move(a_sites), vertices, options.progress);
    std::vector<double> d2 = distances2_to_streamed(a, std::move(vertices), std::move(bounds2), options.progress, true,
                                                    "distance of B's vertices");
    DistanceSums sums;
    std::vector<double> distance(d2.size());
    for (std::size_t v = 0; v < d2.size(); ++v) {
      distance[v] = is_finite(b_kept.positions[v]) ? std::sqrt(d2[v]) : 0.0;
      sums.add(distance[v] * distance[v]);
    }
    report.b_vertices = sums.stats();
    write_error_colours(*colour_file, b_kept, distance, report.b_vertices.max, report.a_diagonal, b_precision, a_path);
    colour_file->commit();
  }

  DistanceSums both = a_to_b;
  both.add(b_to_a);
  report.a_to_b = a_to_b.stats();
  report.b_to_a = b_to_a.stats();
  report.symmetric = both.stats();
  report.seconds = now_seconds() - t0;
  report.peak_rss_bytes = peak_rss_bytes();
  report.peak_anon_bytes = memory.peak();
  return report;
}

std::string distance_report_to_json(const DistanceReport& r) {
  auto stats_json = [&](const DistanceStats& s) {
    DistanceStats f = r.fraction_of_diagonal(s);
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "{\"samples\": %llu, \"hausdorff\": %.9g, \"mean\": %.9g, \"rms\": %.9g, "
                  "\"of_diagonal\": {\"hausdorff\": %.9g, \"mean\": %.9g, \"rms\": %.9g}}",
                  (unsigned long long)s.samples, s.max, s.mean, s.rms, f.max, f.mean, f.rms);
    return std::string(buf);
  };
  char head[512];
  std::snprintf(head, sizeof head,
                "{\n"
                "  \"a\": {\"triangles\": %llu, \"area\": %.9g, \"diagonal\": %.9g},\n"
                "  \"b\": {\"triangles\": %llu, \"area\": %.9g},\n",
                (unsigned long long)r.a_triangles, r.a_area, r.a_diagonal, (unsigned long long)r.b_triangles, r.b_area);
  char tail[256];
  std::snprintf(tail, sizeof tail,
                "  \"seconds\": %.6f,\n"
                "  \"memory\": {\"peak_rss_bytes\": %llu, \"peak_anon_bytes\": %llu}\n"
                "}\n",
                r.seconds, (unsigned long long)r.peak_rss_bytes, (unsigned long long)r.peak_anon_bytes);
  return std::string(head) + "  \"a_to_b\": " + stats_json(r.a_to_b) + ",\n  \"b_to_a\": " + stats_json(r.b_to_a) +
         ",\n  \"symmetric\": " + stats_json(r.symmetric) + ",\n" + tail;
}

}  // namespace oocsimp
