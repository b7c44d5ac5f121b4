// The curvature estimator behind the facade: read the mesh, check the radius and the
// budget, estimate (curvature/vertex_curvatures.hpp), write the PLY.
#include <tbb/global_control.h>

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include "api/simplify.hpp"
#include "common/vec3_math.hpp"
#include "curvature/tiled_curvatures.hpp"
#include "io/byte_sink.hpp"
#include "io/mapped_file.hpp"
#include "io/mesh_input.hpp"
#include "io/mesh_writer_output.hpp"
#include "io/temp_file.hpp"
#include "oocsimp/oocsimp.hpp"
#include "runtime/memory_usage.hpp"

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

// Every vertex's k1 and k2 into k (2 a vertex): in memory when the mesh fits the
// budget (and no tile side is asked), else tile by tile. Both give the same values.
CurvatureStats estimate_into(MeshInput& input, const CurvatureOptions& options, float* k) {
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

// The mesh with k1 and k2 as PLY, streamed: positions from the input, the values from
// k, the faces read again.
void write_curvature_ply(OutputFile& out, MeshInput& input, const float* k, std::uint64_t triangles, bool ascii) {
  ByteSink sink(out.fd(), out.path(), has_zst_suffix(out.path()));
  const std::vector<VertexAttribute> attributes = {VertexAttribute{"k1", AttributeType::f32, 0, 0},
                                                   VertexAttribute{"k2", AttributeType::f32, 0, 0}};
  PlyStreamWriter ply(sink, ascii, input.info.double_precision ? ScalarType::f64 : ScalarType::f32,
                      input.positions.count, triangles, attributes);
  for (std::uint64_t v = 0; v < input.positions.count; ++v) {
    const double values[2] = {k[2 * v], k[2 * v + 1]};
    ply.vertex(input.positions.get(v), values);
  }
  std::vector<std::uint64_t> buffer(3 * kChunkTriangles);
  while (const std::size_t n = input.triangles->read(buffer.data(), kChunkTriangles))
    for (std::size_t t = 0; t < n; ++t) {
      const std::uint32_t corners[3] = {std::uint32_t(buffer[3 * t]), std::uint32_t(buffer[3 * t + 1]),
                                        std::uint32_t(buffer[3 * t + 2])};
      ply.triangle(corners);
    }
  ply.finish();
  sink.finish();
}

// k1 and k2 of every vertex in a temporary file, mapped: out of the heap, for inputs
// larger than memory.
class MappedValues {
 public:
  MappedValues(const std::string& dir, std::uint64_t vertices) : file_(dir, "curvature-values") {
    const std::uint64_t bytes = std::max<std::uint64_t>(8 * vertices, 8);
    if (::ftruncate(file_.fd(), off_t(bytes)) != 0)
      throw IoError(file_.path() + ": cannot make room for the curvature values (" + std::to_string(bytes) +
                    " bytes): " + std::strerror(errno));
    map_ = std::make_unique<MappedFile>(file_.path(), MapAccess::read_write);
  }
  float* data() { return reinterpret_cast<float*>(map_->writable_data()); }

 private:
  TempFile file_;
  std::unique_ptr<MappedFile> map_;
};

}  // namespace

VertexCurvatures estimate_curvatures(const MeshView& mesh, const CurvatureOptions& options) {
  AttributeSelection none;
  none.mode = AttributeSelection::Mode::none;
  MeshInput input = open_mesh_view(mesh, none);
  std::vector<float> k(2 * input.positions.count, 0);
  VertexCurvatures out;
  out.stats = estimate_into(input, options, k.data());
  out.k1.resize(input.positions.count);
  out.k2.resize(input.positions.count);
  for (std::size_t v = 0; v < out.k1.size(); ++v) out.k1[v] = k[2 * v], out.k2[v] = k[2 * v + 1];
  return out;
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
  OutputFile out(output_path);
  MappedValues k(options.temp_dir.empty() ? default_temp_dir() : options.temp_dir, input.positions.count);
  const CurvatureStats st = estimate_into(input, options, k.data());
  write_curvature_ply(out, input, k.data(), st.triangles, format == MeshFormat::ply_ascii);
  out.commit();
  if (stats) *stats = st;
}

}  // namespace oocsimp
