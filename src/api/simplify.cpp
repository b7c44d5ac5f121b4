// The simplify entry points: open, choose the grid, cluster, write.
#include "api/simplify.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "common/vec3_math.hpp"
#include "io/attribute_array.hpp"
#include "io/byte_sink.hpp"
#include "io/error_text.hpp"
#include "io/mesh_writer_output.hpp"
#include "io/temp_file.hpp"
#include "methods/cluster_methods.hpp"
#include "methods/multiphase.hpp"
#include "methods/uniform_clusterer.hpp"
#include "parts/distributed_run.hpp"
#include "oocsimp/error.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/thread_limit.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

// Rounds the clusterers' double positions to float values for a float output. A
// cluster's output vertex may lie up to a cell beyond the bounding box: for inputs
// near the float limit it can overflow where the input did not.
void round_to_float(const MeshInput& input, OutputMesh& m) {
  double* positions = m.positions.data();
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    float f = float(positions[i]);
    if (std::isinf(f))
      throw InputError(input.info.path + ": output vertex " + std::to_string(i / 3) +
                       " overflows the float range (input coordinates too close to the float limit)");
    positions[i] = f;
  }
  m.precision = ScalarType::f32;
}

}  // namespace

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

namespace {

// What every run records before its work: the input's counts and notes.
SimplifyStats begin_run(const MeshInput& input) {
  SimplifyStats st;
  st.input_vertices = input.positions.count;
  st.unwelded_vertices = input.info.unwelded_vertex_count;
  st.non_finite_vertices = input.info.non_finite_vertices;
  st.first_non_finite_vertex = input.info.first_non_finite_vertex;
  st.first_non_finite_position = input.info.first_non_finite_position;
  for (const std::string& note : input.info.not_carried) st.warnings.push_back(note);
  st.attributes = input.attributes.attributes;
  return st;
}

// A warning when the process's peak anonymous memory went past a budget that bounds
// the whole process: the plans that keep a run within it are estimates, and a run
// that overran says so rather than passing for one that fits. Phase by phase where
// the run has phases.
void warn_of_overrun(const RunPlan& plan, SimplifyStats& st) {
  if (!OOCSIMP_MEASURED_MEMORY_MEANINGFUL || !plan.budget_counts_process) return;
  const std::uint64_t budget = plan.budget_bytes;
  std::string over;
  auto note = [&](const char* what, std::uint64_t peak) {
    if (peak <= budget) return;
    over += std::string(over.empty() ? "" : ", ") + what + " " + mib_text(peak);
  };
  if (st.refine.phase1_peak_anon_bytes || st.refine.phase2_peak_anon_bytes) {
    note(st.refine.passes ? "phase 1 (out-of-core passes)" : "phase 1 (clustering)", st.refine.phase1_peak_anon_bytes);
    note("phase 2 (collapse)", st.refine.phase2_peak_anon_bytes);
  }
  if (over.empty()) note("the run", st.peak_anon_bytes);
  if (!over.empty())
    st.warnings.push_back("the peak anonymous memory went past options.memory_budget " + whole_mib(budget) +
                          " MiB: " + over);
}

// A run whose output is not smaller than its input says so, naming the option that
// would make it smaller: a run that removes nothing looks like one that worked. A
// target at or above the input's count has its own warning (input_as_is).
void warn_if_nothing_removed(const RunPlan& plan, std::uint64_t output_triangles, SimplifyStats& st) {
  if (st.input_triangles == 0 || output_triangles < st.input_triangles) return;
  const TargetOptions& t = plan.target;
  if (t.triangles != 0 || t.ratio != 0) return;
  const CellSizing& s = plan.sizing;
  std::ostringstream advice;
  if (t.max_error != 0)
    advice << "a larger options.target.max_error (now " << t.max_error << ")";
  else if (s.cell != 0)
    advice << "a larger options.sizing.cell (now " << s.cell << ")";
  else if (s.grid != 0)
    advice << "a smaller options.sizing.grid (now " << s.grid << ")";
  else
    advice << "a smaller options.sizing.ratio (now " << (s.ratio != 0 ? s.ratio : kDefaultRatio)
           << "), or options.target.triangles for an exact count";
  st.warnings.push_back("the output has " + std::to_string(output_triangles) +
                        " triangles, not fewer than the input's " + std::to_string(st.input_triangles) +
                        ": nothing was removed; " + advice.str() + " would remove some");
}

// The output's precision and the run's peak memory.
void finish_run(const MeshInput& input, const RunPlan& plan, const PeakAnonSampler& memory, OutputMesh& m,
                SimplifyStats& st) {
  warn_if_nothing_removed(plan, m.triangle_count(), st);
  m.precision = ScalarType::f64;
  if (output_precision(input, plan.precision) == ScalarType::f32) round_to_float(input, m);
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = std::max(st.peak_anon_bytes, memory.peak());
  warn_of_overrun(plan, st);
}

void record_grid(const GridSpec& grid, SimplifyStats* st) {
  st->cell_size = grid.cell;
  for (int a = 0; a < 3; ++a) st->grid_dims[a] = grid.dims[a];
}

}  // namespace

namespace {

// begin_run's stats into `st`, after the caller's phases so far (simplify_file's
// "open") and warnings, which stay first.
void begin_stats(const MeshInput& input, SimplifyStats* st) {
  const SimplifyStats begun = begin_run(input);
  std::vector<PhaseTime> phases = std::move(st->phases);
  std::vector<std::string> warnings = std::move(st->warnings);
  *st = begun;
  st->phases = std::move(phases);
  warnings.insert(warnings.end(), st->warnings.begin(), st->warnings.end());
  st->warnings = std::move(warnings);
}

// simplify(), with the output's arrays where the clusterers put them (mapped files
// for an output large next to the budget).
OutputMesh simplify_output(MeshInput& input, const RunPlan& plan, SimplifyStats* stats,
                           std::vector<Quadric>* quadrics = nullptr, std::vector<CoarserLevel>* coarser = nullptr) {
  auto threads = limit_threads(plan.threads);
  const PeakAnonSampler memory;
  const double t0 = now_seconds();
  SimplifyStats local;
  SimplifyStats& st = stats ? *stats : local;
  begin_stats(input, &st);
  OutputMesh m;
  if (plan.target.given()) {
    m = OutputMesh::of(simplify_to_target(input, plan, &st, quadrics, coarser));
  } else {
    const GridSpec grid = choose_grid(input, plan.sizing, plan.threads);
    record_grid(grid, &st);
    input.restart_triangles();
    m = cluster_method(plan.method).run(input, plan, grid, &st, nullptr);
  }
  finish_run(input, plan, memory, m, st);
  // The simplification's time; a run from a file counts its opening and writing too.
  st.seconds_total = now_seconds() - t0;
  return m;
}

}  // namespace

SimplifiedMesh simplify(MeshInput& input, const SimplifyOptions& options, SimplifyStats* stats,
                        std::vector<Quadric>* quadrics) {
  if (quadrics) quadrics->clear();
  return simplify_output(input, plan_run(input, options), stats, quadrics).take();
}

namespace {

void check_lods(const SimplifyOptions& options, const LodOptions& lods) {
  if (lods.levels < 1 || lods.levels > 16)
    throw UsageError("options.lods.levels", "options.lods.levels must be 1 to 16");
  if (!(lods.factor > 1) || !std::isfinite(lods.factor))
    throw UsageError("options.lods.factor", "options.lods.factor must be a number above 1");
  if (options.method == ClusterMethod::qem && !options.target.given())
    throw UsageError("options.lods",
                     "options.lods with options.method qem needs a target to halve per level "
                     "(options.target.triangles or options.target.ratio)");
  if (options.target.triangles != 0 && (options.target.triangles >> (lods.levels - 1)) < 4)
    throw UsageError("options.lods",
                     "options.lods halves options.target.triangles per level: " + std::to_string(lods.levels) +
                         " levels need a target of at least " + std::to_string(std::uint64_t(4) << (lods.levels - 1)));
  if (options.target.max_error > 0 || options.target.max_error_of_diagonal > 0)
    throw UsageError("options.lods",
                     "options.lods halves a triangle target per level; it does not take options.target.max_error");
}

// sqrt(2 A / T) for the output's area A and triangle count T (SimplifyStats::lod_cell).
double equivalent_cell(const OutputMesh& m) {
  double area = 0;
  auto at = [&](std::uint32_t v) {
    return Vec3d{m.positions[3 * std::size_t(v)], m.positions[3 * std::size_t(v) + 1],
                 m.positions[3 * std::size_t(v) + 2]};
  };
  for (std::size_t t = 0; t + 2 < m.triangles.size(); t += 3) {
    const Vec3d a = at(m.triangles[t]);
    area += 0.5 * length(cross(at(m.triangles[t + 1]) - a, at(m.triangles[t + 2]) - a));
  }
  const double triangles = double(m.triangles.size() / 3);
  return triangles > 0 ? std::sqrt(2 * area / triangles) : 0;
}

// Where simplify_lods_output hands each level.
using OutputSink = std::function<void(std::uint32_t level, OutputMesh& mesh, const SimplifyStats& stats)>;

// simplify_lods(), with the levels' arrays where the clusterers put them.
void simplify_lods_output(MeshInput& input, const SimplifyOptions& given, const LodOptions& lods,
                          const OutputSink& sink) {
  check_lods(given, lods);
  auto threads = limit_threads(given.threads);
  if (given.target.given()) {
    // Level k aims at the target halved k times. The edge collapse that meets level
    // 0's target goes on to the coarser ones; a run that ends in no collapse (the
    // input given back, a clustering without refine) leaves them to runs of their own.
    std::vector<RunPlan> at;
    std::vector<CoarserLevel> coarser(lods.levels - 1);
    for (std::uint32_t k = 0; k < lods.levels; ++k) {
      SimplifyOptions level = given;
      level.target.triangles >>= k;
      level.target.ratio = std::ldexp(given.target.ratio, -int(k));
      at.push_back(plan_run(input, level));
      if (k > 0) coarser[k - 1].target = at[k].target;
    }
    SimplifyStats first;
    OutputMesh m = simplify_output(input, at[0], &first, nullptr, &coarser);
    for (CoarserLevel& level : coarser)
      if (level.done) {
        for (const PhaseTime& phase : level.stats.phases) level.stats.seconds_total += phase.seconds;
        first.seconds_total -= level.stats.seconds_total;  // level 0's own time
      }
    first.lod_cell = equivalent_cell(m);
    sink(0, m, first);
    for (std::uint32_t k = 1; k < lods.levels; ++k) {
      CoarserLevel& level = coarser[k - 1];
      SimplifyStats st;
      if (level.done) {
        const PeakAnonSampler memory;
        m = OutputMesh::of(std::move(level.mesh));
        st = std::move(level.stats);
        finish_run(input, at[k], memory, m, st);
        st.peak_rss_bytes = first.peak_rss_bytes;  // reached within level 0's run
        st.peak_anon_bytes = first.peak_anon_bytes;
      } else {
        input.restart_triangles();
        m = simplify_output(input, at[k], &st);
      }
      st.lod_cell = equivalent_cell(m);
      sink(k, m, st);
    }
    return;
  }
  const RunPlan plan = plan_run(input, given);
  const SimplifyStats base = begin_run(input);
  const GridSpec first = choose_grid(input, plan.sizing, plan.threads);
  std::vector<GridSpec> grids = {first};
  for (std::uint32_t k = 1; k < lods.levels; ++k)
    grids.push_back(GridSpec::with_cell(input.info.bounds, first.cell * std::pow(lods.factor, double(k))));
  const ClusterMethodEntry& method = cluster_method(plan.method);
  if (method.levels) {  // the work that does not depend on the grid, once
    const PeakAnonSampler memory;
    input.restart_triangles();
    method.levels(
        input, plan, grids,
        [&](std::size_t k, OutputMesh& m, SimplifyStats& st) {
          record_grid(grids[k], &st);
          st.lod_cell = grids[k].cell;
          finish_run(input, plan, memory, m, st);
          sink(std::uint32_t(k), m, st);
        },
        base, nullptr);
    return;
  }
  for (std::uint32_t k = 0; k < lods.levels; ++k) {
    const PeakAnonSampler memory;
    SimplifyStats st = base;
    record_grid(grids[k], &st);
    st.lod_cell = grids[k].cell;
    input.restart_triangles();
    OutputMesh m = method.run(input, plan, grids[k], &st, nullptr);
    finish_run(input, plan, memory, m, st);
    sink(k, m, st);
  }
}

}  // namespace

void simplify_lods(MeshInput& input, const SimplifyOptions& options, const LodOptions& lods, const LodSink& sink) {
  simplify_lods_output(input, options, lods, [&](std::uint32_t k, OutputMesh& m, const SimplifyStats& st) {
    SimplifiedMesh mesh = m.take();
    sink(k, mesh, st);
  });
}

namespace {

// "out.ply" -> ("out", ".ply"); "a/b.obj.zst" -> ("a/b", ".obj.zst"), and so with .gz; no
// extension: ("x", "").
std::pair<std::string, std::string> split_extension(const std::string& path) {
  const std::string p = without_compression_suffix(path);
  const std::string compressed = path.substr(p.size());
  const std::size_t slash = p.rfind('/'), dot = p.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash) || dot == 0 ||
      (slash != std::string::npos && dot == slash + 1))
    return {p, compressed};
  return {p.substr(0, dot), p.substr(dot) + compressed};
}

}  // namespace

std::string lod_level_path(const std::string& mesh_path, std::uint32_t level) {
  const auto [stem, ext] = split_extension(mesh_path);
  return stem + ".lod" + std::to_string(level) + ext;
}

std::string lod_description_path(const std::string& mesh_path) {
  return split_extension(mesh_path).first + ".lods.json";
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

void refuse_simplify_only_outputs(const OutputOptions& outputs, const char* function) {
  const auto refuse = [&](const char* field) {
    throw UsageError(std::string("outputs.") + field,
                     std::string("outputs.") + field + " is simplify_file's; " + function + " writes the mesh alone");
  };
  if (!outputs.stats.empty()) refuse("stats");
  if (outputs.normals) refuse("normals");
  if (outputs.replace_input) refuse("replace_input");
}

namespace {

// Writing over the input (or one output over the other) would lose it: refused before
// any work, naming both.
void check_distinct_destinations(const std::string& input_path, const OutputOptions& outputs) {
  auto refuse = [](const std::string& option, const std::string& a, const std::string& b, const std::string& hint) {
    throw UsageError(option, a + " and " + b + " are the same file" + hint);
  };
  if (!outputs.replace_input && same_file(outputs.mesh, input_path))
    refuse("", "output " + outputs.mesh, "input " + input_path,
           " (outputs.replace_input replaces the input after a successful run)");
  if (outputs.stats.empty()) return;
  if (same_file(outputs.stats, input_path))
    refuse("outputs.stats", "outputs.stats " + outputs.stats, "input " + input_path, "");
  if (outputs.stats == "-" && outputs.mesh == "-")
    throw UsageError("outputs.mesh", "outputs.mesh - and outputs.stats - cannot both write to stdout");
  if (outputs.stats == outputs.mesh || same_file(outputs.stats, outputs.mesh))
    refuse("outputs.stats", "outputs.stats " + outputs.stats, "output " + outputs.mesh, "");
}

// The warning for an output format that cannot hold the carried attributes: which of
// them it drops.
std::string attributes_not_written(const std::string& path, MeshFormat format,
                                   const std::vector<VertexAttribute>& attributes) {
  const auto is = [](const VertexAttribute& a, std::initializer_list<const char*> names) {
    for (const char* n : names)
      if (a.name == n) return true;
    return false;
  };
  std::string names;
  for (const VertexAttribute& a : attributes) {
    if ((format == MeshFormat::obj || format == MeshFormat::glb) &&
        (is(a, {"red", "green", "blue", "nx", "ny", "nz"}) || is_texture_coordinate(a.name)))
      continue;
    if (format == MeshFormat::glb && a.name == "alpha") continue;
    if ((format == MeshFormat::obj || format == MeshFormat::glb) && is_material_attribute(a.name))
      continue;  // usemtl groups, glTF primitives
    names += (names.empty() ? "" : ", ") + a.name;
  }
  const char* what =
      format == MeshFormat::obj   ? "OBJ keeps only the colours red, green, blue, the normals and texture coordinates"
      : format == MeshFormat::glb ? "glTF keeps only the colours (with alpha), the normals and texture coordinates"
                                  : "STL and OFF keep no vertex attributes";
  return path + ": " + what + "; " + names + " not written (write .ply to keep every attribute)";
}

// The warning for an output format that has no materials: OBJ's mtllib and usemtl,
// glTF's materials of primitives.
std::string materials_not_written(const std::string& path, MeshFormat format, const Materials& materials) {
  std::string what;
  if (!materials.libraries.empty()) what = "the material library (mtllib " + materials.libraries.front() + ")";
  if (!materials.names.empty())
    what += std::string(what.empty() ? "" : " and ") + "the faces' " + std::to_string(materials.names.size()) +
            " materials (usemtl)";
  const bool ply = format == MeshFormat::ply_binary || format == MeshFormat::ply_ascii;
  return path + ": only OBJ and glTF have materials; " + what +
         (ply && !materials.names.empty() ? " kept only as the vertex properties material_0..." : " not written") +
         " (write .obj or .glb to keep them)";
}

// Opens the input as `options` say (welding, attributes, budget, progress).
MeshInput open_input(const std::string& input_path, const SimplifyOptions& options) {
  OpenOptions open;
  open.temp_dir = options.temp_dir;
  open.weld = options.weld;
  open.attributes = options.attributes;
  open.attributes.texture_coordinates = resolved_method(options) == ClusterMethod::qem;
  open.memory_budget = budget_bytes(options.memory_budget);
  open.progress = options.progress;
  return open_mesh_input(input_path, open);
}

// Writes `mesh` (normals added when asked) to `file`, with a warning in `st` for what
// the format cannot keep, and records the "write" phase.
void write_output(OutputFile& file, MeshFormat format, const OutputOptions& outputs, OutputMesh& mesh,
                  const RunPlan& plan, SimplifyStats& st) {
  if (outputs.normals) add_vertex_normals(&mesh, ArrayPlace::within(plan.budget_bytes, plan.temp_dir));
  const double t0 = now_seconds();
  ProgressPhase phase(plan.progress, "write", 0, "B");
  if (!format_keeps_attributes(format, AttributeValues{mesh.attributes, {}, mesh.materials}))
    st.warnings.push_back(attributes_not_written(file.path(), format, mesh.attributes));
  if (!mesh.materials.empty() && !format_keeps_materials(format))
    st.warnings.push_back(materials_not_written(file.path(), format, mesh.materials));
  if (!mesh.primitives.empty() && !format_keeps_primitives(format))
    st.warnings.push_back(file.path() + ": " +
                          (format == MeshFormat::obj
                               ? std::string("OBJ's l and p lines have no thickness; ") +
                                     "the thick edges and points are written without it"
                               : std::string("STL, OFF and the glTF written have no edges or points; ") +
                                     std::to_string(mesh.primitives.edge_count()) + " thick edges and " +
                                     std::to_string(mesh.primitives.point_count()) + " points not written") +
                          " (write .ply to keep them)");
  write_mesh(file, mesh, format);
  st.phases.push_back({"write", now_seconds() - t0});
}

}  // namespace

namespace {

// A run from the file at `input_path` to `outputs`: every destination opened before
// the work (a missing folder fails in a moment, not after the run), the input opened
// (the "open" phase) and its run planned, `produce` run on it, the mesh written; the
// stats committed first, so that when they cannot be written the mesh output stays as
// it was.
void run_to_files(const std::string& input_path, const OutputOptions& outputs, const SimplifyOptions& options,
                  SimplifyStats& st, const std::function<OutputMesh(MeshInput& input, const RunPlan& plan)>& produce) {
  const MeshFormat format = output_format(outputs);
  check_distinct_destinations(input_path, outputs);
  std::unique_ptr<OutputFile> stats_file;
  if (!outputs.stats.empty()) stats_file = std::make_unique<OutputFile>(outputs.stats);
  OutputFile mesh_file(outputs.mesh);
  auto threads = limit_threads(options.threads);
  const PeakAnonSampler memory;
  double t0 = now_seconds();
  MeshInput input = open_input(input_path, options);
  st.phases.push_back({"open", now_seconds() - t0});
  const RunPlan plan = plan_run(input, options);
  OutputMesh mesh = produce(input, plan);
  mesh.materials = input.info.materials;
  write_output(mesh_file, format, outputs, mesh, plan, st);
  st.seconds_total = now_seconds() - t0;
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = std::max(st.peak_anon_bytes, memory.peak());
  if (stats_file) {
    stats_file->write_all(stats_to_json(st, input_path, outputs, options));
    stats_file->commit();
  }
  mesh_file.commit();
}

}  // namespace

void simplify_file(const std::string& input_path, const OutputOptions& outputs, const SimplifyOptions& options,
                   SimplifyStats* stats) {
  SimplifyStats local;
  SimplifyStats& st = stats ? *stats : local;
  run_to_files(input_path, outputs, options, st,
               [&](MeshInput& input, const RunPlan& plan) { return simplify_output(input, plan, &st); });
}

void simplify_lods_file(const std::string& input_path, const OutputOptions& outputs, const SimplifyOptions& options,
                        const LodOptions& lods, std::vector<SimplifyStats>* stats) {
  if (outputs.mesh == "-") throw UsageError("options.lods", "options.lods writes a file per level, not to stdout");
  if (!outputs.stats.empty())
    throw UsageError("outputs.stats", "outputs.stats and options.lods: the levels' figures go to their description (" +
                                          lod_description_path(outputs.mesh) + ")");
  check_lods(options, lods);
  const MeshFormat format = output_format(outputs);
  // Every level's file is opened before the work, and committed when all are written.
  std::vector<std::unique_ptr<OutputFile>> files;
  for (std::uint32_t k = 0; k < lods.levels; ++k) {
    OutputOptions level = outputs;
    level.mesh = lod_level_path(outputs.mesh, k);
    check_distinct_destinations(input_path, level);
    files.push_back(std::make_unique<OutputFile>(level.mesh));
  }
  auto threads = limit_threads(options.threads);
  double t0 = now_seconds();
  MeshInput input = open_input(input_path, options);
  const double open_seconds = now_seconds() - t0;
  const RunPlan plan = plan_run(input, options);  // for the writing; simplify_lods_output plans each level
  std::vector<SimplifyStats> local;
  std::vector<SimplifyStats>& st = stats ? *stats : local;
  st.clear();
  double level_start = now_seconds();
  simplify_lods_output(input, options, lods, [&](std::uint32_t k, OutputMesh& mesh, const SimplifyStats& level) {
    st.push_back(level);
    SimplifyStats& s = st.back();
    if (k == 0) s.phases.insert(s.phases.begin(), {"open", open_seconds});
    const double write_start = now_seconds();
    mesh.materials = input.info.materials;
    write_output(*files[k], format, outputs, mesh, plan, s);
    const double now = now_seconds();
    // A level whose run timed itself (a target's levels, worked out before level 0
    // is handed on) keeps its time; the others took the time since the last.
    const double work = level.seconds_total > 0 ? level.seconds_total + (now - write_start) : now - level_start;
    s.seconds_total = work + (k == 0 ? open_seconds : 0);
    level_start = now;
  });
  for (auto& f : files) f->commit();
}

namespace {

// The absolute path of `path` with links followed, for a manifest read elsewhere.
std::string absolute_path(const std::string& path) {
  char* real = ::realpath(path.c_str(), nullptr);
  if (!real) throw IoError(system_error_text(path, "cannot find", errno));
  std::string out = real;
  std::free(real);
  return out;
}

}  // namespace

void check_distributed_options(const SimplifyOptions& options) {
  const ClusterMethod method = resolved_method(options);
  if (method != ClusterMethod::uniform && method != ClusterMethod::qem && method != ClusterMethod::floating &&
      method != ClusterMethod::curvature)
    throw UsageError("options.method",
                     std::string("a distributed run (options.part) takes options.method uniform, floating, curvature, "
                                 "or qem (the default with a target); ") +
                         method_name(method) + " runs in one process for now");
  if (options.thick_edges)
    throw UsageError("options.thick_edges", "a distributed run (options.part) makes no thick edges yet");
  if (!options.locked_vertices.empty())
    throw UsageError("options.locked_vertices", "a distributed run (options.part) keeps no locked vertices yet");
  if (options.lock_boundary)
    throw UsageError("options.lock_boundary", "a distributed run (options.part) keeps no boundary locked yet");
}

void simplify_part(const std::string& input_path, const SimplifyOptions& options, const PartOptions& part,
                   SimplifyStats* stats) {
  if (part.count < 1 || part.index >= part.count)
    throw UsageError("part.index", "part.index " + std::to_string(part.index) + " must be below part.count " +
                                       std::to_string(part.count));
  if (part.work_dir.empty()) throw UsageError("part.work_dir", "part.work_dir: a distributed run needs a work folder");
  struct stat folder;
  if (::stat(part.work_dir.c_str(), &folder) != 0 || !S_ISDIR(folder.st_mode))
    throw IoError(part.work_dir +
                  ": the work folder does not exist: make it first, where every part and the merge can reach it");
  if (input_path == "-") throw UsageError("", "a distributed run reads its input from a shared path, not stdin");
  check_distributed_options(options);
  SimplifyStats local;
  SimplifyStats& st = stats ? *stats : local;
  auto threads = limit_threads(options.threads);
  const PeakAnonSampler memory;
  const double t0 = now_seconds();
  MeshInput input = open_input(input_path, options);
  const RunPlan plan = plan_run(input, options);
  st = begin_run(input);
  PartManifest manifest;
  manifest.part = part.index;
  manifest.parts = part.count;
  manifest.input = absolute_path(input_path);
  manifest.key = input_key(input_path);
  manifest.options = part_options_text(plan);
  if (plan.method == ClusterMethod::qem) {
    run_qem_part(input, plan, manifest, part.work_dir, &st);
  } else {
    if (!plan.target.given()) {
      manifest.grid = choose_grid(input, plan.sizing, plan.threads);
      record_grid(manifest.grid, &st);
      input.restart_triangles();
    }
    run_clustering_part(input, plan, manifest, PartChannel{part.exchange, part.deliver}, part.work_dir, &st);
  }
  st.seconds_total = now_seconds() - t0;
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = std::max(st.peak_anon_bytes, memory.peak());
}

void merge_parts(const std::string& work_dir, const OutputOptions& outputs, const SimplifyOptions& runtime,
                 SimplifyStats* stats) {
  SimplifyStats local;
  SimplifyStats& st = stats ? *stats : local;
  output_format(outputs);  // an unwritable name is refused before the parts are read
  const PartSet parts(work_dir);
  const PartManifest& manifest = parts.manifest();
  // The parts' options, with only how this process runs taken from the caller's: any
  // other option given here (a lock, a sizing) would change the result.
  SimplifyOptions options;
  options.memory_budget = runtime.memory_budget;
  options.budget_counts_process = runtime.budget_counts_process;
  options.threads = runtime.threads;
  options.temp_dir = runtime.temp_dir;
  options.progress = runtime.progress;
  options.release_memory = runtime.release_memory;
  options.floating.spill_compression = runtime.floating.spill_compression;
  if (!read_part_options(manifest.options, &options))
    throw InputError(work_dir + "/" + part_file_name(0, manifest.parts) + ": its options are malformed");
  run_to_files(manifest.input, outputs, options, st, [&](MeshInput& input, const RunPlan& plan) {
    const PeakAnonSampler memory;
    begin_stats(input, &st);
    OutputMesh mesh;
    if (!plan.target.given()) {
      record_grid(manifest.grid, &st);
      mesh = parts.clustering(input, plan)(manifest.grid, &st, nullptr);
    } else if (plan.method != ClusterMethod::qem && manifest.grid.cell > 0) {
      // The curvature estimate serves phase 1 at any grid; the others' sums, only theirs.
      const bool any_grid = plan.method == ClusterMethod::curvature;
      mesh = OutputMesh::of(simplify_to_target_after_clustering(input, plan, manifest.grid,
                                                                parts.clustering(input, plan), any_grid, &st));
    } else if (plan.method != ClusterMethod::qem) {  // the parts clustered nothing: the run whole
      mesh = OutputMesh::of(simplify_to_target(input, plan, &st));
    } else if (parts.has_first_pass()) {
      mesh =
          OutputMesh::of(simplify_to_target_after_parts(input, plan, parts.first_pass(input.attributes.size()), &st));
    } else {  // the parts found no pass to spread: the run whole
      mesh = OutputMesh::of(simplify_to_target(input, plan, &st));
    }
    finish_run(input, plan, memory, mesh, st);
    return mesh;
  });
}

SimplifiedMesh simplify_file_to_mesh(const std::string& input_path, const SimplifyOptions& options,
                                     SimplifyStats* stats) {
  auto threads = limit_threads(options.threads);
  MeshInput input = open_input(input_path, options);
  return simplify(input, options, stats);
}

void simplify_file_to_lods(const std::string& input_path, const SimplifyOptions& options, const LodOptions& lods,
                           const LodSink& sink) {
  auto threads = limit_threads(options.threads);
  MeshInput input = open_input(input_path, options);
  simplify_lods(input, options, lods, sink);
}

void simplify_file(const std::string& input_path, const std::string& output_path, const SimplifyOptions& options,
                   SimplifyStats* stats) {
  OutputOptions outputs;
  outputs.mesh = output_path;
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

std::uint64_t minimum_memory_budget() { return std::uint64_t(32) << 20; }

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
