// The curvature estimator behind the facade: read the mesh, check the radius and the
// budget, estimate (curvature/vertex_curvatures.hpp), write the PLY.
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "api/simplify.hpp"
#include "common/vec3_math.hpp"
#include "curvature/vertex_curvatures.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/oocsimp.hpp"
#include "runtime/memory_usage.hpp"

namespace oocsimp {

namespace {

struct LoadedMesh {
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;
};

// Heap bytes the estimate holds per vertex and per triangle: positions, the faces
// around each vertex, k1 and k2, the flat copy and the attribute values for the
// writer, and each thread's marks.
std::uint64_t estimate_bytes(std::uint64_t vertices, std::uint64_t triangles, unsigned threads) {
  const std::uint64_t per_vertex = 24 + 8 + 8 + 24 + 16 + 4 * threads;
  const std::uint64_t per_triangle = 12 + 12 + 4 * threads;
  return vertices * per_vertex + triangles * per_triangle;
}

std::string mib(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f MiB", std::ceil(double(bytes) / 1048576.0));
  return text;
}

void check_budget(const MeshInput& input, const CurvatureOptions& options, unsigned threads) {
  const std::uint64_t budget = options.memory_budget ? options.memory_budget : default_memory_budget();
  const std::uint64_t needed = estimate_bytes(input.info.vertex_count, input.info.face_count, threads);
  if (input.info.vertex_count >= std::uint64_t(1) << 32)
    throw UsageError(input.info.path + ": curvature holds the mesh in memory, and it has 2^32 vertices or more");
  if (needed > budget)
    throw UsageError("options.memory_budget", "options.memory_budget " + mib(budget) + " cannot hold " +
                                                  input.info.path + ": curvature holds the whole mesh in memory, " +
                                                  mib(needed) + " for this one");
}

LoadedMesh load(MeshInput& input) {
  LoadedMesh mesh;
  mesh.positions.resize(input.positions.count);
  for (std::uint64_t i = 0; i < input.positions.count; ++i) mesh.positions[i] = input.positions.get(i);
  mesh.triangles.reserve(3 * input.info.face_count);  // a hint: polygons fan into more
  constexpr std::size_t kChunk = 65536;
  std::vector<std::uint64_t> buffer(3 * kChunk);
  while (const std::size_t n = input.triangles->read(buffer.data(), kChunk))
    for (std::size_t i = 0; i < 3 * n; ++i) mesh.triangles.push_back(std::uint32_t(buffer[i]));
  return mesh;
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

VertexCurvatures estimate(MeshInput& input, const CurvatureOptions& options, std::vector<Vec3d>* positions_out,
                          std::vector<std::uint32_t>* triangles_out) {
  const double start = now_seconds();
  PeakAnonSampler peak_anon;
  std::unique_ptr<tbb::global_control> thread_limit;
  if (options.threads > 0)
    thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, options.threads);
  const unsigned threads = unsigned(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  check_budget(input, options, threads);
  LoadedMesh mesh = load(input);
  VertexCurvatures out;
  CurvatureStats& st = out.stats;
  st.vertices = mesh.positions.size();
  st.triangles = mesh.triangles.size() / 3;
  st.mean_edge_length = mean_edge_length(mesh.positions, mesh.triangles);
  VertexCurvatureSettings settings;
  settings.radius = radius_for(options, input.info.bounds, st.mean_edge_length);
  settings.neighbourhood = options.neighbourhood;
  st.radius = settings.radius;
  if (settings.radius > 0) {
    const VertexCurvatureCounts counts = vertex_curvatures(mesh.positions, mesh.triangles, settings, &out.k1, &out.k2);
    st.invariant = counts.invariant;
    st.fitted = counts.fitted;
    st.none = counts.none;
  } else {  // no edge of any length: nothing to measure
    out.k1.assign(st.vertices, 0);
    out.k2.assign(st.vertices, 0);
    st.none = st.vertices;
  }
  if (positions_out) *positions_out = std::move(mesh.positions);
  if (triangles_out) *triangles_out = std::move(mesh.triangles);
  st.seconds = now_seconds() - start;
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = peak_anon.peak();
  return out;
}

}  // namespace

VertexCurvatures estimate_curvatures(const MeshView& mesh, const CurvatureOptions& options) {
  AttributeSelection none;
  none.mode = AttributeSelection::Mode::none;
  MeshInput input = open_mesh_view(mesh, none);
  return estimate(input, options, nullptr, nullptr);
}

void curvature_file(const std::string& input_path, const std::string& output_path, bool ascii,
                    const CurvatureOptions& options, CurvatureStats* stats) {
  const MeshFormat format = format_for_path(output_path, ascii);
  if (format != MeshFormat::ply_binary && format != MeshFormat::ply_ascii)
    throw UsageError("outputs.mesh", "outputs.mesh " + output_path +
                                         ": curvature writes PLY (k1 and k2 are vertex properties); name a .ply file");
  OpenOptions open;
  open.temp_dir = options.temp_dir;
  open.progress = options.progress;
  open.attributes.mode = AttributeSelection::Mode::none;
  MeshInput input = open_mesh_input(input_path, open);
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;
  VertexCurvatures k = estimate(input, options, &positions, &triangles);
  std::vector<double> flat(3 * positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    flat[3 * v] = positions[v].x;
    flat[3 * v + 1] = positions[v].y;
    flat[3 * v + 2] = positions[v].z;
  }
  std::vector<Vec3d>().swap(positions);
  AttributeValues values;
  values.attributes = {VertexAttribute{"k1", AttributeType::f32, 0, 0},
                       VertexAttribute{"k2", AttributeType::f32, 0, 0}};
  values.values.resize(2 * k.k1.size());
  for (std::size_t v = 0; v < k.k1.size(); ++v) {
    values.values[2 * v] = k.k1[v];
    values.values[2 * v + 1] = k.k2[v];
  }
  write_mesh(output_path, flat, triangles, format, input.info.double_precision ? ScalarType::f64 : ScalarType::f32,
             &values);
  if (stats) *stats = k.stats;
}

}  // namespace oocsimp
