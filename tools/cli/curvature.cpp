// oocsimp curvature: per-vertex principal curvatures k1, k2 (the ball estimator, or
// --at-scale's cell estimate).
#include "commands.hpp"
#include "stats_file.hpp"

namespace oocsimp_cli {

CLI::App* add_curvature_command(CLI::App& app, CurvatureArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "curvature", "Principal curvatures k1, k2 of every vertex by integral invariants (Hua et al. §3.4), to PLY");
  cmd->add_option("input", a.in, "Input mesh")->required();
  cmd->add_option("-o,--output", a.output.mesh, "Output PLY: the mesh with float vertex properties k1 and k2")
      ->required();
  add_given(cmd, "--radius", &a.radius, "Radius of the ball or sphere (default 5 mean edge lengths)");
  cmd->add_option("--neighbourhood", a.neighbourhood,
                  "ball: the ball cut by the solid (Hua et al. eq. 13-14, the default); sphere: the sphere cut by it "
                  "(eq. 17-18)")
      ->check(CLI::IsMember({"ball", "sphere"}));
  add_given(cmd, "--mem", &a.mem,
            "Heap budget; a mesh larger than it is estimated in tiles with a halo (default: a quarter of memory)");
  add_given(cmd, "--tile", &a.tile, "Side of the tiles, model units (default: in memory when it fits --mem)");
  add_given(cmd, "--at-scale", &a.at_scale,
            "Estimate at cells of this side (model units) from the faces' moments, interpolated: fast, at that "
            "scale (default: the ball or sphere)");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  cmd->add_flag("--ascii", a.output.ascii, "Write ascii PLY");
  add_stats_option(cmd, &a.stats);
  add_quiet_flag(cmd, &a.quiet, "No progress and no summary");
  return cmd;
}

int run_curvature(CurvatureArgs& a) {
  CurvatureOptions o = a.options;
  if (a.radius.given()) o.radius = positive_number("--radius", a.radius.text);
  if (a.threads.given()) o.threads = threads_of(a.threads);
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem);
  if (a.tile.given()) o.tile_side = positive_number("--tile", a.tile.text);
  if (a.at_scale.given()) o.at_scale = positive_number("--at-scale", a.at_scale.text);
  o.neighbourhood = a.neighbourhood == "sphere" ? CurvatureNeighbourhood::sphere : CurvatureNeighbourhood::ball;
  check_stats_path(a.stats, a.in, a.output.mesh);
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  CurvatureStats st;
  curvature_file(a.in, a.output, o, &st);
  std::vector<std::string> warnings;
  char w[320];
  if (st.at_scale == 0 && st.fitted + st.none > 0) {
    std::snprintf(w, sizeof w,
                  "%" PRIu64
                  " vertices where the surface does not cover the disk of radius %g (an outline, a hole or a soup) "
                  "were fitted with a quadric instead, and %" PRIu64
                  " with no face, area or neighbours within it got 0",
                  st.fitted, st.radius, st.none);
    warnings.push_back(w);
  }
  if (st.at_scale > 0 && st.none > 0) {
    std::snprintf(w, sizeof w, "%" PRIu64 " vertices with no cell around them that has an estimate got 0", st.none);
    warnings.push_back(w);
  }
  if (!a.quiet) print_warnings(warnings);
  if (!a.stats.empty()) {
    const std::string options =
        "{\"radius\": " + json_shortest(st.radius) + ", \"neighbourhood\": " + json_string(a.neighbourhood) +
        ", \"at_scale\": " + json_shortest(st.at_scale) + ", \"tile\": " + json_shortest(st.tile_side) +
        ", \"mem_bytes\": " + json_count(o.memory_budget ? o.memory_budget : default_memory_budget()) +
        ", \"threads\": " + json_count(o.threads) +
        ", \"tmp\": " + json_string(o.temp_dir.empty() ? default_temp_dir() : o.temp_dir) +
        ", \"ascii\": " + json_bool(a.output.ascii) + "}";
    const std::string work =
        "{\"radius\": " + json_shortest(st.radius) + ", \"mean_edge_length\": " + json_shortest(st.mean_edge_length) +
        ", \"at_scale\": " + json_shortest(st.at_scale) + ", \"tile_side\": " + json_shortest(st.tile_side) +
        ", \"invariant\": " + json_count(st.invariant) + ", \"fitted\": " + json_count(st.fitted) +
        ", \"none\": " + json_count(st.none) + "}";
    write_stats(
        a.stats,
        joined(joined(stats_head(a.in, a.output.mesh, a.stats),
                      {json_field("options", options), json_field("input", counts_json(st.vertices, st.triangles)),
                       json_field("curvature", work), json_field("output", counts_json(st.vertices, st.triangles))}),
               stats_tail(warnings, st.seconds, st.peak_rss_bytes, st.peak_anon_bytes)));
  }
  if (a.quiet) return kOk;
  std::FILE* to = a.stats == "-" ? stderr : stdout;
  print_input_line(to, st.vertices, st.triangles);
  if (st.at_scale > 0) {
    std::fprintf(to, "scale   cells of side %g\n", st.at_scale);
    std::fprintf(to, "estimated %" PRIu64 " from the cells around them, %" PRIu64 " not at all\n", st.invariant,
                 st.none);
  } else {
    std::fprintf(to, "radius  %g (mean edge %g), %s\n", st.radius, st.mean_edge_length, a.neighbourhood.c_str());
    std::fprintf(to, "estimated %" PRIu64 " by the invariants, %" PRIu64 " by the fit, %" PRIu64 " not at all, %s\n",
                 st.invariant, st.fitted, st.none,
                 st.tile_side > 0 ? ("in tiles of side " + std::to_string(st.tile_side)).c_str() : "in memory");
  }
  std::fprintf(to, "output  %s: k1 and k2 of %" PRIu64 " vertices\n", a.output.mesh.c_str(), st.vertices);
  std::fprintf(to, "time    %.3f s: %.2f M vertices/s\n", st.seconds,
               st.seconds > 0 ? double(st.vertices) / st.seconds / 1e6 : 0.0);
  print_memory_line(to, st.peak_rss_bytes, st.peak_anon_bytes);
  return kOk;
}

}  // namespace oocsimp_cli
