// The estimate of a whole mesh: the radius checked, then the values in memory or in
// tiles (curvature/tiled_curvatures.hpp).
#include "curvature/mesh_curvatures.hpp"

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "common/vec3_math.hpp"
#include "curvature/tiled_curvatures.hpp"
#include "grid/work_share.hpp"
#include "oocsimp/error.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

constexpr std::size_t kChunkTriangles = 65536;

// Heap bytes the estimate in memory holds per vertex and per triangle: positions,
// the faces around each vertex, the outline flags, k1 and k2, and each thread's marks.
std::uint64_t in_memory_bytes(std::uint64_t vertices, std::uint64_t triangles, unsigned threads) {
  const std::uint64_t per_vertex = 24 + 4 + 1 + 8 + 8 * threads;  // each thread's mark and slot
  const std::uint64_t per_triangle = 12 + 12 + 56 + 4 * threads;  // 56: the face's shape (FaceShape)
  return vertices * per_vertex + triangles * per_triangle;
}

std::vector<Vec3d> load_positions(const MeshInput& input) {
  std::vector<Vec3d> positions(input.positions.count);
  for (std::uint64_t i = 0; i < input.positions.count; ++i) positions[i] = input.positions.get(i);
  return positions;
}

std::vector<std::uint32_t> load_triangles(MeshInput& input, std::uint64_t count) {
  std::vector<std::uint32_t> triangles;
  triangles.reserve(3 * count);
  std::vector<std::uint64_t> buffer(3 * kChunkTriangles);
  while (const std::size_t n = input.triangles->read(buffer.data(), kChunkTriangles))
    for (std::size_t i = 0; i < 3 * n; ++i) triangles.push_back(std::uint32_t(buffer[i]));
  input.restart_triangles();
  return triangles;
}

// The radius asked, or the default; UsageError for one that is not a positive finite
// length no longer than the bounding box's diagonal.
double radius_for(const CurvatureOptions& options, const Box3d& bounds, double mean_edge) {
  const double diagonal = bounds.empty() ? 0 : length(bounds.max - bounds.min);
  if (options.radius == 0) return kDefaultCurvatureRadiusEdges * mean_edge;
  char text[160];
  if (!std::isfinite(options.radius) || !(options.radius > 0)) {
    std::snprintf(text, sizeof text, "options.radius %g: expected a positive finite length", options.radius);
    throw UsageError("options.radius", text);
  }
  if (options.radius > diagonal) {
    std::snprintf(text, sizeof text, "options.radius %g is longer than the mesh's bounding box (diagonal %g)",
                  options.radius, diagonal);
    throw UsageError("options.radius", text);
  }
  return options.radius;
}

}  // namespace

namespace {

// Hands the values of the vertices `which` to `sink`, a bounded run at a time.
void hand_on(const std::vector<std::uint32_t>& which, const std::vector<float>& k1, const std::vector<float>& k2,
             const CurvatureSink& sink) {
  constexpr std::size_t kRun = 65536;
  std::vector<std::uint64_t> vertices;
  for (std::size_t at = 0; at < which.size(); at += kRun) {
    const std::size_t n = std::min(kRun, which.size() - at);
    vertices.assign(which.begin() + std::ptrdiff_t(at), which.begin() + std::ptrdiff_t(at + n));
    sink(vertices.data(), k1.data() + at, k2.data() + at, n);
  }
}

// The estimate of the whole mesh (into `k`) or of the vertices `deal` gives a part
// (to `sink`): the survey and the radius, then the values in memory or in tiles.
CurvatureStats estimate(MeshInput& input, const CurvatureOptions& options, const VertexDeal& deal, float* k,
                        const CurvatureSink& sink) {
  const double start = now_seconds();
  PeakAnonSampler peak_anon;
  std::unique_ptr<tbb::global_control> thread_limit;
  if (options.threads > 0)
    thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, options.threads);
  const unsigned threads = unsigned(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (input.info.vertex_count >= std::uint64_t(1) << 32)
    throw UsageError(input.info.path + ": curvature names vertices by 32-bit indices, and the mesh has 2^32 or more");
  const MeshSurvey survey = survey_mesh(input, options.progress);
  CurvatureStats st;
  st.vertices = input.positions.count;
  st.triangles = survey.triangles;
  st.mean_edge_length = survey.mean_edge_length;
  VertexCurvatureSettings settings;
  settings.radius = radius_for(options, input.info.bounds, survey.mean_edge_length);
  settings.neighbourhood = options.neighbourhood;
  st.radius = settings.radius;
  if (!(settings.radius > 0)) {  // no side of any length: nothing to measure
    st.none = k ? st.vertices : 0;
  } else {
    const std::uint64_t to_estimate = deal.whole() ? st.vertices : deal.owned_vertices();
    const std::uint64_t budget = options.memory_budget ? options.memory_budget : default_memory_budget();
    VertexCurvatureCounts counts;
    if (options.tile_side == 0 && in_memory_bytes(st.vertices, st.triangles, threads) <= budget) {
      ProgressPhase phase(options.progress, "curvatures", to_estimate, "vtx");
      settings.progress = &phase;
      const std::vector<Vec3d> positions = load_positions(input);
      const std::vector<std::uint32_t> triangles = load_triangles(input, survey.triangles);
      std::vector<float> k1, k2;
      if (k) {
        counts = vertex_curvatures(positions, triangles, settings, &k1, &k2);
        for (std::size_t v = 0; v < k1.size(); ++v) k[2 * v] = k1[v], k[2 * v + 1] = k2[v];
      } else {
        std::vector<std::uint32_t> which;
        for (std::size_t v = 0; v < positions.size(); ++v)
          if (deal.owns(positions[v])) which.push_back(std::uint32_t(v));
        counts = vertex_curvatures_of(positions, triangles, settings, which, &k1, &k2);
        hand_on(which, k1, k2, sink);
        counts.none = 0;
      }
    } else {
      TiledCurvatureSettings tiled;
      tiled.vertex = settings;
      tiled.longest_edge = survey.longest_edge;
      tiled.tile_side = options.tile_side;
      tiled.memory_budget = budget;
      tiled.temp_dir = options.temp_dir.empty() ? default_temp_dir() : options.temp_dir;
      tiled.progress = options.progress;
      tiled.estimated_vertices = to_estimate;
      const double side = curvature_tile_side(input, tiled, threads);
      if (k) {
        counts = tiled_vertex_curvatures(input, tiled, side, k);
      } else {
        counts = tiled_vertex_curvatures(
            input, tiled, side, [&deal](const Vec3d& p) { return deal.owns(p); },
            [&sink](const std::vector<std::uint64_t>& vertices, const std::vector<float>& k1,
                    const std::vector<float>& k2) { sink(vertices.data(), k1.data(), k2.data(), vertices.size()); });
        counts.none = 0;
      }
      st.tile_side = side;
    }
    st.invariant = counts.invariant;
    st.fitted = counts.fitted;
    st.none = counts.none;
  }
  st.seconds = now_seconds() - start;
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = peak_anon.peak();
  return st;
}

}  // namespace

CurvatureStats estimate_mesh_curvatures(MeshInput& input, const CurvatureOptions& options, float* k) {
  return estimate(input, options, VertexDeal(), k, nullptr);
}

CurvatureStats estimate_dealt_curvatures(MeshInput& input, const CurvatureOptions& options, const VertexDeal& deal,
                                         const CurvatureSink& sink) {
  return estimate(input, options, deal, nullptr, sink);
}

VertexDeal::VertexDeal(const PositionArray& positions, const Box3d& bounds, std::uint32_t part, std::uint32_t parts) {
  if (parts <= 1 || bounds.empty()) return;  // every vertex
  origin_ = bounds.min;
  const Vec3d extent = bounds.max - bounds.min;
  fine_side_ = std::max({extent.x, extent.y, extent.z}) / (kDivisions * kSplit);
  if (!(fine_side_ > 0) || !std::isfinite(fine_side_)) fine_side_ = 1;
  constexpr std::size_t kBlocks = std::size_t(kDivisions) * kDivisions * kDivisions;
  constexpr std::size_t kSubBlocks = std::size_t(kSplit) * kSplit * kSplit;
  std::vector<std::uint64_t> counts(kBlocks, 0);
  std::size_t block = 0, sub = 0;
  std::uint64_t total = 0;
  for (std::uint64_t v = 0; v < positions.count; ++v) {
    const Vec3d p = positions.get(v);
    if (!is_finite(p)) continue;
    place(p, &block, &sub);
    ++counts[block];
    ++total;
  }
  // A block above a sixteenth of a part's share is cut into sub-blocks, so that the
  // deal can balance a mesh that fills few blocks (a far outlier widens the box).
  const std::uint64_t heavy = std::max<std::uint64_t>(1, total / (16 * std::uint64_t(parts)));
  split_at_.assign(kBlocks, -1);
  std::int64_t splits = 0;
  for (std::size_t b = 0; b < kBlocks; ++b)
    if (counts[b] > heavy) split_at_[b] = std::int64_t(kSubBlocks) * splits++;
  std::vector<std::uint64_t> sub_counts(kSubBlocks * std::size_t(splits), 0);
  if (splits > 0)
    for (std::uint64_t v = 0; v < positions.count; ++v) {
      const Vec3d p = positions.get(v);
      if (!is_finite(p)) continue;
      place(p, &block, &sub);
      if (split_at_[block] >= 0) ++sub_counts[std::size_t(split_at_[block]) + sub];
    }
  // The items dealt: the blocks not cut that hold a vertex, then the sub-blocks that
  // do (an item is a block below kBlocks, else kBlocks plus its place in sub_counts).
  std::vector<std::size_t> items;
  std::vector<std::uint64_t> weights;
  for (std::size_t b = 0; b < kBlocks; ++b)
    if (split_at_[b] < 0 && counts[b] > 0) {
      items.push_back(b);
      weights.push_back(counts[b]);
    }
  for (std::size_t i = 0; i < sub_counts.size(); ++i)
    if (sub_counts[i] > 0) {
      items.push_back(kBlocks + i);
      weights.push_back(sub_counts[i]);
    }
  const std::vector<std::uint32_t> owner = deal_by_weight(weights, parts);
  owned_.assign(kBlocks, 0);
  sub_owned_.assign(sub_counts.size(), 0);
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (owner[i] != part) continue;
    if (items[i] < kBlocks)
      owned_[items[i]] = 1;
    else
      sub_owned_[items[i] - kBlocks] = 1;
    owned_vertices_ += weights[i];
  }
}

void VertexDeal::place(const Vec3d& p, std::size_t* block, std::size_t* sub) const {
  const double last = double(kDivisions * kSplit - 1);
  const auto fine = [this, last](double x, double lo) {
    return std::size_t(std::clamp(std::floor((x - lo) / fine_side_), 0.0, last));
  };
  const std::size_t x = fine(p.x, origin_.x), y = fine(p.y, origin_.y), z = fine(p.z, origin_.z);
  *block = ((z / kSplit) * kDivisions + y / kSplit) * kDivisions + x / kSplit;
  *sub = ((z % kSplit) * kSplit + y % kSplit) * kSplit + x % kSplit;
}

bool VertexDeal::owns(const Vec3d& p) const {
  if (!is_finite(p)) return false;
  if (owned_.empty()) return true;
  std::size_t block = 0, sub = 0;
  place(p, &block, &sub);
  const std::int64_t at = split_at_[block];
  return at < 0 ? owned_[block] != 0 : sub_owned_[std::size_t(at) + sub] != 0;
}

}  // namespace oocsimp
