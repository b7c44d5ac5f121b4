// The oocsimp subcommands other than simplify (cli_commands.cpp), for main() to
// declare and dispatch.
#pragma once

#include "cli_common.hpp"

namespace oocsimp_cli {

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
  std::string in, out, stats;
  Given level, tris, error, box, sphere;
  HierarchyPlacement placement = HierarchyPlacement::quadric;
  bool ascii = false, quiet = false;
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
  std::string in, out, stats;
  Given radius, threads, mem, tile, at_scale;
  std::string neighbourhood = "ball";
  CurvatureOptions options;
  bool ascii = false, quiet = false;
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

CLI::App* add_merge_command(CLI::App& app, MergeArgs& a);
int run_merge(const MergeArgs& a);
CLI::App* add_hierarchy_command(CLI::App& app, HierarchyArgs& a);
int run_hierarchy(HierarchyArgs& a);
CLI::App* add_extract_command(CLI::App& app, ExtractArgs& a);
int run_extract(const ExtractArgs& a);
CLI::App* add_info_command(CLI::App& app, InfoArgs& a);
int run_hierarchy_info(const InfoArgs& a);
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
