// The curvature estimator behind the facade: read the mesh, check the radius and the
// budget, estimate (curvature/mesh_curvatures.hpp), write the PLY.
#include <vector>

#include "api/simplify.hpp"
#include "cluster/cell_moments.hpp"
#include "curvature/mesh_curvatures.hpp"
#include "io/byte_sink.hpp"
#include "io/mesh_input.hpp"
#include "io/mesh_writer_output.hpp"
#include "oocsimp/curvature.hpp"
#include "oocsimp/formats.hpp"
#include "oocsimp/names.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/progress_phase.hpp"
#include "runtime/thread_limit.hpp"

namespace oocsimp {

namespace {

constexpr std::size_t kChunkTriangles = 65536;

// The mesh with k1 and k2 as PLY, streamed: positions from the input, the values from
// k, the faces read again.
void write_curvature_ply(OutputFile& out, MeshInput& input, const float* k, std::uint64_t triangles, bool ascii) {
  ByteSink sink(out.fd(), out.path(), compression_for_path(out.path()));
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

// The estimate options ask for: the integral invariants, or the cell-scale estimate
// at options.at_scale.
CurvatureStats estimate_any(MeshInput& input, const CurvatureOptions& options, float* k) {
  if (options.at_scale == 0) return estimate_mesh_curvatures(input, options, k);
  const double start = now_seconds();
  PeakAnonSampler peak_anon;
  const auto thread_limit = limit_threads(options.threads);
  const MemoryBudget budget(budget_bytes(options.memory_budget), false);
  const ScaleCurvatureCounts c = estimate_at_scale(input, options.at_scale, budget, options.progress, k);
  CurvatureStats st;
  st.vertices = input.positions.count;
  st.triangles = c.triangles;
  st.at_scale = options.at_scale;
  st.invariant = c.interpolated;
  st.none = c.none;
  st.seconds = now_seconds() - start;
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = peak_anon.peak();
  return st;
}

}  // namespace

VertexCurvatures estimate_curvatures(const MeshView& mesh, const CurvatureOptions& options) {
  AttributeSelection none;
  none.mode = AttributeSelection::Mode::none;
  MeshInput input = open_mesh_view(mesh, none);
  std::vector<float> k(2 * input.positions.count, 0);
  VertexCurvatures out;
  out.stats = estimate_any(input, options, k.data());
  out.k1.resize(input.positions.count);
  out.k2.resize(input.positions.count);
  for (std::size_t v = 0; v < out.k1.size(); ++v) out.k1[v] = k[2 * v], out.k2[v] = k[2 * v + 1];
  return out;
}

void curvature_file(const std::string& input_path, const OutputOptions& outputs, const CurvatureOptions& options,
                    CurvatureStats* stats) {
  refuse_simplify_only_outputs(outputs, "curvature_file");
  const std::string& output_path = outputs.mesh;
  const MeshFormat format = format_for_path(output_path, outputs.ascii);
  if (format != MeshFormat::ply_binary && format != MeshFormat::ply_ascii)
    throw UsageError("outputs.mesh", "outputs.mesh " + output_path +
                                         ": curvature writes PLY (k1 and k2 are vertex properties); name a .ply file");
  OpenOptions open;
  open.temp_dir = options.temp_dir;
  open.progress = options.progress;
  open.attributes.mode = AttributeSelection::Mode::none;
  MeshInput input = open_mesh_input(input_path, open);
  OutputFile out(output_path);
  MappedCurvatures k(options.temp_dir.empty() ? default_temp_dir() : options.temp_dir, input.positions.count);
  const CurvatureStats st = estimate_any(input, options, k.data());
  {
    ProgressPhase phase(options.progress, "write", 0, "B");
    write_curvature_ply(out, input, k.data(), st.triangles, format == MeshFormat::ply_ascii);
    out.commit();
  }
  if (stats) *stats = st;
}

void curvature_file(const std::string& input_path, const std::string& output_path, const CurvatureOptions& options,
                    CurvatureStats* stats) {
  OutputOptions outputs;
  outputs.mesh = output_path;
  curvature_file(input_path, outputs, options, stats);
}

}  // namespace oocsimp
