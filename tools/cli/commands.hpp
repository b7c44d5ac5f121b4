// The oocsimp subcommands, one file each in tools/cli/, for main() (main.cpp) to
// declare and dispatch. Each is an args struct that CLI11 fills, add_<name>_command
// declaring its options and run_<name> doing the work.
#pragma once

#include "common.hpp"

namespace oocsimp_cli {

// The units of a 4-k record's error (HierarchyRecord::error), which info, hierarchy
// and extract --error share.
inline constexpr const char* kHierarchyErrorUnits = "area x squared distance, model units^4";

/// The exception being handled, reported on stderr as its exit code (called in a
/// catch block).
int report_failure();

struct SimplifyArgs {
  std::string in;
  OutputOptions outputs;
  // What CLI11 sets directly: the enums, the flags and --tmp. The numbers below are
  // checked into a copy (check_simplify_args).
  SimplifyOptions options;
  std::string attributes = "all";
  std::string lock_vertices;  // a file of vertex indices
  Given cell, grid, ratio, tile, mem, threads, target_tris, target_ratio, max_error, intermediate_factor;
  Given lods, lod_factor;
  CLI::Option* refine = nullptr;
  std::vector<CLI::Option*> floating_only;
  RepresentativeRule representative = RepresentativeRule::quadric;
  CLI::Option* rep = nullptr;
  Given radius, curvature_tolerance, max_depth;
  std::string neighbourhood = "ball";
  std::vector<CLI::Option*> curvature_only;
  bool measure = false;
  bool quiet = false;
  Given part;
  std::string work_dir;
};

struct MergeArgs {
  std::string dir;
  OutputOptions outputs;
  SimplifyOptions options;
  Given mem, threads;
  bool quiet = false;
};

struct HierarchyArgs {
  std::string in, out, stats;
  Given levels, threads, mem, level_ratio, sets;
  HierarchyOptions options;
  bool quiet = false, sequential = false, reuse_quadrics = false, repair = true;
  std::string attributes = "all";
};

struct ExtractArgs {
  std::string in, stats;  // stats: the CLI's own JSON, not OutputOptions::stats
  OutputOptions output;   // CLI11 sets the mesh path and ascii
  Given level, tris, error, box, sphere;
  HierarchyPlacement placement = HierarchyPlacement::quadric;
  bool quiet = false;
};

struct InfoArgs {
  std::string in, tmp;
  bool json = false, quiet = false;
};

struct GenerateArgs {
  Given tris, seed;
  std::string out;
  GenerateOptions options;  // CLI11 sets the shape and the flags
  bool quiet = false;
};

struct MeasureArgs {
  std::string a, b;
  Given samples, seed, threads;
  MeasureOptions options;  // CLI11 sets --tmp
  bool json = false;
  bool quiet = false;
};

struct CurvatureArgs {
  std::string in, stats;  // stats: the CLI's own JSON, not OutputOptions::stats
  OutputOptions output;   // CLI11 sets the mesh path and ascii
  Given radius, threads, mem, tile, at_scale;
  std::string neighbourhood = "ball";
  CurvatureOptions options;
  bool quiet = false;
};

struct LodSelectArgs {
  std::string lods, distance, fov, height, factor;
  bool json = false;
};

struct RenderArgs {
  std::string in, out, size, view, tmp;
  RenderOptions options;  // CLI11 sets the shading and --thick-edges
  bool quiet = false;
};

CLI::App* add_simplify_command(CLI::App& app, SimplifyArgs& a);
int run_simplify(const SimplifyArgs& a);
CLI::App* add_merge_command(CLI::App& app, MergeArgs& a);
int run_merge(const MergeArgs& a);
CLI::App* add_hierarchy_command(CLI::App& app, HierarchyArgs& a);
int run_hierarchy(HierarchyArgs& a);
CLI::App* add_extract_command(CLI::App& app, ExtractArgs& a);
int run_extract(const ExtractArgs& a);
CLI::App* add_info_command(CLI::App& app, InfoArgs& a);
int run_info(const InfoArgs& a);
CLI::App* add_generate_command(CLI::App& app, GenerateArgs& a);
int run_generate(const GenerateArgs& a);
CLI::App* add_measure_command(CLI::App& app, MeasureArgs& a);
int run_measure(const MeasureArgs& a);
CLI::App* add_curvature_command(CLI::App& app, CurvatureArgs& a);
int run_curvature(CurvatureArgs& a);
CLI::App* add_lod_select_command(CLI::App& app, LodSelectArgs& a);
int run_lod_select(const LodSelectArgs& a);
CLI::App* add_render_command(CLI::App& app, RenderArgs& a);
int run_render(const RenderArgs& a);

}  // namespace oocsimp_cli
