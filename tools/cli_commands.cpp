// The oocsimp subcommands other than simplify: merge, hierarchy, extract, info,
// generate, measure, curvature, lod-select and render. Each is an args struct that
// CLI11 fills, add_<name>_command declaring its options and run_<name> doing the work.
#include "cli_commands.hpp"

#include <filesystem>
#include <system_error>

namespace oocsimp_cli {

// The units of a 4-k record's error (HierarchyRecord::error), which info, hierarchy
// and extract --error share.
const char* const kHierarchyErrorUnits = "area x squared distance, model units^4";

// --- --stats of hierarchy, extract and curvature, in the shape simplify's has: version,
// paths, options, input, the work, output, warnings, seconds and memory.

std::string json_string(const std::string& text);
std::string json_strings(const std::vector<std::string>& list);

void add_stats_option(CLI::App* cmd, std::string* path) {
  cmd->add_option("--stats", *path, "Write statistics as JSON to this file (- for stdout; default: none written)");
}

// Whether two paths name one file: the same text, or both there and the same inode.
bool same_path(const std::string& a, const std::string& b) {
  if (a == b) return true;
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec) && !ec;
}

// Refused before the run (exit 2), as simplify refuses them: a stats file that is the
// input or the output, and both on stdout.
void check_stats_path(const std::string& stats, const std::string& input, const std::string& output) {
  if (stats.empty()) return;
  if (stats == "-" && output == "-") throw UsageError("-o - and --stats - cannot both write to stdout");
  if (stats != "-" && same_path(stats, input)) throw UsageError("--stats " + stats + " is the input " + input);
  if (stats != "-" && same_path(stats, output)) throw UsageError("--stats " + stats + " is the output " + output);
}

// `fields` ("\"name\": value" each) as one JSON object, written after the run worked:
// to stdout for "-", else through a temporary file renamed into place, so a failed
// write leaves no half file.
void write_stats(const std::string& path, const std::vector<std::string>& fields) {
  std::string js = "{\n";
  for (std::size_t k = 0; k < fields.size(); ++k) js += "  " + fields[k] + (k + 1 < fields.size() ? ",\n" : "\n");
  js += "}\n";
  if (path == "-") {
    std::fputs(js.c_str(), stdout);
    std::fflush(stdout);
    return;
  }
  const std::string temp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out << js;
    out.close();
    if (!out) {
      std::remove(temp.c_str());
      throw IoError(path + ": cannot write the statistics");
    }
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    throw IoError(path + ": cannot write the statistics: " + std::strerror(errno));
  }
}

std::string json_field(const char* name, const std::string& value) { return json_string(name) + ": " + value; }

std::string json_count(std::uint64_t n) { return std::to_string(n); }

// A mesh's size as the stats' "input" and "output" give it.
std::string counts_json(std::uint64_t vertices, std::uint64_t triangles) {
  return "{\"vertices\": " + json_count(vertices) + ", \"triangles\": " + json_count(triangles) + "}";
}

// The shortest text that reads back as `v`, as simplify's --stats writes numbers; null
// where JSON has no number.
std::string json_shortest(double v) {
  if (!std::isfinite(v)) return "null";
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

std::string json_bool(bool b) { return b ? "true" : "false"; }

std::vector<std::string> stats_head(const std::string& input, const std::string& output, const std::string& stats) {
  return {json_field("version", json_string(version())),
          json_field("paths", "{\"input\": " + json_string(input) + ", \"output\": " + json_string(output) +
                                  ", \"stats\": " + json_string(stats) + "}")};
}

// Seconds to the microsecond, as simplify's --stats writes them.
std::string json_seconds(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6f", v);
  return text;
}

std::vector<std::string> stats_tail(const std::vector<std::string>& warnings, double seconds,
                                    std::uint64_t peak_rss_bytes, std::uint64_t peak_anon_bytes) {
  return {json_field("warnings", json_strings(warnings)),
          json_field("seconds", "{\"total\": " + json_seconds(seconds) + "}"),
          json_field("memory", "{\"peak_rss_bytes\": " + json_count(peak_rss_bytes) +
                                   ", \"peak_anon_bytes\": " + json_count(peak_anon_bytes) + "}")};
}

std::vector<std::string> joined(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// --- merge

CLI::App* add_merge_command(CLI::App& app, MergeArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "merge", "Finish a run spread over parts (simplify --part I/K --work-dir DIR): the same output as one process");
  cmd->add_option("work-dir", a.dir, "The parts' work folder")->required();
  cmd->add_option("-o,--output", a.outputs.mesh, "Output mesh, as for simplify")->required();
  cmd->add_option("--stats", a.outputs.stats,
                  "Write statistics as JSON to this file (- for stdout; default: none written)");
  cmd->add_flag("--ascii", a.outputs.ascii, "Write ascii PLY or STL instead of binary");
  cmd->add_flag("--normals", a.outputs.normals, "Write per-vertex normals nx, ny, nz, as for simplify");
  add_given(cmd, "--mem", &a.mem,
            "Memory budget of the whole process, as for simplify (default: a quarter of physical memory)");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  add_quiet_flag(cmd, &a.quiet, "No progress and no summary");
  return cmd;
}

int run_merge(const MergeArgs& a) {
  SimplifyOptions o = a.options;
  if (a.threads.given()) o.threads = threads_of(a.threads);
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem, minimum_memory_budget());
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  o.release_memory = release_free_heap;
  o.budget_counts_process = true;
  SimplifyStats stats;
  merge_parts(a.dir, a.outputs, o, &stats);
  // The parts' method, for the summary: a grid for the uniform one, none for the collapse.
  o.method = stats.grid_dims[0] != 0 ? ClusterMethod::uniform : ClusterMethod::qem;
  if (!a.quiet) print_simplify_summary(a.outputs.mesh == "-" || a.outputs.stats == "-" ? stderr : stdout, o, stats);
  print_warnings(stats.warnings);
  return kOk;
}

// --- hierarchy, extract

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

CLI::App* add_extract_command(CLI::App& app, ExtractArgs& a) {
  CLI::App* cmd = app.add_subcommand("extract", "Extract a conforming mesh from a .4k hierarchy");
  cmd->add_option("input", a.in, "Input .4k file (written by oocsimp hierarchy)")->required();
  cmd->add_option("-o,--output", a.out, "Output mesh (PLY, OBJ, STL, OFF, glTF .glb; .zst or .gz compresses)")
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
  cmd->add_flag("--ascii", a.ascii, "Write ascii PLY or STL");
  add_stats_option(cmd, &a.stats);
  add_quiet_flag(cmd, &a.quiet, "No progress and no summary");
  return cmd;
}

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
  check_stats_path(a.stats, a.in, a.out);
  ProgressReporter progress(a.quiet);
  ExtractStats st;
  extract_file(a.in, a.out, a.ascii, q, progress.callback(), &st);
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
             ", \"ascii\": " + json_bool(a.ascii) + ", \"error_units\": " + json_string(kHierarchyErrorUnits) + "}";
    write_stats(a.stats, joined(joined(stats_head(a.in, a.out, a.stats),
                                       {json_field("options", query),
                                        json_field("input", counts_json(st.finest_vertices, st.finest_triangles)),
                                        json_field("output", counts_json(st.output_vertices, st.output_triangles))}),
                                stats_tail({}, st.seconds, st.peak_rss_bytes, st.peak_anon_bytes)));
  }
  if (a.quiet) return kOk;
  std::FILE* to = a.out == "-" || a.stats == "-" ? stderr : stdout;
  print_input_line(to, st.finest_vertices, st.finest_triangles, " (the hierarchy's finest level)");
  std::fprintf(to, "output  %" PRIu64 " vertices, %" PRIu64 " triangles\n", st.output_vertices, st.output_triangles);
  std::fprintf(to, "time    %.3f s\n", st.seconds);
  print_memory_line(to, st.peak_rss_bytes, st.peak_anon_bytes);
  return kOk;
}

// --- info

// A string as a JSON string: quoted, with quotes, backslashes and control bytes escaped.
std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A number as JSON has it: 17 significant digits, and null where JSON has no number.
std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string json_strings(const std::vector<std::string>& list) {
  std::string out = "[";
  for (std::size_t k = 0; k < list.size(); ++k) out += (k ? ", " : "") + json_string(list[k]);
  return out + "]";
}

std::string json_tally(const PrimitiveTally& t) {
  std::string out = "{\"count\": " + std::to_string(t.count);
  if (t.count > 0)
    out += ", \"thickness\": {\"least\": " + json_number(t.least) + ", \"most\": " + json_number(t.most) +
           ", \"mean\": " + json_number(t.sum / double(t.count)) + "}";
  return out + "}";
}

// info --json: what info prints, as one object whose fields scripts can read.
std::string mesh_info_json(const MeshSummary& m) {
  const MeshInfo& i = m.info;
  std::string js = "{\"file\": " + json_string(i.path) + ", \"format\": " + json_string(i.format);
  js += ", \"compression\": " + (i.compressed ? json_string(i.compression) : std::string("null"));
  js += ", \"vertices\": " + std::to_string(i.vertex_count);
  if (i.unwelded_vertex_count) js += ", \"stored_vertices\": " + std::to_string(i.unwelded_vertex_count);
  js += ", \"faces\": " + std::to_string(i.face_count);
  js += ", \"edges\": " + json_tally(m.edges) + ", \"points\": " + json_tally(m.points);
  js += ", \"elements\": " + json_strings(i.elements) + ", \"header_comments\": " + json_strings(i.comments);
  js += std::string(", \"positions_in_place\": ") + (i.positions_in_place ? "true" : "false");
  js += ", \"attributes\": [";
  for (std::size_t k = 0; k < m.attributes.size(); ++k) {
    const VertexAttribute& v = m.attributes[k];
    js += std::string(k ? ", " : "") + "{\"name\": " + json_string(v.name) +
          ", \"type\": " + json_string(attribute_type_name(v.type)) + ", \"min\": " + json_number(v.min) +
          ", \"max\": " + json_number(v.max) +
          ", \"carried_by_clustering\": " + (is_texture_coordinate(v.name) ? "false" : "true") + "}";
  }
  js += "], \"not_carried\": " + json_strings(i.not_carried);
  if (i.bounds.empty()) {
    js += ", \"bounds\": null, \"diagonal\": null";
  } else {
    const Box3d& b = i.bounds;
    js += ", \"bounds\": {\"min\": [" + json_number(b.min.x) + ", " + json_number(b.min.y) + ", " +
          json_number(b.min.z) + "], \"max\": [" + json_number(b.max.x) + ", " + json_number(b.max.y) + ", " +
          json_number(b.max.z) + "]}, \"diagonal\": " + json_number(b.diagonal());
  }
  js += ", \"non_finite_vertices\": " + std::to_string(i.non_finite_vertices);
  if (i.non_finite_vertices > 0)
    js += ", \"first_non_finite_vertex\": {\"index\": " + std::to_string(i.first_non_finite_vertex) +
          ", \"at\": " + json_string(i.first_non_finite_position) + "}";
  return js + "}\n";
}

// info --json of a .4k hierarchy: its counts and levels, errors in kHierarchyErrorUnits.
int print_hierarchy_info_json(const InfoArgs& a) {
  const MeshHierarchy h = read_hierarchy(a.in);
  std::size_t swaps = 0;
  for (const HierarchyRecord& r : h.records) swaps += r.swap;
  std::string js = "{\"file\": " + json_string(a.in) +
                   ", \"format\": \"oocsimp 4-k hierarchy\", \"version\": " + std::to_string(h.file_version) +
                   ", \"positions\": " + (h.precision == ScalarType::f64 ? "\"double\"" : "\"float\"");
  js += ", \"attributes\": [";
  for (std::size_t k = 0; k < h.attributes.attributes.size(); ++k) {
    const VertexAttribute& v = h.attributes.attributes[k];
    js += std::string(k ? ", " : "") + "{\"name\": " + json_string(v.name) +
          ", \"type\": " + json_string(attribute_type_name(v.type)) + "}";
  }
  js += "], \"vertices\": " + std::to_string(h.positions.size() / 3) +
        ", \"faces\": " + std::to_string(h.triangles.size() / 3) +
        ", \"records\": " + std::to_string(h.records.size()) + ", \"swaps\": " + std::to_string(swaps) +
        ", \"height\": " + std::to_string(hierarchy_height(h)) +
        ", \"error_units\": " + json_string(kHierarchyErrorUnits) + ", \"levels\": [";
  for (std::size_t j = 0; j < h.levels.size(); ++j) {
    const HierarchyLevel& l = h.levels[j];
    js += std::string(j ? ", " : "") + "{\"triangles\": " + std::to_string(l.triangles) +
          ", \"vertices\": " + std::to_string(l.vertices) +
          ", \"largest_error\": " + json_number(double(l.largest_error)) + "}";
  }
  std::fputs((js + "]}\n").c_str(), stdout);
  return kOk;
}

CLI::App* add_info_command(CLI::App& app, InfoArgs& a) {
  CLI::App* cmd = app.add_subcommand("info", "Print format, element counts, properties and bounding box");
  cmd->add_option("input", a.in, "Input mesh, or a .4k hierarchy")->required();
  add_tmp_option(cmd, &a.tmp);
  cmd->add_flag("--json", a.json, "Print the description as one JSON object");
  add_quiet_flag(cmd, &a.quiet, "No progress (the description is printed all the same)");
  return cmd;
}

// The thick edges or points: count and the range and mean of their thicknesses.
void print_tally(const char* name, const PrimitiveTally& t) {
  if (t.count > 0 && t.most == 0)
    std::printf("%-9s %" PRIu64 " (no thickness)\n", name, t.count);
  else if (t.count > 0)
    std::printf("%-9s %" PRIu64 " (thickness %.6g to %.6g, mean %.6g)\n", name, t.count, t.least, t.most,
                t.sum / double(t.count));
}

// A .4k hierarchy: its counts and levels.
int run_hierarchy_info(const InfoArgs& a) {
  const MeshHierarchy h = read_hierarchy(a.in);
  std::printf("file      %s\n", a.in.c_str());
  std::printf("format    oocsimp 4-k hierarchy, version %u, positions %s\n", unsigned(h.file_version),
              h.precision == ScalarType::f64 ? "double" : "float");
  if (!h.attributes.empty()) {
    std::printf("attributes");
    for (const VertexAttribute& v : h.attributes.attributes)
      std::printf(" %s (%s)", v.name.c_str(), attribute_type_name(v.type));
    std::printf("\n");
  }
  std::printf("vertices  %zu\n", h.positions.size() / 3);
  std::printf("faces     %zu\n", h.triangles.size() / 3);
  std::size_t swaps = 0;
  for (const HierarchyRecord& r : h.records) swaps += r.swap;
  std::printf("records   %zu (%zu swaps, %zu removals), height %" PRIu64 "\n", h.records.size(), swaps,
              h.records.size() - swaps, hierarchy_height(h));
  std::printf("errors    in %s\n", kHierarchyErrorUnits);
  std::printf("level  triangles   vertices  ratio  largest error\n");
  for (std::size_t j = 0; j < h.levels.size(); ++j) {
    const HierarchyLevel& l = h.levels[j];
    const double ratio = j > 0 ? double(l.triangles) / double(h.levels[j - 1].triangles) : 1.0;
    std::printf("%5zu %10" PRIu64 " %10" PRIu64 "  %.3f  %.6g\n", j, l.triangles, l.vertices, ratio,
                double(l.largest_error));
  }
  return kOk;
}

int run_info(const InfoArgs& a) {
  if (is_hierarchy_file(a.in)) return a.json ? print_hierarchy_info_json(a) : run_hierarchy_info(a);
  MeshSummary m;
  {
    ProgressReporter progress(a.quiet);
    m = describe_mesh(a.in, a.tmp, progress.callback());
  }
  if (a.json) {
    std::fputs(mesh_info_json(m).c_str(), stdout);
    return kOk;
  }
  const MeshInfo& i = m.info;
  std::printf("file      %s\n", i.path.c_str());
  std::printf("format    %s%s%s%s\n", i.format.c_str(), i.compressed ? " (" : "", i.compression.c_str(),
              i.compressed ? ")" : "");
  std::printf("vertices  %" PRIu64, i.vertex_count);
  if (i.unwelded_vertex_count) std::printf(" (welded from %" PRIu64 " stored)", i.unwelded_vertex_count);
  std::printf("\n");
  std::printf("faces     %" PRIu64 "\n", i.face_count);
  print_tally("edges", m.edges);
  print_tally("points", m.points);
  for (const auto& e : i.elements) std::printf("element   %s\n", e.c_str());
  for (const auto& c : i.comments) std::printf("header    %s\n", c.c_str());
  std::printf("positions %s\n", i.positions_in_place ? "read in place (mmap)" : "converted to a temporary array");
  // What simplify carries by default (--attributes all), with the range of each.
  if (m.attributes.empty()) std::printf("attributes none carried\n");
  for (const VertexAttribute& v : m.attributes)
    std::printf("attribute %s %s, carried%s (values %.9g to %.9g)\n", v.name.c_str(), attribute_type_name(v.type),
                is_texture_coordinate(v.name) ? " by the edge collapse, dropped by clustering" : "", v.min, v.max);
  for (const std::string& n : i.not_carried) std::printf("not carried %s\n", n.c_str());
  if (i.bounds.empty()) {
    std::printf("bounds    empty\n");
  } else {
    std::printf("bounds    min %.9g %.9g %.9g\n", i.bounds.min.x, i.bounds.min.y, i.bounds.min.z);
    std::printf("          max %.9g %.9g %.9g\n", i.bounds.max.x, i.bounds.max.y, i.bounds.max.z);
    std::printf("diagonal  %.9g\n", i.bounds.diagonal());
  }
  if (i.non_finite_vertices > 0)
    std::printf("non-finite %" PRIu64
                " (vertices with a NaN or infinite coordinate, ignored; the first: vertex %" PRIu64 " at %s)\n",
                i.non_finite_vertices, i.first_non_finite_vertex, i.first_non_finite_position.c_str());
  return kOk;
}

// --- generate

CLI::App* add_generate_command(CLI::App& app, GenerateArgs& a) {
  CLI::App* cmd = app.add_subcommand("generate", "Write a synthetic dense mesh, streamed in O(1) memory");
  add_given(cmd, "--tris", &a.tris, "Number of triangles (approximately), at least 1")->required();
  const EnumNames<SyntheticShape>& shapes = synthetic_shape_names();
  add_enum_option(cmd, "--shape", &a.options.shape, shapes,
                  std::string("Shape (default ") + name_of(shapes, SyntheticShape::sphere) + "; " +
                      name_of(shapes, SyntheticShape::branches) + ": a leafless tree of thin tubes; " +
                      name_of(shapes, SyntheticShape::boxes) +
                      ": a city block of closed boxes, long thin triangles and zero-area slivers)");
  add_given(cmd, "--seed", &a.seed, "Random seed (default 1)");
  cmd->add_option("-o,--output", a.out, "Output PLY: .ply, or .ply.zst or .ply.gz (compressed), - for stdout")
      ->required();
  cmd->add_flag("--ascii", a.options.ascii, "Write ascii PLY");
  cmd->add_flag("--attributes", a.options.attributes,
                "Also write uchar red, green, blue (linear in x, y, z over the bounding box) and float nx, ny, nz (the "
                "unit surface normal) per vertex");
  add_quiet_flag(cmd, &a.quiet);
  return cmd;
}

// generate writes PLY only: another extension would get PLY bytes under a misleading name.
void check_generate_output(const std::string& out) {
  std::string name = out;
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  auto ends_with = [&](const std::string& ext) {
    return name.size() >= ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  };
  if (out != "-" && !ends_with(".ply") && !ends_with(".ply.zst") && !ends_with(".ply.gz"))
    throw UsageError(out +
                     ": generate writes PLY only: give a name ending in .ply, .ply.zst or .ply.gz (or - for stdout)");
}

int run_generate(const GenerateArgs& a) {
  GenerateOptions o = a.options;
  o.triangles = whole_number("--tris", a.tris.text, 1, kMost);
  if (a.seed.given()) o.seed = whole_number("--seed", a.seed.text, 0, kMost);
  check_generate_output(a.out);
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  const GenerateResult r = generate_mesh(a.out, o);
  if (!a.quiet)
    std::fprintf(a.out == "-" ? stderr : stdout, "%s: %" PRIu64 " vertices, %" PRIu64 " triangles\n", a.out.c_str(),
                 r.vertices, r.triangles);
  return kOk;
}

// --- measure

CLI::App* add_measure_command(CLI::App& app, MeasureArgs& a) {
  CLI::App* cmd = app.add_subcommand("measure", "Hausdorff, mean and RMS distance between two surfaces");
  cmd->add_option("a", a.a, "Mesh A, streamed (the original; any size)")->required();
  cmd->add_option("b", a.b, "Mesh B, loaded into memory (e.g. the simplification)")->required();
  add_given(cmd, "--samples", &a.samples, "Points sampled on each surface (default 1000000)");
  add_given(cmd, "--seed", &a.seed, "Random seed of the samples (default 1)");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  cmd->add_flag("--json", a.json, "Print the report as JSON");
  cmd->add_option("--error-colours", a.options.error_colours,
                  "Write B to this PLY with each vertex's distance to A as property quality and as colours (blue 0 "
                  "to red the largest); render draws it with a legend (default: none written)");
  add_quiet_flag(cmd, &a.quiet);
  return cmd;
}

void print_distance_report(const MeasureArgs& a, const DistanceReport& r) {
  std::printf("A  %s: %" PRIu64 " triangles, area %.6g, bounding-box diagonal %.6g\n", a.a.c_str(), r.a_triangles,
              r.a_area, r.a_diagonal);
  std::printf("B  %s: %" PRIu64 " triangles, area %.6g\n", a.b.c_str(), r.b_triangles, r.b_area);
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
  if (!a.options.error_colours.empty()) {
    const DistanceStats f = r.fraction_of_diagonal(r.b_vertices);
    std::printf("colours    %s: B's %" PRIu64 " vertices by distance to A, 0 to %.6e (%.4e of the diagonal)\n",
                a.options.error_colours.c_str(), r.b_vertices.samples, r.b_vertices.max, f.max);
  }
  std::printf("time %.3f s, peak RSS %.1f MiB, peak anonymous %.1f MiB\n", r.seconds,
              double(r.peak_rss_bytes) / 1048576.0, double(r.peak_anon_bytes) / 1048576.0);
}

int run_measure(const MeasureArgs& a) {
  MeasureOptions o = a.options;
  if (a.samples.given()) o.samples = whole_number("--samples", a.samples.text, 1, kMost);
  if (a.seed.given()) o.seed = whole_number("--seed", a.seed.text, 0, kMost);
  if (a.threads.given()) o.threads = threads_of(a.threads);
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  const DistanceReport r = measure_surface_distance(a.a, a.b, o);
  if (a.json)
    std::fputs(distance_report_to_json(r).c_str(), stdout);
  else
    print_distance_report(a, r);
  return kOk;
}

// --- curvature

CLI::App* add_curvature_command(CLI::App& app, CurvatureArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "curvature", "Principal curvatures k1, k2 of every vertex by integral invariants (Hua et al. §3.4), to PLY");
  cmd->add_option("input", a.in, "Input mesh")->required();
  cmd->add_option("-o,--output", a.out, "Output PLY: the mesh with float vertex properties k1 and k2")->required();
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
  cmd->add_flag("--ascii", a.ascii, "Write ascii PLY");
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
  check_stats_path(a.stats, a.in, a.out);
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  CurvatureStats st;
  curvature_file(a.in, a.out, a.ascii, o, &st);
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
        ", \"ascii\": " + json_bool(a.ascii) + "}";
    const std::string work =
        "{\"radius\": " + json_shortest(st.radius) + ", \"mean_edge_length\": " + json_shortest(st.mean_edge_length) +
        ", \"at_scale\": " + json_shortest(st.at_scale) + ", \"tile_side\": " + json_shortest(st.tile_side) +
        ", \"invariant\": " + json_count(st.invariant) + ", \"fitted\": " + json_count(st.fitted) +
        ", \"none\": " + json_count(st.none) + "}";
    write_stats(
        a.stats,
        joined(joined(stats_head(a.in, a.out, a.stats),
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
  std::fprintf(to, "output  %s: k1 and k2 of %" PRIu64 " vertices\n", a.out.c_str(), st.vertices);
  std::fprintf(to, "time    %.3f s: %.2f M vertices/s\n", st.seconds,
               st.seconds > 0 ? double(st.vertices) / st.seconds / 1e6 : 0.0);
  print_memory_line(to, st.peak_rss_bytes, st.peak_anon_bytes);
  return kOk;
}

// --- lod-select

CLI::App* add_lod_select_command(CLI::App& app, LodSelectArgs& a) {
  CLI::App* cmd = app.add_subcommand("lod-select", "Pick the level of detail for a viewing distance (Low & Tan §4)");
  cmd->add_option("lods", a.lods, "OUT.lods.json, written by simplify --lods")->required();
  cmd->add_option("--distance", a.distance, "Distance from the camera, model units")->required();
  cmd->add_option("--fov", a.fov, "Vertical field of view, degrees")->required();
  cmd->add_option("--height", a.height, "Image height, pixels")->required();
  cmd->add_option("--factor", a.factor, "Pixels a cell may span, at least 1 (default 5)");
  cmd->add_flag("--json", a.json, "Print the choice as JSON");
  return cmd;
}

// Low & Tan §4: the level for a viewing distance. X defaults to 5, the accurate end of
// the paper's 5-10 (a higher X trades visual accuracy for speed).
int run_lod_select(const LodSelectArgs& a) {
  // The numbers first: a mistyped one is refused before the file is read.
  const double r = pixel_size_at(positive_number("--distance", a.distance), positive_number("--fov", a.fov, 179.999),
                                 double(whole_number("--height", a.height, 1, 1u << 20)));
  const double x = a.factor.empty() ? 5.0 : positive_number("--factor", a.factor);
  if (x < 1) bad_value("--factor", a.factor, "a number of at least 1");
  const std::vector<LodLevel> levels = read_lod_levels(a.lods);
  const LodChoice c = choose_lod(levels, r, x);
  const LodLevel& l = levels[c.level];
  if (a.json) {
    std::puts(lod_choice_json(levels, c, r, x).c_str());
    return kOk;
  }
  std::printf("level      %zu: %s (cell %.6g)%s\n", c.level, l.file.c_str(), l.cell,
              c.finest_too_coarse ? ", the finest there is: its cell spans more than the factor's pixels" : "");
  std::printf("pixel      %.6g model units (R = 2 D tan(FOV/2) / H); cells up to %.6g (factor %g)\n", r, x * r, x);
  std::printf("thick line T / R = T x %.6g pixels for an edge of thickness T\n", 1 / r);
  return kOk;
}

// --- render

CLI::App* add_render_command(CLI::App& app, RenderArgs& a) {
  CLI::App* cmd = app.add_subcommand("render", "Draw a mesh file into a PNG or JPEG (software rasteriser, streamed)");
  cmd->add_option("input", a.in, "Mesh file (PLY, OBJ, STL, OFF, glTF .glb, optionally .zst or .gz)")->required();
  cmd->add_option("-o,--output", a.out, "Picture file: .png, or .jpg / .jpeg for JPEG")->required();
  cmd->add_option("--size", a.size, "Image size WIDTHxHEIGHT (default 1024x768)");
  cmd->add_option("--view", a.view,
                  "Camera direction AZIMUTH,ELEVATION in degrees (default 30,20; 0,90 looks straight down)");
  add_enum_option(cmd, "--up", &a.options.up, up_axis_names(),
                  "The model's up axis: auto (the default: the way the surface faces, else z), z, y (y-up scans, glTF) "
                  "or x; --view turns about it");
  add_enum_option(
      cmd, "--shading", &a.options.shading, shading_names(),
      value_list(shading_names(), {{Shading::flat, "default"}, {Shading::smooth, "the file's vertex normals"}}));
  cmd->add_flag("--thick-edges", a.options.thick_edges,
                "Draw edges T/R pixels wide and points as discs T/R across (T their thickness, R the pixel size; Low "
                "& Tan 1997 sec. 3.3); one pixel wide without");
  add_tmp_option(cmd, &a.tmp);
  add_quiet_flag(cmd, &a.quiet, "No progress or summary");
  return cmd;
}

// "WxH" and "AZ,EL" of render.
void parse_render_args(const std::string& size, const std::string& view, RenderOptions* o) {
  if (!size.empty()) {
    const std::size_t x = size.find('x');
    if (x == std::string::npos) bad_value("--size", size, "WIDTHxHEIGHT, e.g. 1024x768");
    o->width = std::uint32_t(whole_number("--size", size.substr(0, x), 1, 16384));
    o->height = std::uint32_t(whole_number("--size", size.substr(x + 1), 1, 16384));
  }
  if (!view.empty()) {
    const std::size_t comma = view.find(',');
    if (comma == std::string::npos) bad_value("--view", view, "AZIMUTH,ELEVATION in degrees, e.g. 30,20");
    auto angle = [&](const std::string& text) {
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0' || !std::isfinite(v)) bad_value("--view", view, "two finite numbers of degrees");
      return v;
    };
    o->azimuth_degrees = angle(view.substr(0, comma));
    o->elevation_degrees = angle(view.substr(comma + 1));
  }
}

int run_render(const RenderArgs& a) {
  RenderOptions o = a.options;
  parse_render_args(a.size, a.view, &o);
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  const auto t0 = std::chrono::steady_clock::now();
  const RenderStats s = render_file(a.in, a.out, o, a.tmp);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!a.quiet)
    std::fprintf(stderr,
                 "render  %" PRIu64 " triangles, %" PRIu64 " edges, %" PRIu64 " points, %ux%u pixels (%" PRIu64
                 " covered, %.3g model units each), %s up%s%s, %.3f s\n",
                 s.triangles, s.edges, s.points, o.width, o.height, s.covered_pixels, s.pixel_size,
                 name_of(up_axis_names(), s.up), o.up == UpAxis::automatic ? " (auto)" : "",
                 s.legend ? ", error colours with their legend" : "", seconds);
  return kOk;
}

}  // namespace oocsimp_cli
