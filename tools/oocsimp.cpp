// oocsimp command line: a thin layer over the library (include/oocsimp/).
//
// Exit codes: 0 ok, 2 usage, 3 bad input, 4 I/O or resource failure.
#include <CLI/CLI.hpp>

#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <map>
#include <new>
#include <thread>
#include <utility>

#include "oocsimp/error.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/mesh_input.hpp"
#include "oocsimp/progress.hpp"
#include "oocsimp/simplify.hpp"
#include "oocsimp/temp_file.hpp"

using namespace oocsimp;

namespace {

enum ExitCode { kOk = 0, kUsage = 2, kBadInput = 3, kIo = 4 };

void progress_callback(std::uint64_t done, std::uint64_t total, void* user) {
  auto* p = static_cast<ProgressReporter*>(user);
  p->set_total(total);
  p->set(done);
}

int run_simplify(const std::string& in, const std::string& out, SimplifyOptions options, const std::string& mem,
                 const std::string& stats_path, bool quiet, bool ascii) {
  ProgressReporter progress(quiet);
  if (options.sizing.cell <= 0 && options.sizing.grid == 0 && options.sizing.ratio <= 0) options.sizing.grid = 256;
  if (!mem.empty()) options.memory_budget = parse_byte_size(mem);
  options.progress = &progress;
  SimplifyStats stats;
  simplify_file(in, out, ascii, options, &stats);
  if (!stats_path.empty()) write_file_atomically(stats_path, stats_to_json(stats));
  if (!quiet) {
    if (options.method == ClusterMethod::floating)
      std::fprintf(stdout, "tiles   %" PRIu64 " tiles%s, %" PRIu64 " rounds, spill %.1f MiB on disk (%.1f MiB raw)\n",
                   stats.tiles, stats.resumed ? " (kept by an earlier run)" : "", stats.rounds,
                   double(stats.spill_bytes) / 1048576.0, double(stats.spill_raw_bytes) / 1048576.0);
    double mtri = stats.seconds_total > 0 ? double(stats.input_triangles) / stats.seconds_total / 1e6 : 0;
    std::fprintf(stdout,
                 "input   %" PRIu64 " vertices, %" PRIu64 " triangles\n"
                 "output  %" PRIu64 " vertices, %" PRIu64 " triangles (grid %ux%ux%u, cell %.6g)\n"
                 "time    %.3f s (open %.3f, vertices %.3f, faces %.3f, solve %.3f, write %.3f): %.2f Mtri/s\n"
                 "memory  peak RSS %.1f MiB, peak anonymous %.1f MiB\n",
                 stats.input_vertices, stats.input_triangles, stats.output_vertices, stats.output_triangles,
                 stats.grid_dims[0], stats.grid_dims[1], stats.grid_dims[2], stats.cell_size, stats.seconds_total,
                 stats.seconds_open, stats.seconds_vertices, stats.seconds_faces, stats.seconds_solve,
                 stats.seconds_write, mtri, double(stats.peak_rss_bytes) / 1048576.0,
                 double(stats.peak_anon_bytes) / 1048576.0);
  }
  // Not silenced by --quiet: the output lacks part of the input.
  std::string skipped = skipped_input_summary(in, stats);
  if (!skipped.empty()) std::fprintf(stderr, "oocsimp: warning: %s\n", skipped.c_str());
  return kOk;
}

int run_info(const std::string& in, const std::string& tmp) {
  OpenOptions open;
  open.temp_dir = tmp;
  MeshInput m = open_mesh_input(in, open);
  const MeshInfo& i = m.info;
  std::printf("file      %s\n", i.path.c_str());
  std::printf("format    %s%s\n", i.format.c_str(), i.compressed ? " (zstd)" : "");
  std::printf("vertices  %" PRIu64 "\n", i.vertex_count);
  std::printf("faces     %" PRIu64 "\n", i.face_count);
  for (const auto& e : i.elements) std::printf("element   %s\n", e.c_str());
  for (const auto& c : i.comments) std::printf("header    %s\n", c.c_str());
  std::printf("positions %s\n", i.positions_in_place ? "read in place (mmap)" : "converted to a temporary array");
  if (i.bounds.empty()) {
    std::printf("bounds    empty\n");
  } else {
    std::printf("bounds    min %.9g %.9g %.9g\n", i.bounds.min.x, i.bounds.min.y, i.bounds.min.z);
    std::printf("          max %.9g %.9g %.9g\n", i.bounds.max.x, i.bounds.max.y, i.bounds.max.z);
    std::printf("diagonal  %.9g\n", i.bounds.diagonal());
  }
  if (i.non_finite_vertices > 0)
    std::printf("non-finite %" PRIu64 " (vertices with a NaN or infinite coordinate, ignored; the first: vertex %" PRIu64
                " at %s)\n",
                i.non_finite_vertices, i.first_non_finite_vertex, i.first_non_finite_position.c_str());
  return kOk;
}

int run_generate(std::uint64_t tris, const std::string& shape, std::uint64_t seed, const std::string& out, bool ascii,
                 bool quiet) {
  GenerateOptions o;
  o.triangles = tris;
  o.seed = seed;
  o.ascii = ascii;
  if (shape == "sphere") o.shape = SyntheticShape::sphere;
  else if (shape == "terrain") o.shape = SyntheticShape::terrain;
  else if (shape == "parts") o.shape = SyntheticShape::parts;
  else throw UsageError("unknown shape \"" + shape + "\" (sphere, terrain or parts)");
  ProgressReporter progress(quiet);
  progress.begin("generate", tris, "tri");
  GenerateResult r = generate_mesh(out, o, progress_callback, &progress);
  progress.end();
  if (!quiet) std::printf("%s: %" PRIu64 " vertices, %" PRIu64 " triangles\n", out.c_str(), r.vertices, r.triangles);
  return kOk;
}

int run_measure(const std::string& a, const std::string& b, MeasureOptions options, bool json, bool quiet) {
  ProgressReporter progress(quiet);
  options.progress = &progress;
  DistanceReport r = measure_surface_distance(a, b, options);
  if (json) {
    std::fputs(distance_report_to_json(r).c_str(), stdout);
    return kOk;
  }
  std::printf("A  %s: %" PRIu64 " triangles, area %.6g, bounding-box diagonal %.6g\n", a.c_str(), r.a_triangles,
              r.a_area, r.a_diagonal);
  std::printf("B  %s: %" PRIu64 " triangles, area %.6g\n", b.c_str(), r.b_triangles, r.b_area);
  std::printf("%-10s %9s %13s %13s %13s %11s %11s %11s\n", "", "samples", "hausdorff", "mean", "rms", "haus/diag",
              "mean/diag", "rms/diag");
  const std::pair<const char*, const DistanceStats*> rows[] = {
      {"A -> B", &r.a_to_b}, {"B -> A", &r.b_to_a}, {"symmetric", &r.symmetric}};
  for (const auto& row : rows) {
    const DistanceStats& s = *row.second;
    DistanceStats f = r.fraction_of_diagonal(s);
    std::printf("%-10s %9" PRIu64 " %13.6e %13.6e %13.6e %11.4e %11.4e %11.4e\n", row.first, s.samples, s.max, s.mean,
                s.rms, f.max, f.mean, f.rms);
  }
  std::printf("time %.3f s, peak RSS %.1f MiB, peak anonymous %.1f MiB\n", r.seconds,
              double(r.peak_rss_bytes) / 1048576.0, double(r.peak_anon_bytes) / 1048576.0);
  return kOk;
}

}  // namespace

int main(int argc, char** argv) {
  install_signal_cleanup();
  CLI::App app{"oocsimp: out-of-core simplification of huge triangle meshes"};
  app.require_subcommand(1);

  std::string in, out, tmp, stats_path, shape = "sphere", mem;
  SimplifyOptions so;
  CellSizing& sizing = so.sizing;
  bool quiet = false, ascii = false;
  std::uint64_t tris = 1000000, seed = 1;

  CLI::App* simplify = app.add_subcommand("simplify", "Simplify a mesh file (PLY, OBJ, STL, optionally .zst)");
  simplify->add_option("input", in, "Input mesh")->required();
  simplify->add_option("-o,--output", out, "Output mesh (.ply, .obj, .stl or .off, optionally .zst)")->required();
  auto* cell = simplify->add_option("--cell", sizing.cell, "Cell side in model units");
  auto* grid = simplify->add_option("--grid", sizing.grid, "Cells along the longest bounding-box axis (default 256)");
  auto* ratio = simplify->add_option("--ratio", sizing.ratio, "Approximate fraction of triangles to keep");
  cell->excludes(grid)->excludes(ratio);
  grid->excludes(ratio);
  simplify->add_option("--method", so.method, "floating (Low & Tan, the default) or uniform (OoCS grid)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, ClusterMethod>{{"floating", ClusterMethod::floating}, {"uniform", ClusterMethod::uniform}}));
  simplify->add_option("--cell-shape", so.cell_shape, "Floating cell shape: cube or sphere")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, CellShape>{{"cube", CellShape::cube}, {"sphere", CellShape::sphere}}));
  simplify->add_option("--assign", so.assign, "Vertex in several cells: nearest (centre) or heaviest")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, AssignRule>{{"nearest", AssignRule::nearest}, {"heaviest", AssignRule::heaviest}}));
  simplify->add_option("--rep", so.representative, "Representative vertex: quadric, centre or mean")
      ->transform(CLI::CheckedTransformer(std::map<std::string, RepresentativeRule>{
          {"quadric", RepresentativeRule::quadric}, {"centre", RepresentativeRule::centre},
          {"mean", RepresentativeRule::mean}}));
  simplify->add_option("--mem", mem, "Working-set budget, e.g. 256M or 2G (default: a quarter of physical memory)");
  simplify->add_option("--tile", so.tile_side, "Floating: tile side in model units (default: from --mem)");
  simplify->add_flag("--keep-tmp", so.keep_temp,
                     "Floating: keep the binned tiles in --tmp and reuse them on the next run of the same input");
  simplify->add_option("--spill-compress", so.spill_compression,
                       "Floating: zstd on the triangle, stitch and kept-triangle spills: auto (when they would not "
                       "fit in half the available memory, or with --keep-tmp), zstd or none")
      ->transform(CLI::CheckedTransformer(std::map<std::string, SpillCompression>{
          {"auto", SpillCompression::automatic}, {"zstd", SpillCompression::zstd}, {"none", SpillCompression::none}}));
  simplify->add_option("--threads", so.threads, "Worker threads (default: all cores)");
  simplify->add_option("--tmp", so.temp_dir, "Folder for temporary files (default $TMPDIR or /tmp)");
  simplify->add_option("--stats", stats_path, "Write statistics as JSON to this file");
  simplify->add_flag("--quiet", quiet, "No progress and no summary");
  simplify->add_flag("--ascii", ascii, "Write ascii PLY or STL instead of binary");
  simplify->add_option("--precision", so.precision, "Output coordinates: float, double or auto (like the input)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, Precision>{
          {"auto", Precision::automatic}, {"float", Precision::float32}, {"double", Precision::float64}}));

  CLI::App* info = app.add_subcommand("info", "Print format, element counts, properties and bounding box");
  info->add_option("input", in, "Input mesh")->required();
  info->add_option("--tmp", tmp, "Folder for temporary files (default $TMPDIR or /tmp)");

  CLI::App* generate = app.add_subcommand("generate", "Write a synthetic dense mesh, streamed in O(1) memory");
  generate->add_option("--tris", tris, "Number of triangles (approximately)")->required();
  generate->add_option("--shape", shape, "sphere, terrain or parts")->check(CLI::IsMember({"sphere", "terrain", "parts"}));
  generate->add_option("--seed", seed, "Random seed");
  generate->add_option("-o,--output", out, "Output PLY (.zst compresses)")->required();
  generate->add_flag("--ascii", ascii, "Write ascii PLY");
  generate->add_flag("--quiet", quiet, "No progress");

  std::string second;
  MeasureOptions measure_options;
  bool json = false;
  CLI::App* measure = app.add_subcommand("measure", "Hausdorff, mean and RMS distance between two surfaces");
  measure->add_option("a", in, "Mesh A, streamed (the original; any size)")->required();
  measure->add_option("b", second, "Mesh B, loaded into memory (e.g. the simplification)")->required();
  measure->add_option("--samples", measure_options.samples, "Points sampled on each surface (default 1000000)");
  measure->add_option("--seed", measure_options.seed, "Random seed of the samples");
  measure->add_option("--threads", measure_options.threads, "Worker threads (default: all cores)");
  measure->add_option("--tmp", measure_options.temp_dir, "Folder for temporary files (default $TMPDIR or /tmp)");
  measure->add_flag("--json", json, "Print the report as JSON");
  measure->add_flag("--quiet", quiet, "No progress");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kOk : kUsage;
  }

  try {
    if (*simplify) return run_simplify(in, out, so, mem, stats_path, quiet, ascii);
    if (*info) return run_info(in, tmp);
    if (*generate) return run_generate(tris, shape, seed, out, ascii, quiet);
    if (*measure) return run_measure(in, second, measure_options, json, quiet);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kUsage;
  } catch (const InputError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kBadInput;
  } catch (const IoError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kIo;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "oocsimp: out of memory\n");
    return kIo;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kIo;
  }
  return kUsage;
}
