// oocsimp hierarchy: Velho's 4-k hierarchy of a mesh, written as a .4k file.
#include "commands.hpp"
#include "stats_file.hpp"

namespace oocsimp_cli {

CLI::App* add_hierarchy_command(CLI::App& app, HierarchyArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "hierarchy", "Build Velho's 4-k hierarchy (four-face clusters) of a manifold mesh into a .4k file");
  cmd->add_option("input", a.in, "Input mesh")->required();
  cmd->add_option("-o,--output", a.out, "Output .4k file")->required();
  add_given(cmd, "--levels", &a.levels, "Levels to build, 1 to 1000 (default: until a level removes nothing)");
  add_given(cmd, "--mem", &a.mem,
            "Heap budget; a larger input is first simplified out of core to what fits (default: a quarter of memory)");
  cmd->add_option("--attributes", a.attributes,
                  "Vertex attributes to keep: all (the default), none, or NAME,NAME... (as info lists them)");
  cmd->add_flag("--repair,!--no-repair", a.repair,
                "Make a mesh that is not a manifold surface wound consistently one, with a warning: turn faces to "
                "agree, cut edges of three or more faces, split vertices (the default); --no-repair refuses it");
  cmd->add_flag("--reuse-quadrics", a.reuse_quadrics,
                "After that out-of-core phase, start from its vertex quadrics rather than the reduced mesh's faces");
  cmd->add_flag("--sequential", a.sequential,
                "A level's removals need not be independent: the cheapest first, as an edge collapse takes them "
                "(closer to QEM, a deeper hierarchy)");
  add_given(cmd, "--level-ratio", &a.level_ratio,
            "A level ends at this fraction of the triangles of the level before (default 0.7; 0 = all it can)");
  add_given(cmd, "--sets", &a.sets,
            "Independent sets of removals a level is made of, 1 to 16 (default 3; fewer build faster, farther from "
            "QEM; 1: Velho's, a shallower hierarchy)");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  add_stats_option(cmd, &a.stats);
  add_quiet_flag(cmd, &a.quiet, "No progress and no summary");
  return cmd;
}

int run_hierarchy(HierarchyArgs& a) {
  HierarchyOptions o = a.options;
  if (a.levels.given()) o.levels = std::uint32_t(whole_number("--levels", a.levels.text, 1, 1000));
  if (a.level_ratio.given()) {
    char* end = nullptr;
    o.level_ratio = std::strtod(a.level_ratio.text.c_str(), &end);
    if (a.level_ratio.text.empty() || *end != '\0' || !(o.level_ratio >= 0 && o.level_ratio < 1))
      bad_value("--level-ratio", a.level_ratio.text, "a number from 0 to below 1");
  }
  if (a.sets.given()) o.sets_per_level = std::uint32_t(whole_number("--sets", a.sets.text, 1, 16));
  o.independent = !a.sequential;
  o.reuse_quadrics = a.reuse_quadrics;
  o.repair = a.repair;
  o.attributes = parse_attribute_selection(a.attributes);
  if (a.threads.given()) o.threads = threads_of(a.threads);
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem);
  check_stats_path(a.stats, a.in, a.out);
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  HierarchyStats st;
  build_hierarchy_file(a.in, a.out, o, &st);
  std::vector<std::string> warnings;
  if (st.flipped_faces + st.cut_edges + st.detached_faces > 0)
    warnings.push_back(
        a.in + " is not a manifold surface wound consistently; repaired: " + std::to_string(st.flipped_faces) +
        " faces turned to agree with their neighbours, " + std::to_string(st.cut_edges) +
        " edges of three or more faces (or that could not agree) cut, " + std::to_string(st.detached_faces) +
        " faces given vertices of their own (--no-repair refuses such a mesh)");
  if (o.reuse_quadrics && !st.reduced_triangles)
    warnings.push_back(
        "--reuse-quadrics: the input fitted --mem, so no out-of-core phase ran; the hierarchy started from the faces' "
        "quadrics");
  print_warnings(warnings);
  if (!a.stats.empty()) {
    const std::string options =
        "{\"levels\": " + json_count(o.levels) + ", \"level_ratio\": " + json_shortest(o.level_ratio) +
        ", \"sets\": " + json_count(o.sets_per_level) + ", \"sequential\": " + json_bool(!o.independent) +
        ", \"reuse_quadrics\": " + json_bool(o.reuse_quadrics) + ", \"repair\": " + json_bool(o.repair) +
        ", \"mem_bytes\": " + json_count(o.memory_budget ? o.memory_budget : default_memory_budget()) +
        ", \"threads\": " + json_count(o.threads) +
        ", \"tmp\": " + json_string(o.temp_dir.empty() ? default_temp_dir() : o.temp_dir) + "}";
    const std::string work =
        "{\"reduced_triangles\": " + json_count(st.reduced_triangles) +
        ", \"kept_quadrics\": " + json_bool(st.kept_quadrics) +
        ", \"split_vertices\": " + json_count(st.split_vertices) +
        ", \"flipped_faces\": " + json_count(st.flipped_faces) + ", \"cut_edges\": " + json_count(st.cut_edges) +
        ", \"detached_faces\": " + json_count(st.detached_faces) + ", \"records\": " + json_count(st.records) +
        ", \"swaps\": " + json_count(st.swaps) + ", \"removals\": " + json_count(st.records - st.swaps) +
        ", \"largest_error\": " + json_shortest(st.largest_error) +
        ", \"error_units\": " + json_string(kHierarchyErrorUnits) + "}";
    write_stats(a.stats, joined(joined(stats_head(a.in, a.out, a.stats),
                                       {json_field("options", options),
                                        json_field("input", counts_json(st.input_vertices, st.input_triangles)),
                                        json_field("hierarchy", work),
                                        json_field("output", "{\"bytes\": " + json_count(st.file_bytes) + "}")}),
                                stats_tail(warnings, st.seconds, st.peak_rss_bytes, st.peak_anon_bytes)));
  }
  if (a.quiet) return kOk;
  // stdout may carry the stats: then the summary goes to stderr.
  std::FILE* to = a.stats == "-" ? stderr : stdout;
  char reduced[96] = "";
  if (st.reduced_triangles)
    std::snprintf(reduced, sizeof reduced, " (simplified out of core to %" PRIu64 " first%s)", st.reduced_triangles,
                  st.kept_quadrics ? ", its quadrics kept" : "");
  print_input_line(to, st.input_vertices, st.input_triangles, reduced);
  if (st.split_vertices)
    std::fprintf(to, "split   %" PRIu64 " vertices where several fans of faces met\n", st.split_vertices);
  std::fprintf(to, "records %" PRIu64 " (%" PRIu64 " swaps, %" PRIu64 " removals), largest error %.6g (%s)\n",
               st.records, st.swaps, st.records - st.swaps, st.largest_error, kHierarchyErrorUnits);
  std::fprintf(to, "output  %s, %.1f MiB\n", a.out.c_str(), double(st.file_bytes) / 1048576.0);
  std::fprintf(to, "time    %.3f s: %.2f Mtri/s\n", st.seconds,
               st.seconds > 0 ? double(st.input_triangles) / st.seconds / 1e6 : 0.0);
  print_memory_line(to, st.peak_rss_bytes, st.peak_anon_bytes);
  return kOk;
}

}  // namespace oocsimp_cli
