// oocsimp command line: a thin layer over the library (include/oocsimp/).
//
// Each subcommand is an args struct that CLI11 fills, add_<name>_command declaring its
// options and run_<name> doing the work; main parses, dispatches and maps failures to
// exit codes: 0 ok, 2 usage, 3 bad input, 4 I/O or resource failure.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "oocsimp/oocsimp.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/lod.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/progress_reporter.hpp"
#include "oocsimp/render.hpp"
#include "mpi_run.hpp"

using namespace oocsimp;

namespace {

enum ExitCode { kOk = 0, kUsage = 2, kBadInput = 3, kIo = 4 };

// --- Option fields shown as flags.

// The library names an option by its field ("options.memory_budget"); the command
// line shows the flag that sets it. The one table of that mapping, for errors and
// warnings alike.
constexpr std::pair<const char*, const char*> kFlagOfField[] = {
    {"options.floating.tile_side", "--tile"},
    {"options.floating.keep_temp", "--keep-tmp"},
    {"options.memory_budget", "--mem"},
    {"options.sizing.cell", "--cell"},
    {"options.sizing.grid", "--grid"},
    {"options.sizing.ratio", "--ratio"},
    {"options.attributes", "--attributes"},
    {"options.temp_dir", "--tmp"},
    {"options.target.triangles", "--target-tris"},
    {"options.target.ratio", "--target-ratio"},
    {"options.target.max_error", "--max-error"},
    {"options.target.intermediate_factor", "--intermediate-factor"},
    {"options.thick_edges", "--thick-edges"},
    {"options.lock_boundary", "--lock-boundary"},
    {"options.locked_vertices", "--lock-vertices"},
    {"options.method", "--method"},
    {"options.lods.levels", "--lods"},
    {"options.lods.factor", "--lod-factor"},
    {"options.lods", "--lods"},
    {"options.triangles", "--tris"},
    {"options.samples", "--samples"},
    {"options.radius", "--radius"},
    {"options.curvature.radius", "--radius"},
    {"options.curvature.tolerance", "--curvature-tolerance"},
    {"options.curvature.max_depth", "--max-depth"},
    {"options.curvature.representative", "--rep"},
    {"options.floating.representative", "--rep"},
    {"options.tile_side", "--tile"},
    {"outputs.replace_input", "--force"},
    {"outputs.stats", "--stats"},
    {"outputs.mesh", "-o"},
    {"query.level", "--level"},
    {"query.triangles", "--tris"},
    {"query.error", "--error"},
    {"query.radius", "--sphere"},
    {"query.box", "--box"},
    {"query.region", "the region"},
    {"query", "extract"},
    {"options.level_ratio", "--level-ratio"},
    {"options.sets_per_level", "--sets"},
};

// A character that continues a name or a path.
bool continues_name(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '/' || c == '.';
}

// Whether text[at, end) stands as a name of its own: not part of a path or of a
// longer field ("options.lods" in "options.lods.levels"). A full stop after it ends
// a sentence.
bool stands_alone(const std::string& text, std::size_t at, std::size_t end) {
  if (at > 0 && continues_name(text[at - 1])) return false;
  if (end == text.size() || !continues_name(text[end])) return true;
  return text[end] == '.' && (end + 1 == text.size() || !continues_name(text[end + 1]));
}

// The row of kFlagOfField whose field stands at text[at], or null.
const std::pair<const char*, const char*>* field_at(const std::string& text, std::size_t at) {
  for (const auto& row : kFlagOfField) {
    const std::size_t end = at + std::strlen(row.first);
    if (text.compare(at, end - at, row.first) == 0 && stands_alone(text, at, end)) return &row;
  }
  return nullptr;
}

// `text` with each option field it names shown as its flag (advice names fields
// anywhere: "give options.memory_budget 512 MiB or more, or a larger options.sizing.cell").
std::string with_flags(const std::string& text) {
  std::string shown;
  for (std::size_t at = 0; at < text.size();) {
    if (const auto* row = field_at(text, at)) {
      shown += row->second;
      at += std::strlen(row->first);
    } else {
      shown += text[at++];
    }
  }
  return shown;
}

// --- Checked option values: every size and count is refused (exit 2, naming the flag
// and the value) rather than replaced by a default. CLI11 reads "-5" into an unsigned
// without complaint, so numbers are taken as text and parsed here.

[[noreturn]] void bad_value(const std::string& flag, const std::string& text, const std::string& expected) {
  throw UsageError(flag + " \"" + text + "\": expected " + expected);
}

double positive_number(const std::string& flag, const std::string& text, double max = HUGE_VAL) {
  char* end = nullptr;
  double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v) || !(v > 0) || v > max) {
    char range[64];
    std::snprintf(range, sizeof range, "a number above 0 and at most %g", max);
    bad_value(flag, text, max == HUGE_VAL ? "a positive finite number" : range);
  }
  return v;
}

// A count: digits, or a number with an exponent or a decimal suffix k, M or G (10^3,
// 10^6, 10^9: "10k", "2.5M", "1e6") that comes to a whole number.
std::uint64_t whole_number(const std::string& flag, const std::string& text, std::uint64_t min, std::uint64_t max) {
  std::uint64_t v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  bool ok = !text.empty() && text[0] != '-' && r.ec == std::errc() && r.ptr == text.data() + text.size();
  if (!ok && !text.empty() && text[0] != '-') {
    std::string number = text;
    double scale = 1;
    const char last = number.back();
    if (last == 'k' || last == 'K' || last == 'M' || last == 'G') {
      scale = last == 'G' ? 1e9 : last == 'M' ? 1e6 : 1e3;
      number.pop_back();
    }
    char* end = nullptr;
    const double x = std::strtod(number.c_str(), &end) * scale;
    // Below 2^53 every whole number is exact in a double.
    ok = !number.empty() && *end == '\0' && std::isfinite(x) && x >= 0 && x < 9007199254740992.0 && x == std::floor(x);
    if (ok) v = std::uint64_t(x);
  }
  if (!ok || v < min || v > max)
    bad_value(
        flag, text,
        "a whole number from " + std::to_string(min) + " to " + std::to_string(max) + " (digits, or 10k, 2.5M, 1e6)");
  return v;
}

constexpr std::uint64_t kMost = ~std::uint64_t(0);
constexpr std::uint64_t kMaxThreads = 65536;

// An option taken as text and checked after parsing: whether the user gave it, and what.
struct Given {
  CLI::Option* option = nullptr;
  std::string text;
  bool given() const { return option && option->count() > 0; }
};

CLI::Option* add_given(CLI::App* app, const std::string& flag, Given* g, const std::string& help) {
  return g->option = app->add_option(flag, g->text, help);
}

// --- Enum options: their values are spelled by the library's tables (EnumNames).

template <class E>
std::vector<std::string> names_of(const EnumNames<E>& names) {
  std::vector<std::string> spelled;
  for (const EnumName<E>& n : names) spelled.push_back(n.name);
  return spelled;
}

// An option taking one of the spellings in `names` into `value`: CLI11 checks the text
// (its help and its error list the spellings, "{cube,sphere}"), the table converts it.
template <class E>
CLI::Option* add_enum_option(CLI::App* app, const std::string& flag, E* value, const EnumNames<E>& names,
                             const std::string& help) {
  return app
      ->add_option_function<std::string>(
          flag, [value, &names](const std::string& text) { value_named(names, text, value); }, help)
      ->check(CLI::IsMember(names_of(names)));
}

// "a (note), b or c (note)": `values` in their order as `names` spells them, each with
// its note when it has one.
template <class E>
std::string value_list(const EnumNames<E>& names, std::initializer_list<std::pair<E, const char*>> values) {
  std::string list;
  std::size_t k = 0;
  for (const auto& [value, note] : values) {
    if (k > 0) list += k + 1 == values.size() ? " or " : ", ";
    list += name_of(names, value);
    if (note) list += std::string(" (") + note + ")";
    ++k;
  }
  return list;
}

// --- Options several subcommands take.

void add_tmp_option(CLI::App* app, std::string* dir) {
  app->add_option("--tmp", *dir, "Folder for temporary files (default $TMPDIR or /tmp)");
}

void add_threads_option(CLI::App* app, Given* threads) {
  add_given(app, "--threads", threads, "Worker threads (default: all cores)");
}

unsigned threads_of(const Given& threads) { return unsigned(whole_number("--threads", threads.text, 1, kMaxThreads)); }

void add_quiet_flag(CLI::App* app, bool* quiet, const std::string& help = "No progress") {
  app->add_flag("--quiet", *quiet, help);
}

// The bytes --mem gives; a bad size exits 2 naming --mem.
std::uint64_t memory_budget_of(const Given& mem) {
  try {
    return parse_byte_size(mem.text);
  } catch (const UsageError& e) {
    throw UsageError(std::string("--mem: ") + e.what());
  }
}

// --- simplify

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

// The size of the output: cell, grid or ratio, or an exact target, and levels of detail.
void add_size_options(CLI::App* cmd, SimplifyArgs& a) {
  add_given(cmd, "--cell", &a.cell, "Cell side in model units");
  add_given(cmd, "--grid", &a.grid,
            "Cells along the longest bounding-box axis, 1 to " + std::to_string(kMaxGridDivisions));
  add_given(cmd, "--ratio", &a.ratio, "Approximate fraction of the triangles to keep, in (0, 1] (default 0.1)");
  a.cell.option->excludes(a.grid.option)->excludes(a.ratio.option);
  a.grid.option->excludes(a.ratio.option);
  add_given(cmd, "--target-tris", &a.target_tris,
            "Exactly this many output triangles (at least 4): clustering to a few times that, then quadric edge "
            "collapse");
  add_given(cmd, "--target-ratio", &a.target_ratio, "Exactly this fraction of the input's triangles");
  add_given(cmd, "--max-error", &a.max_error,
            "Stop collapsing before an error above this, in model units (with or without a count)");
  a.refine = add_enum_option(
      cmd, "--refine", &a.options.target.refine, refine_method_names(),
      "With a target: " +
          value_list(refine_method_names(),
                     {{RefineMethod::qem, "edge collapse to it exactly, the default"},
                      {RefineMethod::none, "clustering alone, at a cell chosen for about the target"}}));
  add_given(cmd, "--lods", &a.lods,
            "Write K levels of detail OUT.lod0 ... OUT.lod{K-1} at cells C, C*F, C*F^2, ... and their description "
            "OUT.lods.json (floating cells bin and grade once); with a target, at the target halved per level, "
            "each going on from the finer level's edge collapse");
  add_given(cmd, "--lod-factor", &a.lod_factor, "With --lods: the cell grows F times a level (default 2)");
  cmd->add_flag("--measure", a.measure,
                "With --lods: measure each level's RMS and Hausdorff distance to the input (oocsimp measure's "
                "symmetric figures) into OUT.lods.json");
  add_given(cmd, "--intermediate-factor", &a.intermediate_factor,
            "With a target: phase 1 clusters to about this many times the target, at least 1 (default 4; less when "
            "--mem cannot hold that)");
}

// The floating method's own options: refused with another method.
void add_floating_options(CLI::App* cmd, SimplifyArgs& a) {
  FloatingOptions& f = a.options.floating;
  a.floating_only = {
      add_enum_option(cmd, "--cell-shape", &f.cell_shape, cell_shape_names(),
                      std::string("Cell shape (default ") + cell_shape_name(CellShape::cube) + ")"),
      add_enum_option(cmd, "--assign", &f.assign, assign_rule_names(),
                      "Vertex in several cells: " +
                          value_list(assign_rule_names(),
                                     {{AssignRule::nearest, "centre, the default"}, {AssignRule::heaviest, nullptr}})),
      add_given(cmd, "--tile", &a.tile,
                "Tile side in model units (default: from --mem); refused when the tiles' buffers (9 KiB each) "
                "exceed a quarter of --mem"),
      cmd->add_flag("--keep-tmp", f.keep_temp,
                    "Keep the binned tiles in --tmp and reuse them on the next run of the same input"),
      add_enum_option(
          cmd, "--spill-compress", &f.spill_compression, spill_compression_names(),
          "zstd on the triangle, stitch and kept-triangle spills: " +
              value_list(spill_compression_names(),
                         {{SpillCompression::automatic,
                           "when they would not fit in half the available memory, or with --keep-tmp, the default"},
                          {SpillCompression::zstd, nullptr},
                          {SpillCompression::none, nullptr}})),
  };
  for (CLI::Option* o : a.floating_only)
    o->group("Floating method only (--method floating, the default without a target)");
  a.rep = add_enum_option(cmd, "--rep", &a.representative, representative_rule_names(),
                          "Where a cluster's vertex goes: floating takes quadric (the default), centre or mean; "
                          "curvature takes quadric (the default) or vertex (the paper's: the input vertex that matches "
                          "its cell's curvature with the least quadric error)");
  a.rep->group("Floating and curvature methods");
}

// The curvature method's own options: refused with another method.
void add_curvature_options(CLI::App* cmd, SimplifyArgs& a) {
  a.curvature_only = {
      add_given(cmd, "--radius", &a.radius,
                "Radius of the integral invariants' ball or sphere, model units (default 5 mean edge lengths)"),
      cmd->add_option("--neighbourhood", a.neighbourhood,
                      "ball (the default: the ball cut by the solid) or sphere (the sphere cut by it)")
          ->check(CLI::IsMember({"ball", "sphere"})),
      add_given(cmd, "--curvature-tolerance", &a.curvature_tolerance,
                "A cell of side s is split where a vertex's curvature differs from the cell's mean by more than "
                "this / s (default 0.5)"),
      add_given(cmd, "--max-depth", &a.max_depth, "Splits of a grid cell, 0 to 6 (default 3)"),
  };
  for (CLI::Option* o : a.curvature_only) o->group("Curvature method only (--method curvature)");
}

CLI::App* add_simplify_command(CLI::App& app, SimplifyArgs& a) {
  CLI::App* cmd =
      app.add_subcommand("simplify", "Simplify a mesh file (PLY, OBJ, STL, OFF, glTF .glb, optionally .zst or .gz)");
  cmd->footer(
      "Give at most one of --cell, --grid and --ratio; without any, --ratio 0.1 (keep about a tenth of the "
      "triangles).\n");
  cmd->add_option("input", a.in, "Input mesh")->required();
  cmd->add_option("-o,--output", a.outputs.mesh,
                  "Output mesh; the format from the name: .ply, .obj, .stl, .off or .glb, + .zst compresses; - writes "
                  "binary PLY to stdout")
      ->required();
  add_size_options(cmd, a);
  add_enum_option(cmd, "--method", &a.options.method, cluster_method_names(),
                  value_list(cluster_method_names(),
                             {{ClusterMethod::automatic, "the default: qem with a target, floating without"},
                              {ClusterMethod::floating, "Low & Tan; with a target, clustering then collapse"},
                              {ClusterMethod::uniform, "OoCS grid; the same"},
                              {ClusterMethod::curvature,
                               "Hua et al.: grid cells split where principal curvatures differ, one cluster per "
                               "connected part of a cell; the same"},
                              {ClusterMethod::qem,
                               "edge collapse, out of core in tiles on a large input; with a target or --ratio's "
                               "default share, exactly"}}));
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  cmd->add_option("--stats", a.outputs.stats, "Write statistics as JSON to this file (- for stdout)");
  cmd->add_flag("--force", a.outputs.replace_input,
                "Allow the output to be the input (replaced only after a successful run)");
  add_quiet_flag(cmd, &a.quiet, "No progress and no summary");
  cmd->add_flag("--ascii", a.outputs.ascii, "Write ascii PLY or STL instead of binary");
  cmd->add_flag(
      "--normals", a.outputs.normals,
      "Write per-vertex normals nx, ny, nz (area-weighted from the output's triangles; carried ones replaced)");
  cmd->add_flag("--lock-boundary", a.options.lock_boundary,
                "Leave every vertex on the mesh's boundary (an edge of one face) where it is: open borders and holes "
                "keep their exact outline (the edge collapse, the default with a target, and floating cells without "
                "one)");
  cmd->add_option("--lock-vertices", a.lock_vertices,
                  "A text file of input vertex indices (from 0, separated by blanks or lines, # comments) that stay "
                  "where they are: fixed in the edge collapse, each its own cluster in clustering");
  cmd->add_flag("--thick-edges", a.options.thick_edges,
                "Keep parts thinner than a cell as thick edges and points (Low & Tan 1997 sec. 3.3; PLY element "
                "edge and point with a thickness, OBJ l and p lines)");
  add_enum_option(
      cmd, "--precision", &a.options.precision, precision_names(),
      "Output coordinates: " +
          value_list(precision_names(),
                     {{Precision::float32, nullptr},
                      {Precision::float64, nullptr},
                      {Precision::automatic, "double when the input holds more than float precision, the default"}}));
  add_given(cmd, "--mem", &a.mem,
            "Memory budget of the whole process (its anonymous memory, output tables included), e.g. 256M or 2G, "
            "at least 32M (default: a quarter of physical memory)");
  cmd->add_option("--attributes", a.attributes,
                  "Vertex attributes to carry: all (the default), none, or NAME,NAME... (as info lists them)");
  cmd->add_flag("--weld", a.options.weld, "Merge PLY/OBJ vertices at exactly the same position (STL always is)");
  add_floating_options(cmd, a);
  add_curvature_options(cmd, a);
  add_given(cmd, "--part", &a.part,
            "I/K: run part I (0 to K-1) of a run spread over K processes, leaving its share in --work-dir for "
            "oocsimp merge (any method, with or without a target; not with thick edges, locks or --lods: see "
            "docs/cluster.md)")
      ->group("Distributed runs");
  cmd->add_option("--work-dir", a.work_dir, "With --part: the folder shared by the parts and the merge")
      ->group("Distributed runs");
  return cmd;
}

// Given with another method, the floating-only options would do nothing.
void refuse_floating_only(const std::vector<CLI::Option*>& floating_only, const SimplifyOptions& options) {
  const std::string method = method_name(resolved_method(options));
  const std::string why = options.method == ClusterMethod::automatic ? " (the default with a target)" : "";
  for (const CLI::Option* o : floating_only)
    if (o->count() > 0)
      throw UsageError(o->get_name() + " applies to --method floating only, not to --method " + method + why);
}

void refuse_curvature_only(const std::vector<CLI::Option*>& curvature_only, const SimplifyOptions& options) {
  const std::string method = method_name(resolved_method(options));
  for (const CLI::Option* o : curvature_only)
    if (o->count() > 0)
      throw UsageError(o->get_name() + " applies to --method curvature only, not to --method " + method);
}

// --rep for the method that takes it: floating's rules or curvature's.
void set_representative(const SimplifyArgs& a, SimplifyOptions* o) {
  if (a.rep->count() == 0) return;
  const ClusterMethod m = resolved_method(*o);
  const RepresentativeRule r = a.representative;
  const std::string name = representative_name(r);
  if (m == ClusterMethod::floating) {
    if (r == RepresentativeRule::vertex)
      throw UsageError("--rep vertex applies to --method curvature; floating takes quadric, centre or mean");
    o->floating.representative = r;
  } else if (m == ClusterMethod::curvature) {
    if (r != RepresentativeRule::vertex && r != RepresentativeRule::quadric)
      throw UsageError("--rep " + name + " applies to --method floating; curvature takes vertex or quadric");
    o->curvature.representative = r;
  } else {
    throw UsageError(std::string("--rep applies to --method floating or curvature, not to --method ") + method_name(m));
  }
}

// What simplify runs with, checked.
struct SimplifyPlan {
  SimplifyOptions options;
  LodOptions lod;
  PartOptions part;  // count 1 and no folder: one process
};

// Checks the options given as text into a SimplifyPlan, each refused with its flag.
// --lock-vertices FILE: vertex indices from 0, separated by blanks or line ends, with
// "#" comments. A word that is no index exits 3 naming the file and line.
std::vector<std::uint64_t> read_vertex_list(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open: " + std::strerror(errno));
  std::vector<std::uint64_t> out;
  std::string line;
  for (std::uint64_t number = 1; std::getline(in, line); ++number) {
    const char* p = line.data();
    const char* end = p + std::min(line.size(), line.find('#'));
    while (p < end) {
      while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
      const char* word = p;
      while (p < end && !std::isspace(static_cast<unsigned char>(*p))) ++p;
      if (word == p) break;
      std::uint64_t v = 0;
      const auto r = std::from_chars(word, p, v);
      if (r.ec != std::errc() || r.ptr != p)
        throw InputError(path + ": line " + std::to_string(number) + ": \"" + std::string(word, p).substr(0, 32) +
                         "\" is no vertex index (expected a whole number from 0)");
      out.push_back(v);
    }
  }
  return out;
}

SimplifyPlan check_simplify_args(const SimplifyArgs& a) {
  SimplifyPlan p{a.options, {}, {}};
  SimplifyOptions& o = p.options;
  if (a.target_tris.given()) o.target.triangles = whole_number("--target-tris", a.target_tris.text, 4, kMost);
  if (a.target_ratio.given()) o.target.ratio = positive_number("--target-ratio", a.target_ratio.text, 1.0);
  if (!a.lock_vertices.empty()) o.locked_vertices = read_vertex_list(a.lock_vertices);
  if (a.max_error.given()) o.target.max_error = positive_number("--max-error", a.max_error.text);
  if (resolved_method(o) != ClusterMethod::floating) refuse_floating_only(a.floating_only, o);
  if (resolved_method(o) != ClusterMethod::curvature) refuse_curvature_only(a.curvature_only, o);
  set_representative(a, &o);
  if (a.radius.given()) o.curvature.radius = positive_number("--radius", a.radius.text);
  o.curvature.sphere_neighbourhood = a.neighbourhood == "sphere";
  if (a.curvature_tolerance.given())
    o.curvature.tolerance = positive_number("--curvature-tolerance", a.curvature_tolerance.text);
  if (a.max_depth.given()) o.curvature.max_depth = std::uint32_t(whole_number("--max-depth", a.max_depth.text, 0, 6));
  if (a.refine->count() > 0 && !o.target.given())
    throw UsageError("--refine applies with a target: give --target-tris, --target-ratio or --max-error");
  if (a.intermediate_factor.given()) {
    if (!o.target.given())
      throw UsageError(
          "--intermediate-factor applies with a target: give --target-tris, --target-ratio or --max-error");
    o.target.intermediate_factor = positive_number("--intermediate-factor", a.intermediate_factor.text);
  }
  // Both shape a clustering phase 1, which qem does not run.
  if (resolved_method(o) == ClusterMethod::qem && (a.refine->count() > 0 || a.intermediate_factor.given()))
    throw UsageError(
        std::string(a.refine->count() > 0 ? "--refine" : "--intermediate-factor") +
        " applies to a clustering method with a target (--method floating, uniform or curvature), not to --method "
        "qem" +
        (o.method == ClusterMethod::automatic ? " (the default with a target)" : ""));
  o.attributes = parse_attribute_selection(a.attributes);
  if (a.cell.given()) o.sizing.cell = positive_number("--cell", a.cell.text);
  if (a.grid.given()) o.sizing.grid = std::uint32_t(whole_number("--grid", a.grid.text, 1, kMaxGridDivisions));
  if (a.ratio.given()) o.sizing.ratio = positive_number("--ratio", a.ratio.text, 1.0);
  if (a.tile.given()) o.floating.tile_side = positive_number("--tile", a.tile.text);
  if (a.threads.given()) o.threads = threads_of(a.threads);
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem);
  if (a.lods.given()) p.lod.levels = std::uint32_t(whole_number("--lods", a.lods.text, 1, 16));
  if (a.lod_factor.given()) {
    if (!a.lods.given()) throw UsageError("--lod-factor applies with --lods");
    p.lod.factor = positive_number("--lod-factor", a.lod_factor.text);
    if (!(p.lod.factor > 1)) bad_value("--lod-factor", a.lod_factor.text, "a number above 1");
  }
  if (a.measure && !a.lods.given()) throw UsageError("--measure applies with --lods (use oocsimp measure otherwise)");
  if (a.part.given()) {
    unsigned index = 0, count = 0;
    char end = 0;
    if (std::sscanf(a.part.text.c_str(), "%u/%u%c", &index, &count, &end) != 2 || count < 1 || index >= count)
      bad_value("--part", a.part.text, "I/K with 0 <= I < K, e.g. 0/4");
    if (a.work_dir.empty()) throw UsageError("--part needs --work-dir, the folder shared by the parts and the merge");
    if (a.lods.given()) throw UsageError("--part and --lods: a distributed run makes one level for now");
    p.part.index = index;
    p.part.count = count;
    p.part.work_dir = a.work_dir;
  } else if (!a.work_dir.empty() && !oocsimp_cli::launched_by_mpi()) {
    throw UsageError("--work-dir applies with --part or under mpirun");
  }
  return p;
}

// What the run did differently from what was asked, and what the input lost: not
// silenced by --quiet.
void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::fprintf(stderr, "oocsimp: warning: %s\n", with_flags(w).c_str());
}

// The last part of a path: level files are named in their description relative to it.
std::string base_name(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// Level k as its description lists it (with --measure, measured against the input).
LodLevel describe_level(const SimplifyArgs& a, const SimplifyOptions& o, const SimplifyStats& s, std::uint32_t k) {
  LodLevel l;
  l.file = base_name(lod_level_path(a.outputs.mesh, k));
  l.cell = s.lod_cell;
  l.vertices = s.output_vertices;
  l.triangles = s.output_triangles;
  l.edges = s.output_edges;
  l.points = s.output_points;
  l.seconds = s.seconds_total;
  for (const PhaseTime& p : s.phases) l.phases.push_back({p.name, p.seconds});
  if (a.measure) {
    MeasureOptions m;
    m.threads = o.threads;
    m.temp_dir = o.temp_dir;
    m.progress = o.progress;
    const DistanceReport r = measure_surface_distance(a.in, lod_level_path(a.outputs.mesh, k), m);
    l.rms = r.symmetric.rms;
    l.hausdorff = r.symmetric.max;
  }
  return l;
}

// The description OUT.lods.json of the levels just written, and a line per level.
void describe_levels(const SimplifyArgs& a, const SimplifyOptions& o, const std::vector<SimplifyStats>& stats,
                     const std::string& description) {
  std::vector<LodLevel> levels;
  for (std::uint32_t k = 0; k < stats.size(); ++k) levels.push_back(describe_level(a, o, stats[k], k));
  write_lod_levels(description, levels);
  if (!a.quiet) {
    double total = 0;
    for (std::size_t k = 0; k < levels.size(); ++k) {
      const LodLevel& l = levels[k];
      total += l.seconds;
      char measured[96] = "";
      if (l.rms >= 0) std::snprintf(measured, sizeof measured, ", RMS %.3g, Hausdorff %.3g", l.rms, l.hausdorff);
      std::printf("level %zu  %s: cell %.6g, %" PRIu64 " vertices, %" PRIu64 " triangles, %" PRIu64 " edges, %" PRIu64
                  " points, %.3f s%s\n",
                  k, lod_level_path(a.outputs.mesh, std::uint32_t(k)).c_str(), l.cell, l.vertices, l.triangles, l.edges,
                  l.points, l.seconds, measured);
    }
    std::printf("levels  %zu in %.3f s, described in %s\n", levels.size(), total, description.c_str());
  }
  for (const SimplifyStats& s : stats) print_warnings(s.warnings);
}

// simplify --lods: the levels, then (with --measure) each against the input, then the
// description OUT.lods.json, and a line per level.
int run_simplify_lods(const SimplifyArgs& a, const SimplifyPlan& p) {
  std::vector<SimplifyStats> stats;
  simplify_lods_file(a.in, a.outputs, p.options, p.lod, &stats);
  // The levels are in place now: a description of the ones they replaced must not
  // outlive a failure to describe them (measuring or writing).
  const std::string description = lod_description_path(a.outputs.mesh);
  try {
    describe_levels(a, p.options, stats, description);
  } catch (...) {
    std::remove(description.c_str());
    throw;
  }
  return kOk;
}

// "open 0.012, bin 0.100, ...": the seconds of each phase.
std::string phase_times(const std::vector<PhaseTime>& phases) {
  std::string list;
  for (const PhaseTime& p : phases) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s %.3f", list.empty() ? "" : ", ", p.name.c_str(), p.seconds);
    list += buf;
  }
  return list;
}

// The floating method's tiles and its spill's parts that exist: on disk, in memory or both.
void print_tiles(std::FILE* to, const SimplifyStats& stats) {
  char disk[96] = "", memory[64] = "";
  if (stats.floating.spill_bytes)
    std::snprintf(disk, sizeof disk, ", spill %.1f MiB on disk (%.1f MiB raw)",
                  double(stats.floating.spill_bytes) / 1048576.0, double(stats.floating.spill_raw_bytes) / 1048576.0);
  if (stats.floating.spill_bytes_in_memory)
    std::snprintf(memory, sizeof memory, ", %.1f MiB of spill held in memory",
                  double(stats.floating.spill_bytes_in_memory) / 1048576.0);
  std::fprintf(to, "tiles   %" PRIu64 " tiles%s, %" PRIu64 " rounds%s%s\n", stats.floating.tiles,
               stats.floating.resumed ? " (kept by an earlier run)" : "", stats.floating.rounds, disk, memory);
}

void print_simplify_summary(std::FILE* to, const SimplifyOptions& o, const SimplifyStats& stats) {
  const ClusterMethod method = resolved_method(o);
  if (method == ClusterMethod::floating) print_tiles(to, stats);
  if (o.target.given() || method == ClusterMethod::qem)
    std::fprintf(
        to, "refine  %" PRIu64 " intermediate triangles, %" PRIu64 " collapses, largest error %.3g (cost %.3g)%s\n",
        stats.refine.intermediate_triangles, stats.refine.collapses, stats.refine.largest_collapse_error,
        stats.refine.largest_collapse_cost, stats.refine.target_missed ? ", target missed" : "");
  if (stats.refine.passes) {
    std::string counts = std::to_string(stats.input_triangles);
    for (std::uint64_t n : stats.refine.pass_triangles) counts += " -> " + std::to_string(n);
    std::fprintf(to, "passes  %u out-of-core passes of the collapse before the last: %s triangles\n",
                 unsigned(stats.refine.passes), counts.c_str());
  }
  if (stats.refine.phase1_peak_anon_bytes)
    std::fprintf(to, "phases  peak anonymous: phase 1 (%s) %.1f MiB, phase 2 (collapse) %.1f MiB\n",
                 stats.refine.passes ? "out-of-core passes" : "clustering",
                 double(stats.refine.phase1_peak_anon_bytes) / 1048576.0,
                 double(stats.refine.phase2_peak_anon_bytes) / 1048576.0);
  const std::string thick = o.thick_edges ? ", " + std::to_string(stats.output_edges) + " edges, " +
                                                std::to_string(stats.output_points) + " points"
                                          : std::string();
  const double mtri = stats.seconds_total > 0 ? double(stats.input_triangles) / stats.seconds_total / 1e6 : 0;
  // A collapse with no clustering before it has no grid to show.
  char how[160];
  if (stats.grid_dims[0] == 0)
    std::snprintf(how, sizeof how, "%s", o.target.given() || method == ClusterMethod::qem ? "edge collapse" : "as is");
  else
    std::snprintf(how, sizeof how, "%s, grid %ux%ux%u, cell %.6g", method_name(method), stats.grid_dims[0],
                  stats.grid_dims[1], stats.grid_dims[2], stats.cell_size);
  std::fprintf(to,
               "input   %" PRIu64 " vertices, %" PRIu64
               " triangles\n"
               "output  %" PRIu64 " vertices, %" PRIu64
               " triangles%s (%s)\n"
               "time    %.3f s (%s): %.2f Mtri/s\n"
               "memory  peak RSS %.1f MiB, peak anonymous %.1f MiB\n",
               stats.input_vertices, stats.input_triangles, stats.output_vertices, stats.output_triangles,
               thick.c_str(), how, stats.seconds_total, phase_times(stats.phases).c_str(), mtri,
               double(stats.peak_rss_bytes) / 1048576.0, double(stats.peak_anon_bytes) / 1048576.0);
}

// simplify --part I/K: the part's share into --work-dir; -o is the merge's.
int run_simplify_part(const SimplifyArgs& a, const SimplifyPlan& p) {
  SimplifyStats stats;
  simplify_part(a.in, p.options, p.part, &stats);
  const char* work = resolved_method(p.options) == ClusterMethod::qem
                         ? "input triangles, its share of the collapse's first pass (if the run has one) collapsed"
                         : "input triangles summed";
  if (!a.quiet)
    std::printf("part    %u of %u: %" PRIu64
                " %s into %s in %.3f s (peak anonymous %.1f "
                "MiB); when every part is done: oocsimp merge %s -o %s\n",
                p.part.index, p.part.count, stats.input_triangles, work, p.part.work_dir.c_str(), stats.seconds_total,
                double(stats.peak_anon_bytes) / 1048576.0, p.part.work_dir.c_str(), a.outputs.mesh.c_str());
  print_warnings(stats.warnings);
  return kOk;
}

int report_failure();
int run_simplify_one(const SimplifyArgs& a, const SimplifyPlan& p);

// simplify under mpirun or srun: each rank a part, rank 0 the merge; a method that
// cannot be spread yet runs whole on rank 0. -1 when this is no MPI run.
int run_simplify_mpi(const SimplifyArgs& a, const SimplifyPlan& p) {
  oocsimp_cli::MpiJob job;
  job.work_dir = a.work_dir;
  job.temp_dir = p.options.temp_dir;
  const auto start = std::chrono::steady_clock::now();
  const auto seconds_since_start = [start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  SimplifyStats stats;
  std::uint32_t ranks = 1;
  try {
    check_distributed_options(p.options);
    job.run_part = [&](const PartOptions& part) {
      try {
        SimplifyOptions o = p.options;
        if (part.index != 0) o.progress = nullptr;  // one rank reports
        ranks = part.count;
        simplify_part(a.in, o, part, &stats);
        return int(kOk);
      } catch (...) {
        return report_failure();
      }
    };
  } catch (const UsageError& e) {
    const std::string why = with_flags(e.what());
    job.whole = [&a, &p, why] {
      std::fprintf(stderr, "oocsimp: warning: %s: rank 0 runs the job alone\n", why.c_str());
      try {
        return run_simplify_one(a, p);
      } catch (...) {
        return report_failure();
      }
    };
  }
  job.merge = [&](const std::string& dir) {
    try {
      // The summary's figures are the merge's; the job line says what the whole job
      // took on rank 0's clock.
      const double parts_seconds = seconds_since_start();
      SimplifyStats merged;
      merge_parts(dir, a.outputs, p.options, &merged);
      SimplifyOptions shown = p.options;
      shown.method = resolved_method(p.options);
      std::FILE* to = a.outputs.mesh == "-" || a.outputs.stats == "-" ? stderr : stdout;
      if (!a.quiet) {
        merged.floating.rounds = stats.floating.rounds;  // the ranks swept together: rank 0 counted them
        print_simplify_summary(to, shown, merged);
        const double total = seconds_since_start();
        std::fprintf(to, "job     %u ranks, %.3f s (the parts %.3f s, then the merge %.3f s): %.2f Mtri/s",
                     unsigned(ranks), total, parts_seconds, total - parts_seconds,
                     total > 0 ? double(merged.input_triangles) / total / 1e6 : 0.0);
        // Floating cells bin by tiles: rank 0 read its range of the faces, or all.
        if (stats.floating.faces_read > 0)
          std::fprintf(to, "; rank 0 read %llu faces", static_cast<unsigned long long>(stats.floating.faces_read));
        std::fprintf(to, "\n");
      }
      print_warnings(merged.warnings);
      return int(kOk);
    } catch (...) {
      return report_failure();
    }
  };
  return oocsimp_cli::run_mpi_job(job);
}

int run_simplify(const SimplifyArgs& a) {
  SimplifyPlan p = check_simplify_args(a);
  ProgressReporter progress(a.quiet);
  p.options.progress = progress.callback();
  p.options.release_memory = release_free_heap;
  p.options.budget_counts_process = true;
  keep_freed_heap(p.options.memory_budget ? p.options.memory_budget : default_memory_budget());
  if (a.lods.given()) return run_simplify_lods(a, p);
  if (!p.part.work_dir.empty()) return run_simplify_part(a, p);
  if (oocsimp_cli::launched_by_mpi()) {
    const int status = run_simplify_mpi(a, p);
    if (status >= 0) return status;
  }
  return run_simplify_one(a, p);
}

// simplify in one process.
int run_simplify_one(const SimplifyArgs& a, const SimplifyPlan& p) {
  SimplifyStats stats;
  simplify_file(a.in, a.outputs, p.options, &stats);
  // stdout may carry the mesh or the stats: then the summary goes to stderr.
  if (!a.quiet)
    print_simplify_summary(a.outputs.mesh == "-" || a.outputs.stats == "-" ? stderr : stdout, p.options, stats);
  // Not silenced by --quiet: the output lacks part of the input.
  const std::string skipped = skipped_input_summary(a.in, stats);
  if (!skipped.empty()) std::fprintf(stderr, "oocsimp: warning: %s\n", skipped.c_str());
  print_warnings(stats.warnings);
  return kOk;
}

// --- merge

struct MergeArgs {
  std::string dir;
  OutputOptions outputs;
  SimplifyOptions options;
  Given mem, threads;
  bool quiet = false;
};

CLI::App* add_merge_command(CLI::App& app, MergeArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "merge", "Finish a run spread over parts (simplify --part I/K --work-dir DIR): the same output as one process");
  cmd->add_option("work-dir", a.dir, "The parts' work folder")->required();
  cmd->add_option("-o,--output", a.outputs.mesh, "Output mesh, as for simplify")->required();
  cmd->add_option("--stats", a.outputs.stats, "Write statistics as JSON to this file (- for stdout)");
  cmd->add_flag("--ascii", a.outputs.ascii, "Write ascii PLY or STL instead of binary");
  cmd->add_flag("--normals", a.outputs.normals, "Write per-vertex normals nx, ny, nz, as for simplify");
  add_given(cmd, "--mem", &a.mem, "Memory budget of the whole process, as for simplify");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  add_quiet_flag(cmd, &a.quiet, "No progress and no summary");
  return cmd;
}

int run_merge(const MergeArgs& a) {
  SimplifyOptions o = a.options;
  if (a.threads.given()) o.threads = threads_of(a.threads);
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem);
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

struct HierarchyArgs {
  std::string in, out;
  Given levels, threads, mem, level_ratio, sets;
  HierarchyOptions options;
  bool quiet = false, sequential = false, reuse_quadrics = false;
  std::string attributes = "all";
};

CLI::App* add_hierarchy_command(CLI::App& app, HierarchyArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "hierarchy", "Build Velho's 4-k hierarchy (four-face clusters) of a manifold mesh into a .4k file");
  cmd->add_option("input", a.in, "Input mesh")->required();
  cmd->add_option("-o,--output", a.out, "Output .4k file")->required();
  add_given(cmd, "--levels", &a.levels, "Levels to build (default: until a level removes nothing)");
  add_given(cmd, "--mem", &a.mem,
            "Heap budget; a larger input is first simplified out of core to what fits (default: a quarter of memory)");
  cmd->add_option("--attributes", a.attributes,
                  "Vertex attributes to keep: all (the default), none, or NAME,NAME... (as info lists them)");
  cmd->add_flag("--reuse-quadrics", a.reuse_quadrics,
                "After that out-of-core phase, start from its vertex quadrics rather than the reduced mesh's faces");
  cmd->add_flag("--sequential", a.sequential,
                "A level's removals need not be independent: the cheapest first, as an edge collapse takes them "
                "(closer to QEM, a deeper hierarchy)");
  add_given(cmd, "--level-ratio", &a.level_ratio,
            "A level ends at this fraction of the triangles of the level before (default 0.7; 0 = all it can)");
  add_given(cmd, "--sets", &a.sets,
            "Independent sets of removals a level is made of (default 3; fewer build faster, farther from QEM; 1: "
            "Velho's, a shallower hierarchy)");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  add_quiet_flag(cmd, &a.quiet);
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
  o.attributes = parse_attribute_selection(a.attributes);
  if (a.threads.given()) o.threads = threads_of(a.threads);
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem);
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  HierarchyStats st;
  build_hierarchy_file(a.in, a.out, o, &st);
  std::printf("hierarchy %" PRIu64 " vertices, %" PRIu64 " triangles", st.input_vertices, st.input_triangles);
  if (st.reduced_triangles)
    std::printf(" (simplified out of core to %" PRIu64 " first%s)", st.reduced_triangles,
                st.kept_quadrics ? ", its quadrics kept" : "");
  std::printf("\n");
  if (st.split_vertices) std::printf("split %" PRIu64 " vertices where several fans of faces met\n", st.split_vertices);
  if (o.reuse_quadrics && !st.reduced_triangles)
    std::fprintf(stderr,
                 "oocsimp: warning: --reuse-quadrics: the input fitted --mem, so no out-of-core phase ran; the "
                 "hierarchy started from the faces' quadrics\n");
  std::printf("records %" PRIu64 " (%" PRIu64 " swaps, %" PRIu64 " removals), file %.1f MiB\n", st.records, st.swaps,
              st.records - st.swaps, double(st.file_bytes) / 1048576.0);
  std::printf("time %.3f s: %.2f Mtri/s; peak RSS %.1f MiB, peak anonymous %.1f MiB\n", st.seconds,
              st.seconds > 0 ? double(st.input_triangles) / st.seconds / 1e6 : 0.0,
              double(st.peak_rss_bytes) / 1048576.0, double(st.peak_anon_bytes) / 1048576.0);
  return kOk;
}

struct ExtractArgs {
  std::string in, out;
  Given level, tris, error, box, sphere;
  HierarchyPlacement placement = HierarchyPlacement::quadric;
  bool ascii = false;
};

CLI::App* add_extract_command(CLI::App& app, ExtractArgs& a) {
  CLI::App* cmd = app.add_subcommand("extract", "Extract a conforming mesh from a .4k hierarchy");
  cmd->add_option("input", a.in, "Input .4k file (written by oocsimp hierarchy)")->required();
  cmd->add_option("-o,--output", a.out, "Output mesh (PLY, OBJ, STL, OFF, glTF .glb; .zst compresses)")->required();
  add_given(cmd, "--level", &a.level, "Level J: 0 is the finest, higher is coarser");
  add_given(cmd, "--tris", &a.tris, "The finest state with at most this many triangles");
  add_given(cmd, "--error", &a.error, "The coarsest state whose removals all cost at most this (see info)");
  add_given(cmd, "--box", &a.box, "x0,y0,z0,x1,y1,z1: keep the faces meeting this box at the finest level");
  add_given(cmd, "--sphere", &a.sphere, "x,y,z,r: keep the faces meeting this ball at the finest level");
  add_enum_option(cmd, "--placement", &a.placement, hierarchy_placement_names(),
                  "Where the kept vertices go: quadric (each at the minimum of the quadric it holds, the default) "
                  "or kept (where the finest mesh has them)");
  cmd->add_flag("--ascii", a.ascii, "Write ascii PLY or STL");
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
  extract_file(a.in, a.out, a.ascii, q);
  return kOk;
}

// --- info

struct InfoArgs {
  std::string in, tmp;
};

CLI::App* add_info_command(CLI::App& app, InfoArgs& a) {
  CLI::App* cmd = app.add_subcommand("info", "Print format, element counts, properties and bounding box");
  cmd->add_option("input", a.in, "Input mesh, or a .4k hierarchy")->required();
  add_tmp_option(cmd, &a.tmp);
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
  if (is_hierarchy_file(a.in)) return run_hierarchy_info(a);
  const MeshSummary m = describe_mesh(a.in, a.tmp);
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

struct GenerateArgs {
  Given tris, seed;
  std::string out;
  GenerateOptions options;  // CLI11 sets the shape and the flags
  bool quiet = false;
};

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
  cmd->add_option("-o,--output", a.out, "Output PLY: .ply or .ply.zst (compressed), - for stdout")->required();
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
  if (out != "-" && !ends_with(".ply") && !ends_with(".ply.zst"))
    throw UsageError(out + ": generate writes PLY only: give a name ending in .ply or .ply.zst (or - for stdout)");
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

struct MeasureArgs {
  std::string a, b;
  Given samples, seed, threads;
  MeasureOptions options;  // CLI11 sets --tmp
  bool json = false;
  bool quiet = false;
};

CLI::App* add_measure_command(CLI::App& app, MeasureArgs& a) {
  CLI::App* cmd = app.add_subcommand("measure", "Hausdorff, mean and RMS distance between two surfaces");
  cmd->add_option("a", a.a, "Mesh A, streamed (the original; any size)")->required();
  cmd->add_option("b", a.b, "Mesh B, loaded into memory (e.g. the simplification)")->required();
  add_given(cmd, "--samples", &a.samples, "Points sampled on each surface (default 1000000)");
  add_given(cmd, "--seed", &a.seed, "Random seed of the samples (default 1)");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  cmd->add_flag("--json", a.json, "Print the report as JSON");
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

struct CurvatureArgs {
  std::string in, out;
  Given radius, threads, mem, tile;
  std::string neighbourhood = "ball";
  CurvatureOptions options;
  bool ascii = false, quiet = false;
};

CLI::App* add_curvature_command(CLI::App& app, CurvatureArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "curvature", "Principal curvatures k1, k2 of every vertex by integral invariants (Hua et al. §3.4), to PLY");
  cmd->add_option("input", a.in, "Input mesh")->required();
  cmd->add_option("-o,--output", a.out, "Output PLY: the mesh with float vertex properties k1 and k2")->required();
  add_given(cmd, "--radius", &a.radius, "Radius of the ball or sphere (default 5 mean edge lengths)");
  cmd->add_option("--neighbourhood", a.neighbourhood,
                  "ball: the ball cut by the solid (Hua et al. eq. 13-14); sphere: the sphere cut by it (eq. 17-18)")
      ->check(CLI::IsMember({"ball", "sphere"}));
  add_given(cmd, "--mem", &a.mem,
            "Heap budget; a mesh larger than it is estimated in tiles with a halo (default: a quarter of memory)");
  add_given(cmd, "--tile", &a.tile, "Side of the tiles, model units (default: in memory when it fits --mem)");
  add_threads_option(cmd, &a.threads);
  add_tmp_option(cmd, &a.options.temp_dir);
  cmd->add_flag("--ascii", a.ascii, "Write ascii PLY");
  add_quiet_flag(cmd, &a.quiet);
  return cmd;
}

int run_curvature(CurvatureArgs& a) {
  CurvatureOptions o = a.options;
  if (a.radius.given()) o.radius = positive_number("--radius", a.radius.text);
  if (a.threads.given()) o.threads = threads_of(a.threads);
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem);
  if (a.tile.given()) o.tile_side = positive_number("--tile", a.tile.text);
  o.neighbourhood = a.neighbourhood == "sphere" ? CurvatureNeighbourhood::sphere : CurvatureNeighbourhood::ball;
  ProgressReporter progress(a.quiet);
  o.progress = progress.callback();
  CurvatureStats st;
  curvature_file(a.in, a.out, a.ascii, o, &st);
  if (st.fitted + st.none > 0 && !a.quiet)
    std::fprintf(stderr,
                 "oocsimp: warning: %" PRIu64
                 " vertices where the surface does not cover the disk of radius %g (an "
                 "outline, a hole or a soup) were fitted with a quadric instead, and %" PRIu64
                 " with no face, area or neighbours within it got 0\n",
                 st.fitted, st.radius, st.none);
  std::printf("curvature %" PRIu64 " vertices, %" PRIu64 " triangles, radius %g (mean edge %g), %s\n", st.vertices,
              st.triangles, st.radius, st.mean_edge_length, a.neighbourhood.c_str());
  std::printf("estimated %" PRIu64 " by the invariants, %" PRIu64 " by the fit, %" PRIu64 " not at all, %s\n",
              st.invariant, st.fitted, st.none,
              st.tile_side > 0 ? ("in tiles of side " + std::to_string(st.tile_side)).c_str() : "in memory");
  std::printf("time %.3f s: %.2f M vertices/s; peak RSS %.1f MiB, peak anonymous %.1f MiB\n", st.seconds,
              st.seconds > 0 ? double(st.vertices) / st.seconds / 1e6 : 0.0, double(st.peak_rss_bytes) / 1048576.0,
              double(st.peak_anon_bytes) / 1048576.0);
  return kOk;
}

// --- lod-select

struct LodSelectArgs {
  std::string lods, distance, fov, height, factor;
  bool json = false;
};

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
  const std::vector<LodLevel> levels = read_lod_levels(a.lods);
  const double r = pixel_size_at(positive_number("--distance", a.distance), positive_number("--fov", a.fov, 179.999),
                                 double(whole_number("--height", a.height, 1, 1u << 20)));
  const double x = a.factor.empty() ? 5.0 : positive_number("--factor", a.factor);
  if (x < 1) bad_value("--factor", a.factor, "a number of at least 1");
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

struct RenderArgs {
  std::string in, out, size, view, tmp;
  RenderOptions options;  // CLI11 sets the shading and --thick-edges
  bool quiet = false;
};

CLI::App* add_render_command(CLI::App& app, RenderArgs& a) {
  CLI::App* cmd = app.add_subcommand("render", "Draw a mesh file into a PNG (software rasteriser, streamed)");
  cmd->add_option("input", a.in, "Mesh file (PLY, OBJ, STL, OFF, glTF .glb, optionally .zst or .gz)")->required();
  cmd->add_option("-o,--output", a.out, "PNG file")->required();
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
                 " covered, %.3g model units each), %s up%s, %.3f s\n",
                 s.triangles, s.edges, s.points, o.width, o.height, s.covered_pixels, s.pixel_size,
                 name_of(up_axis_names(), s.up), o.up == UpAxis::automatic ? " (auto)" : "", seconds);
  return kOk;
}

// --- Parse errors and failures.

// Levenshtein distance, for "did you mean".
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// " (did you mean --grid?)" for the first argument that names no flag of `command`
// (or no subcommand of the app) but is within two edits of one; empty otherwise.
std::string suggestion(const CLI::App& app, int argc, char** argv) {
  std::vector<CLI::App*> parsed = app.get_subcommands();
  const CLI::App* command = parsed.empty() ? nullptr : parsed.front();
  std::vector<std::string> names;
  if (command) {
    for (const CLI::Option* o : command->get_options())
      for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
  } else {
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
      names.push_back(sub->get_name());
  }
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    arg = arg.substr(0, arg.find('='));
    if (command ? arg.rfind("--", 0) != 0 : arg.rfind("-", 0) == 0) continue;
    if (std::find(names.begin(), names.end(), arg) != names.end()) continue;
    if (!command && i > 1) break;  // only the subcommand's own position
    std::string best;
    std::size_t best_distance = 3;
    for (const std::string& n : names) {
      std::size_t d = edit_distance(arg, n);
      if (d < best_distance) best_distance = d, best = n;
    }
    if (!best.empty()) return " (did you mean " + best + "?)";
  }
  return "";
}

// CLI11's messages may span lines; a usage error is one line.
std::string one_line(std::string text) {
  for (char& c : text)
    if (c == '\n') c = ' ';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// The exception being handled, reported on stderr as its exit code (called in a catch block).
int report_failure() {
  try {
    throw;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", with_flags(e.what()).c_str());
    return kUsage;
  } catch (const InputError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kBadInput;
  } catch (const IoError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", with_flags(e.what()).c_str());
    return kIo;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "oocsimp: out of memory\n");
    return kIo;
  } catch (const std::exception& e) {  // Cancelled among them
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kIo;
  }
}

}  // namespace

// What each option's value is, for --help: every value is taken as text and checked
// later, which CLI11 would show as TEXT.
void show_value_types(CLI::App& app) {
  static const std::pair<const char*, const char*> kTypeOfOption[] = {
      {"threads", "INT"},
      {"target-tris", "INT"},
      {"tris", "INT"},
      {"grid", "INT"},
      {"lods", "INT"},
      {"levels", "INT"},
      {"samples", "INT"},
      {"seed", "INT"},
      {"level", "INT"},
      {"max-depth", "INT"},
      {"height", "INT"},
      {"mem", "SIZE"},
      {"part", "I/K"},
      {"box", "X0,Y0,Z0,X1,Y1,Z1"},
      {"sphere", "X,Y,Z,R"},
      {"size", "WxH"},
      {"view", "AZ,EL"},
      {"attributes", "NAMES"},
      {"tmp", "PATH"},
      {"work-dir", "PATH"},
      {"output", "PATH"},
      {"stats", "PATH"},
      {"lock-vertices", "PATH"},
      {"input", "PATH"},
      {"a", "PATH"},
      {"b", "PATH"},
  };
  for (CLI::App* command : app.get_subcommands({}))
    for (CLI::Option* option : command->get_options()) {
      const std::string shown = option->get_type_name();
      if (option->get_type_size() == 0 || shown.empty()) continue;  // a flag
      const std::string name = option->get_lnames().empty() ? option->get_name() : option->get_lnames().front();
      const char* type = shown.find(':') != std::string::npos ? "NAME" : "FLOAT";  // a choice, or a number
      for (const auto& [n, t] : kTypeOfOption)
        if (name == n) type = t;
      option->type_name(type);
    }
}

int main(int argc, char** argv) {
  install_signal_cleanup();
  tune_allocator_for_tiles();
  CLI::App app{"oocsimp: out-of-core simplification of huge triangle meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("oocsimp ") + version());
  SimplifyArgs simplify;
  InfoArgs info;
  GenerateArgs generate;
  MeasureArgs measure;
  CurvatureArgs curvature;
  LodSelectArgs lod_select;
  RenderArgs render;
  HierarchyArgs hierarchy;
  ExtractArgs extract;
  MergeArgs merge;
  const std::pair<CLI::App*, std::function<int()>> commands[] = {
      {add_simplify_command(app, simplify), [&] { return run_simplify(simplify); }},
      {add_info_command(app, info), [&] { return run_info(info); }},
      {add_generate_command(app, generate), [&] { return run_generate(generate); }},
      {add_measure_command(app, measure), [&] { return run_measure(measure); }},
      {add_curvature_command(app, curvature), [&] { return run_curvature(curvature); }},
      {add_lod_select_command(app, lod_select), [&] { return run_lod_select(lod_select); }},
      {add_render_command(app, render), [&] { return run_render(render); }},
      {add_hierarchy_command(app, hierarchy), [&] { return run_hierarchy(hierarchy); }},
      {add_extract_command(app, extract), [&] { return run_extract(extract); }},
      {add_merge_command(app, merge), [&] { return run_merge(merge); }},
  };
  show_value_types(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "oocsimp: %s%s (see oocsimp --help)\n", one_line(e.what()).c_str(),
                 suggestion(app, argc, argv).c_str());
    return kUsage;
  }
  try {
    for (const auto& [command, run] : commands)
      if (*command) return run();
  } catch (...) {
    return report_failure();
  }
  return kUsage;
}
