// The estimate of a whole mesh: the radius checked, then the values in memory or in
// tiles (curvature/tiled_curvatures.hpp).
#include "curvature/mesh_curvatures.hpp"

#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "common/vec3_math.hpp"
#include "curvature/tiled_curvatures.hpp"
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
  const std::uint64_t per_vertex = 24 + 4 + 1 + 8 + 4 * threads;
  const std::uint64_t per_triangle = 12 + 12 + 4 * threads;
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

CurvatureStats estimate_mesh_curvatures(MeshInput& input, const CurvatureOptions& options, float* k) {
  const double start = now_seconds();
  PeakAnonSampler peak_anon;
  std::unique_ptr<tbb::global_control> thread_limit;
  if (options.threads > 0)
    thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, options.threads);
  const unsigned threads = unsigned(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (input.info.vertex_count >= std::uint64_t(1) << 32)
    throw UsageError(input.info.path + ": curvature names vertices by 32-bit indices, and the mesh has 2^32 or more");
  const MeshSurvey survey = survey_mesh(input);
  CurvatureStats st;
  st.vertices = input.positions.count;
  st.triangles = survey.triangles;
  st.mean_edge_length = survey.mean_edge_length;
  VertexCurvatureSettings settings;
  settings.radius = radius_for(options, input.info.bounds, survey.mean_edge_length);
  settings.neighbourhood = options.neighbourhood;
  st.radius = settings.radius;
  if (!(settings.radius > 0)) {  // no side of any length: nothing to measure
    st.none = st.vertices;
  } else {
    ProgressPhase phase(options.progress, "curvatures", st.vertices, "vtx");
    settings.progress = &phase;
    const std::uint64_t budget = options.memory_budget ? options.memory_budget : default_memory_budget();
    VertexCurvatureCounts counts;
    if (options.tile_side == 0 && in_memory_bytes(st.vertices, st.triangles, threads) <= budget) {
      const std::vector<Vec3d> positions = load_positions(input);
      const std::vector<std::uint32_t> triangles = load_triangles(input, survey.triangles);
      std::vector<float> k1, k2;
      counts = vertex_curvatures(positions, triangles, settings, &k1, &k2);
      for (std::size_t v = 0; v < k1.size(); ++v) k[2 * v] = k1[v], k[2 * v + 1] = k2[v];
    } else {
      TiledCurvatureSettings tiled;
      tiled.vertex = settings;
      tiled.longest_edge = survey.longest_edge;
      tiled.tile_side = options.tile_side;
      tiled.memory_budget = budget;
      tiled.temp_dir = options.temp_dir.empty() ? default_temp_dir() : options.temp_dir;
      const double side = curvature_tile_side(input, tiled, threads);
      counts = tiled_vertex_curvatures(input, tiled, side, k);
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

}  // namespace oocsimp
