// The simplify entry points: open, choose the grid, cluster, write.
#include "oocsimp/simplify.hpp"

#include <tbb/global_control.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "io/mesh_writer_output.hpp"
#include "io/temp_file.hpp"
#include "methods/cluster_methods.hpp"
#include "methods/multiphase.hpp"
#include "oocsimp/error.hpp"
#include "report/memory_usage.hpp"
#include "report/progress_phase.hpp"

namespace oocsimp {

namespace {

std::unique_ptr<tbb::global_control> limit_threads(unsigned threads) {
  if (threads == 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
}

// The clusterers work, and a float output is written, within the float range: an
// input coordinate beyond it (possible in double input) is rejected up front, naming
// the first such vertex, whatever the output precision.
void check_float_range(const MeshInput& input) {
  const Box3d& b = input.info.bounds;
  constexpr double kMax = std::numeric_limits<float>::max();
  if (b.empty() || (std::max({-b.min.x, -b.min.y, -b.min.z, b.max.x, b.max.y, b.max.z}) <= kMax)) return;
  for (std::uint64_t i = 0; i < input.positions.count; ++i) {
    Vec3d p = input.positions.get(i);
    for (double c : {p.x, p.y, p.z})
      if (std::isfinite(c) && std::abs(c) > kMax) {  // non-finite vertices are skipped, not out of range
        std::ostringstream msg;
        msg << input.info.path << ": vertex " << i << " has the coordinate " << c
            << ", beyond the float range oocsimp works in";
        throw InputError(msg.str());
      }
  }
}

// Rounds the clusterers' double positions to float values for a float output. A
// cluster's output vertex may lie up to a cell beyond the bounding box: for inputs
// near the float limit it can overflow where the input did not.
void round_to_float(const MeshInput& input, SimplifiedMesh& m) {
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    float f = float(m.positions[i]);
    if (std::isinf(f))
      throw InputError(input.info.path + ": output vertex " + std::to_string(i / 3) +
                       " overflows the float range (input coordinates too close to the float limit)");
    m.positions[i] = f;
  }
  m.precision = ScalarType::f32;
}

}  // namespace

std::uint64_t default_memory_budget() {
  long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return std::uint64_t(1) << 30;
  return std::uint64_t(pages) * std::uint64_t(page) / 4;
}

ScalarType output_precision(const MeshInput& input, Precision precision) {
  switch (precision) {
    case Precision::float32:
      return ScalarType::f32;
    case Precision::float64:
      return ScalarType::f64;
    default:
      return input.info.double_precision ? ScalarType::f64 : ScalarType::f32;
  }
}

SimplifiedMesh simplify(MeshInput& input, const SimplifyOptions& options, SimplifyStats* stats) {
  // Below this a run cannot hold its buffers (I/O buffers, one tile's spill
  // buffers, the pipeline's chunks), whatever the input: say so before starting.
  constexpr std::uint64_t kMinimumBudget = 32u << 20;
  if (options.memory_budget != 0 && options.memory_budget < kMinimumBudget)
    throw UsageError("options.memory_budget " + std::to_string(options.memory_budget >> 20) +
                     " MiB is below the minimum of " + std::to_string(kMinimumBudget >> 20) + " MiB");
  // Thick edges come from clustering; a collapse to a target does not make them (yet),
  // and saying so beats dropping them.
  if (options.thick_edges && (options.method == ClusterMethod::qem || options.target.given()))
    throw UsageError("options.thick_edges needs a clustering method without a target (options.method floating or "
                     "uniform; exact targets do not make thick edges yet)");
  auto threads = limit_threads(options.threads);
  const PeakAnonSampler memory;
  check_float_range(input);
  SimplifyStats local;
  SimplifyStats& st = stats ? *stats : local;
  st.input_vertices = input.positions.count;
  st.unwelded_vertices = input.info.unwelded_vertex_count;
  st.non_finite_vertices = input.info.non_finite_vertices;
  st.first_non_finite_vertex = input.info.first_non_finite_vertex;
  st.first_non_finite_position = input.info.first_non_finite_position;
  for (const std::string& note : input.info.not_carried) st.warnings.push_back(note);
  st.attributes = input.attributes.attributes;
  SimplifiedMesh m;
  if (options.method == ClusterMethod::qem || options.target.given()) {
    m = simplify_to_target(input, options, &st);
  } else {
    const GridSpec grid = choose_grid(input, options.sizing, options.threads);
    st.cell_size = grid.cell;
    for (int a = 0; a < 3; ++a) st.grid_dims[a] = grid.dims[a];
    input.restart_triangles();
    m = cluster_method(options.method).run(input, options, grid, &st, nullptr);
  }
  m.precision = ScalarType::f64;
  if (output_precision(input, options.precision) == ScalarType::f32) round_to_float(input, m);
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = memory.peak();
  return m;
}

MeshFormat output_format(const OutputOptions& outputs) {
  // stdout, a device, a FIFO or a socket has no extension to tell the format by (a name
  // like /dev/stdout or x/null): PLY, unless the name has one we can write.
  struct stat st;
  const bool special =
      outputs.mesh == "-" || (::stat(outputs.mesh.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode));
  if (special) {
    try {
      return format_for_path(outputs.mesh, outputs.ascii);
    } catch (const UsageError&) {
      return outputs.ascii ? MeshFormat::ply_ascii : MeshFormat::ply_binary;
    }
  }
  return format_for_path(outputs.mesh, outputs.ascii);
}

namespace {

// Writing over the input (or one output over the other) would lose it: refused before
// any work, naming both.
void check_distinct_destinations(const std::string& input_path, const OutputOptions& outputs) {
  auto refuse = [](const std::string& a, const std::string& b, const std::string& hint) {
    throw UsageError(a + " and " + b + " are the same file" + hint);
  };
  if (!outputs.replace_input && same_file(outputs.mesh, input_path))
    refuse("output " + outputs.mesh, "input " + input_path,
           " (outputs.replace_input replaces the input after a successful run)");
  if (outputs.stats.empty()) return;
  if (same_file(outputs.stats, input_path)) refuse("outputs.stats " + outputs.stats, "input " + input_path, "");
  if (outputs.stats == "-" && outputs.mesh == "-")
    throw UsageError("outputs.mesh - and outputs.stats - cannot both write to stdout");
  if (outputs.stats == outputs.mesh || same_file(outputs.stats, outputs.mesh))
    refuse("outputs.stats " + outputs.stats, "output " + outputs.mesh, "");
}

// The warning for an output format that cannot hold the carried attributes.
std::string attributes_not_written(const std::string& path, MeshFormat format, const AttributeValues& attributes) {
  std::string names;
  for (const VertexAttribute& a : attributes.attributes) {
    if (format == MeshFormat::obj && (a.name == "red" || a.name == "green" || a.name == "blue")) continue;
    names += (names.empty() ? "" : ", ") + a.name;
  }
  const char* what = format == MeshFormat::obj ? "OBJ keeps only the colours red, green and blue"
                                               : "STL and OFF keep no vertex attributes";
  return path + ": " + what + "; " + names + " not written (write .ply to keep every attribute)";
}

}  // namespace

void simplify_file(const std::string& input_path, const OutputOptions& outputs, const SimplifyOptions& options,
                   SimplifyStats* stats) {
  SimplifyStats local;
  SimplifyStats& st = stats ? *stats : local;
  const MeshFormat format = output_format(outputs);
  check_distinct_destinations(input_path, outputs);
  // Every destination is opened before the work: a missing folder fails in a moment,
  // not after the run.
  std::unique_ptr<OutputFile> stats_file;
  if (!outputs.stats.empty()) stats_file = std::make_unique<OutputFile>(outputs.stats);
  OutputFile mesh_file(outputs.mesh);
  auto threads = limit_threads(options.threads);
  const PeakAnonSampler memory;
  double t0 = now_seconds();
  OpenOptions open;
  open.temp_dir = options.temp_dir;
  open.weld = options.weld;
  open.attributes = options.attributes;
  open.memory_budget = options.memory_budget ? options.memory_budget : default_memory_budget();
  open.progress = options.progress;
  MeshInput input = open_mesh_input(input_path, open);
  double t1 = now_seconds();
  st.phases.push_back({"open", t1 - t0});
  SimplifiedMesh mesh = simplify(input, options, &st);
  if (outputs.normals) add_vertex_normals(&mesh);
  double t2 = now_seconds();
  {
    ProgressPhase phase(options.progress, "write", 0, "B");
    if (!format_keeps_attributes(format, mesh.attributes))
      st.warnings.push_back(attributes_not_written(outputs.mesh, format, mesh.attributes));
    if (!mesh.primitives.empty() && !format_keeps_primitives(format))
      st.warnings.push_back(outputs.mesh + ": " +
                            (format == MeshFormat::obj ? std::string("OBJ's l and p lines have no thickness; ") +
                                                             "the thick edges and points are written without it"
                                                       : std::string("STL and OFF have no edges or points; ") +
                                                             std::to_string(mesh.primitives.edge_count()) +
                                                             " thick edges and " +
                                                             std::to_string(mesh.primitives.point_count()) +
                                                             " points not written") +
                            " (write .ply to keep them)");
    write_mesh(mesh_file, mesh.positions, mesh.triangles, format, mesh.precision, &mesh.attributes,
               &mesh.primitives);
  }
  double t3 = now_seconds();
  st.phases.push_back({"write", t3 - t2});
  st.seconds_total = t3 - t0;
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = std::max(st.peak_anon_bytes, memory.peak());
  // The stats first: when they cannot be written, the mesh output stays as it was.
  if (stats_file) {
    stats_file->write_all(stats_to_json(st, input_path, outputs, options));
    stats_file->commit();
  }
  mesh_file.commit();
}

void simplify_file(const std::string& input_path, const std::string& output_path, bool ascii,
                   const SimplifyOptions& options, SimplifyStats* stats) {
  OutputOptions outputs;
  outputs.mesh = output_path;
  outputs.ascii = ascii;
  simplify_file(input_path, outputs, options, stats);
}

}  // namespace oocsimp

namespace oocsimp {

std::string skipped_input_summary(const std::string& input_path, const SimplifyStats& s) {
  if (s.skipped.total() == 0 && s.non_finite_vertices == 0) return "";
  auto count = [](std::uint64_t n, const char* noun, const char* what) {
    std::string plural = std::string(noun) == "vertex" ? "vertices" : std::string(noun) + "s";
    return std::to_string(n) + " " + (n == 1 ? std::string(noun) : plural) + what;
  };
  std::string parts;
  auto add = [&](std::uint64_t n, const char* noun, const char* what) {
    if (n > 0) parts += (parts.empty() ? "" : ", ") + count(n, noun, what);
  };
  add(s.skipped.non_finite, "triangle", " with a NaN or infinite corner");
  // Welded, a vertex is a position: the triangle had two corners there (it may not
  // have named one vertex twice in the file).
  add(s.skipped.repeated_index, "triangle",
      s.unwelded_vertices ? " with two corners at one position" : " naming one vertex twice");
  add(s.skipped.short_faces, "face", " with fewer than 3 corners");
  std::string text = input_path + ": skipped " + count(s.skipped.total(), "face", "");
  if (!parts.empty()) text += " (" + parts + ")";
  if (s.non_finite_vertices > 0)
    text += "; ignored " + count(s.non_finite_vertices, "vertex", "") +
            " with a NaN or infinite coordinate, the first vertex " + std::to_string(s.first_non_finite_vertex) +
            " at " + s.first_non_finite_position;
  return text;
}

std::uint64_t parse_byte_size(const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    throw UsageError("bad size \"" + text + "\" (expected a number with an optional k, M, G or T suffix)");
  }
  std::string suffix = text.substr(used);
  double mult = 1;
  if (suffix == "k" || suffix == "K" || suffix == "KiB")
    mult = 1024.0;
  else if (suffix == "M" || suffix == "MiB")
    mult = 1024.0 * 1024;
  else if (suffix == "G" || suffix == "GiB")
    mult = 1024.0 * 1024 * 1024;
  else if (suffix == "T" || suffix == "TiB")
    mult = 1024.0 * 1024 * 1024 * 1024;
  else if (!suffix.empty())
    throw UsageError("bad size suffix in \"" + text + "\" (k, M, G or T)");
  // 2^64: the first byte count that does not fit
  if (!(v > 0) || !std::isfinite(v) || v * mult < 1 || v * mult >= 18446744073709551616.0)
    throw UsageError("size \"" + text + "\" must be at least 1 byte and below 16 EiB");
  return std::uint64_t(v * mult);
}

}  // namespace oocsimp
