// oocsimp extract: a mesh cut from a .4k hierarchy at a level, a count, an error or
// in a region.
#include "commands.hpp"
#include "stats_file.hpp"

namespace oocsimp_cli {

namespace {

// `count` finite numbers separated by commas, for `flag`.
std::vector<double> number_list(const std::string& flag, const std::string& text, std::size_t count) {
  std::vector<double> values;
  std::size_t at = 0;
  while (at <= text.size() && values.size() < count + 1) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v))
      bad_value(flag, text, std::to_string(count) + " finite numbers separated by commas");
    values.push_back(v);
    at = comma + 1;
  }
  if (values.size() != count) bad_value(flag, text, std::to_string(count) + " finite numbers separated by commas");
  return values;
}

}  // namespace

CLI::App* add_extract_command(CLI::App& app, ExtractArgs& a) {
  CLI::App* cmd = app.add_subcommand("extract", "Extract a conforming mesh from a .4k hierarchy");
  cmd->add_option("input", a.in, "Input .4k file (written by oocsimp hierarchy)")->required();
  cmd->add_option("-o,--output", a.output.mesh, "Output mesh (PLY, OBJ, STL, OFF, glTF .glb; .zst or .gz compresses)")
      ->required();
  add_given(cmd, "--level", &a.level, "Level J: 0 is the finest, higher is coarser (give one of the three)");
  add_given(cmd, "--tris", &a.tris, "The finest state with at most this many triangles (give one of the three)");
  add_given(cmd, "--error", &a.error,
            std::string("The coarsest state whose removals all cost at most this, in ") + kHierarchyErrorUnits +
                " (info lists each level's; give one of the three)");
  add_given(cmd, "--box", &a.box,
            "x0,y0,z0,x1,y1,z1: keep the faces meeting this box at the finest level (default: no region)");
  add_given(cmd, "--sphere", &a.sphere,
            "x,y,z,r: keep the faces meeting this ball at the finest level (default: no region)");
  add_enum_option(cmd, "--placement", &a.placement, hierarchy_placement_names(),
                  "Where the kept vertices go: quadric (each at the minimum of the quadric it holds, the default) "
                  "or kept (where the finest mesh has them)");
  cmd->add_flag("--ascii", a.output.ascii, "Write ascii PLY or STL");
  add_stats_option(cmd, &a.stats);
  add_quiet_flag(cmd, &a.quiet, "No progress and no summary");
  return cmd;
}

int run_extract(const ExtractArgs& a) {
  HierarchyQuery q;
  const int asked = int(a.level.given()) + int(a.tris.given()) + int(a.error.given());
  if (asked != 1) throw UsageError("extract: give exactly one of --level, --tris and --error");
  if (a.level.given()) q.level = std::uint32_t(whole_number("--level", a.level.text, 0, 1000000));
  if (a.tris.given()) q.triangles = whole_number("--tris", a.tris.text, 1, kMost);
  if (a.error.given()) {
    char* end = nullptr;
    q.error = std::strtod(a.error.text.c_str(), &end);
    if (a.error.text.empty() || *end != '\0' || !std::isfinite(q.error) || q.error < 0)
      bad_value("--error", a.error.text, "a finite number of 0 or more");
  }
  if (a.box.given() && a.sphere.given()) throw UsageError("extract: give --box or --sphere, not both");
  if (a.box.given()) {
    const std::vector<double> b = number_list("--box", a.box.text, 6);
    if (b[0] > b[3] || b[1] > b[4] || b[2] > b[5]) bad_value("--box", a.box.text, "a minimum corner below the maximum");
    q.region = HierarchyQuery::Region::box;
    q.box.min = {b[0], b[1], b[2]};
    q.box.max = {b[3], b[4], b[5]};
  }
  if (a.sphere.given()) {
    const std::vector<double> s = number_list("--sphere", a.sphere.text, 4);
    if (!(s[3] > 0)) bad_value("--sphere", a.sphere.text, "a positive radius");
    q.region = HierarchyQuery::Region::sphere;
    q.centre = {s[0], s[1], s[2]};
    q.radius = s[3];
  }
  q.placement = a.placement;
  check_stats_path(a.stats, a.in, a.output.mesh);
  ProgressReporter progress(a.quiet);
  ExtractStats st;
  extract_file(a.in, a.output, q, progress.callback(), &st);
  if (!a.stats.empty()) {
    std::string query = "{";
    if (a.level.given()) query += "\"level\": " + json_count(q.level);
    if (a.tris.given()) query += "\"triangles\": " + json_count(q.triangles);
    if (a.error.given()) query += "\"error\": " + json_shortest(q.error);
    if (q.region == HierarchyQuery::Region::box)
      query += ", \"box\": {\"min\": [" + json_shortest(q.box.min.x) + ", " + json_shortest(q.box.min.y) + ", " +
               json_shortest(q.box.min.z) + "], \"max\": [" + json_shortest(q.box.max.x) + ", " +
               json_shortest(q.box.max.y) + ", " + json_shortest(q.box.max.z) + "]}";
    if (q.region == HierarchyQuery::Region::sphere)
      query += ", \"sphere\": {\"centre\": [" + json_shortest(q.centre.x) + ", " + json_shortest(q.centre.y) + ", " +
               json_shortest(q.centre.z) + "], \"radius\": " + json_shortest(q.radius) + "}";
    query += ", \"placement\": " + json_string(name_of(hierarchy_placement_names(), q.placement)) +
             ", \"ascii\": " + json_bool(a.output.ascii) + ", \"error_units\": " + json_string(kHierarchyErrorUnits) +
             "}";
    write_stats(a.stats, joined(joined(stats_head(a.in, a.output.mesh, a.stats),
                                       {json_field("options", query),
                                        json_field("input", counts_json(st.finest_vertices, st.finest_triangles)),
                                        json_field("output", counts_json(st.output_vertices, st.output_triangles))}),
                                stats_tail({}, st.seconds, st.peak_rss_bytes, st.peak_anon_bytes)));
  }
  if (a.quiet) return kOk;
  std::FILE* to = a.output.mesh == "-" || a.stats == "-" ? stderr : stdout;
  print_input_line(to, st.finest_vertices, st.finest_triangles, " (the hierarchy's finest level)");
  std::fprintf(to, "output  %" PRIu64 " vertices, %" PRIu64 " triangles\n", st.output_vertices, st.output_triangles);
  std::fprintf(to, "time    %.3f s\n", st.seconds);
  print_memory_line(to, st.peak_rss_bytes, st.peak_anon_bytes);
  return kOk;
}

}  // namespace oocsimp_cli
