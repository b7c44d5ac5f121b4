// oocsimp command line: a thin layer over the library (include/oocsimp/).
//
// Exit codes: 0 ok, 2 usage, 3 bad input, 4 I/O or resource failure.
#include <CLI/CLI.hpp>

#include <cinttypes>
#include <cstdio>
#include <iostream>
#include <new>
#include <thread>

#include "oocsimp/error.hpp"
#include "oocsimp/generate.hpp"
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

int run_simplify(const std::string& in, const std::string& out, const CellSizing& sizing, unsigned threads,
                 const std::string& tmp, const std::string& stats_path, bool quiet, bool ascii) {
  ProgressReporter progress(quiet);
  SimplifyOptions options;
  options.sizing = sizing;
  if (options.sizing.cell <= 0 && options.sizing.grid == 0 && options.sizing.ratio <= 0) options.sizing.grid = 256;
  options.threads = threads;
  options.temp_dir = tmp;
  options.progress = &progress;
  SimplifyStats stats;
  simplify_file(in, out, ascii, options, &stats);
  if (!stats_path.empty()) write_file_atomically(stats_path, stats_to_json(stats));
  if (!quiet) {
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
    if (stats.skipped_faces)
      std::fprintf(stderr, "oocsimp: warning: skipped %" PRIu64 " faces with fewer than 3 corners\n",
                   stats.skipped_faces);
  }
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

}  // namespace

int main(int argc, char** argv) {
  install_signal_cleanup();
  CLI::App app{"oocsimp: out-of-core simplification of huge triangle meshes"};
  app.require_subcommand(1);

  std::string in, out, tmp, stats_path, shape = "sphere";
  CellSizing sizing;
  unsigned threads = 0;
  bool quiet = false, ascii = false;
  std::uint64_t tris = 1000000, seed = 1;

  CLI::App* simplify = app.add_subcommand("simplify", "Simplify a mesh file (PLY, OBJ, STL, optionally .zst)");
  simplify->add_option("input", in, "Input mesh")->required();
  simplify->add_option("-o,--output", out, "Output mesh (.ply, .obj, optionally .zst)")->required();
  auto* cell = simplify->add_option("--cell", sizing.cell, "Cell side in model units");
  auto* grid = simplify->add_option("--grid", sizing.grid, "Cells along the longest bounding-box axis (default 256)");
  auto* ratio = simplify->add_option("--ratio", sizing.ratio, "Approximate fraction of triangles to keep");
  cell->excludes(grid)->excludes(ratio);
  grid->excludes(ratio);
  simplify->add_option("--threads", threads, "Worker threads (default: all cores)");
  simplify->add_option("--tmp", tmp, "Folder for temporary files (default $TMPDIR or /tmp)");
  simplify->add_option("--stats", stats_path, "Write statistics as JSON to this file");
  simplify->add_flag("--quiet", quiet, "No progress and no summary");
  simplify->add_flag("--ascii", ascii, "Write ascii PLY instead of binary");

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kOk : kUsage;
  }

  try {
    if (*simplify) return run_simplify(in, out, sizing, threads, tmp, stats_path, quiet, ascii);
    if (*info) return run_info(in, tmp);
    if (*generate) return run_generate(tris, shape, seed, out, ascii, quiet);
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
