// oocsimp command line: a thin layer over the library (include/oocsimp/).
//
// Exit codes: 0 ok, 2 usage, 3 bad input, 4 I/O or resource failure.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "oocsimp/error.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/lod.hpp"
#include "grid/grid_spec.hpp"
#include "oocsimp/oocsimp.hpp"
#include "oocsimp/measure.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/progress_reporter.hpp"
#include "oocsimp/render.hpp"
#include "api/simplify.hpp"
#include "oocsimp/oocsimp.hpp"

using namespace oocsimp;

namespace {

enum ExitCode { kOk = 0, kUsage = 2, kBadInput = 3, kIo = 4 };

// The library names an option at fault by its field ("options.memory_budget"); the
// command line shows the flag that sets it. Longer names first, so that no name is
// replaced inside another.
std::string with_flags(std::string message) {
  static const std::pair<const char*, const char*> kFlags[] = {
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
      {"options.method", "--method"},
      {"options.lods.levels", "--lods"},
      {"options.lods.factor", "--lod-factor"},
      {"options.lods", "--lods"},
      {"options.triangles", "--tris"},
      {"options.samples", "--samples"},
      {"outputs.replace_input", "--force"},
      {"outputs.stats", "--stats"},
      {"outputs.mesh", "-o"},
  };
  for (const auto& f : kFlags) {
    const std::string field = f.first;
    for (std::size_t at = message.find(field); at != std::string::npos; at = message.find(field, at))
      message.replace(at, field.size(), f.second);
  }
  return message;
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

std::uint64_t whole_number(const std::string& flag, const std::string& text, std::uint64_t min, std::uint64_t max) {
  std::uint64_t v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || text[0] == '-' || r.ec != std::errc() || r.ptr != text.data() + text.size() || v < min || v > max)
    bad_value(flag, text, "a whole number from " + std::to_string(min) + " to " + std::to_string(max));
  return v;
}

// An option the user gave, with its text.
struct Given {
  CLI::Option* option = nullptr;
  std::string text;
  bool given() const { return option && option->count() > 0; }
};

constexpr std::uint64_t kMaxThreads = 65536;

// Given with another method, the floating-only options would do nothing.
void refuse_floating_only(const std::vector<CLI::Option*>& floating_only, ClusterMethod method) {
  for (const CLI::Option* o : floating_only)
    if (o->count() > 0)
      throw UsageError(o->get_name() + " applies to --method floating only, not to --method " + method_name(method));
}

struct SimplifyArgs {
  std::string in;
  OutputOptions outputs;
  SimplifyOptions options;
  std::string method = "floating", cell_shape = "cube", assign = "nearest", rep = "quadric", spill = "auto",
              precision = "auto", attributes = "all";
  Given cell, grid, ratio, tile, mem, threads, target_tris, target_ratio, max_error, intermediate_factor;
  Given lods, lod_factor;
  LodOptions lod;
  bool measure = false;
  std::string refine = "qem";
  CLI::Option* refine_option = nullptr;
  std::vector<CLI::Option*> floating_only;
  bool quiet = false;
};

template <class E>
E enum_named(const std::string& text, std::initializer_list<E> values, const char* (*name)(E)) {
  for (E e : values)
    if (text == name(e)) return e;
  throw UsageError("unknown value \"" + text + "\"");  // IsMember checked it already
}

ClusterMethod method_named(const std::string& text) {
  for (ClusterMethod m : cluster_methods())
    if (text == method_name(m)) return m;
  throw UsageError("unknown value \"" + text + "\"");  // IsMember checked it already
}

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (ClusterMethod m : cluster_methods()) names.push_back(method_name(m));
  return names;
}

// Turns the texts of the simplify options into SimplifyOptions, checking each.
void resolve_simplify_args(SimplifyArgs& a) {
  SimplifyOptions& o = a.options;
  o.method = method_named(a.method);
  if (o.method != ClusterMethod::floating) refuse_floating_only(a.floating_only, o.method);
  if (a.target_tris.given())
    o.target.triangles = whole_number("--target-tris", a.target_tris.text, 4, ~std::uint64_t(0));
  if (a.target_ratio.given()) o.target.ratio = positive_number("--target-ratio", a.target_ratio.text, 1.0);
  if (a.max_error.given()) o.target.max_error = positive_number("--max-error", a.max_error.text);
  o.target.refine = enum_named(a.refine, {RefineMethod::qem, RefineMethod::none}, refine_name);
  if (a.refine_option->count() > 0 && !o.target.given())
    throw UsageError("--refine applies with a target: give --target-tris, --target-ratio or --max-error");
  if (a.intermediate_factor.given()) {
    if (!o.target.given())
      throw UsageError(
          "--intermediate-factor applies with a target: give --target-tris, --target-ratio or --max-error");
    o.target.intermediate_factor = positive_number("--intermediate-factor", a.intermediate_factor.text);
  }
  o.floating.cell_shape = enum_named(a.cell_shape, {CellShape::cube, CellShape::sphere}, cell_shape_name);
  o.floating.assign = enum_named(a.assign, {AssignRule::nearest, AssignRule::heaviest}, assign_name);
  o.floating.representative = enum_named(
      a.rep, {RepresentativeRule::quadric, RepresentativeRule::centre, RepresentativeRule::mean}, representative_name);
  o.floating.spill_compression = enum_named(
      a.spill, {SpillCompression::automatic, SpillCompression::zstd, SpillCompression::none}, spill_compression_name);
  o.precision = enum_named(a.precision, {Precision::automatic, Precision::float32, Precision::float64}, precision_name);
  o.attributes = parse_attribute_selection(a.attributes);
  if (a.cell.given()) o.sizing.cell = positive_number("--cell", a.cell.text);
  if (a.grid.given()) o.sizing.grid = std::uint32_t(whole_number("--grid", a.grid.text, 1, GridSpec::kMaxDim));
  if (a.ratio.given()) o.sizing.ratio = positive_number("--ratio", a.ratio.text, 1.0);
  if (a.tile.given()) o.floating.tile_side = positive_number("--tile", a.tile.text);
  if (a.threads.given()) o.threads = unsigned(whole_number("--threads", a.threads.text, 1, kMaxThreads));
  if (a.mem.given()) {
    try {
      o.memory_budget = parse_byte_size(a.mem.text);
    } catch (const UsageError& e) {
      throw UsageError(std::string("--mem: ") + e.what());
    }
  }
  if (a.lods.given()) a.lod.levels = std::uint32_t(whole_number("--lods", a.lods.text, 1, 16));
  if (a.lod_factor.given()) {
    if (!a.lods.given()) throw UsageError("--lod-factor applies with --lods");
    a.lod.factor = positive_number("--lod-factor", a.lod_factor.text);
    if (!(a.lod.factor > 1)) bad_value("--lod-factor", a.lod_factor.text, "a number above 1");
  }
  if (a.measure && !a.lods.given()) throw UsageError("--measure applies with --lods (use oocsimp measure otherwise)");
}

// The last part of a path: level files are named in their description relative to it.
std::string base_name(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The description OUT.lods.json of the levels just written (with --measure, each
// measured against the input), and a line per level.
void describe_levels(const SimplifyArgs& a, const std::vector<SimplifyStats>& stats, const std::string& description) {
  std::vector<LodLevel> levels;
  for (std::uint32_t k = 0; k < stats.size(); ++k) {
    const SimplifyStats& s = stats[k];
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
      m.threads = a.options.threads;
      m.temp_dir = a.options.temp_dir;
      m.progress = a.options.progress;
      const DistanceReport r = measure_surface_distance(a.in, lod_level_path(a.outputs.mesh, k), m);
      l.rms = r.symmetric.rms;
      l.hausdorff = r.symmetric.max;
    }
    levels.push_back(l);
  }
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
  for (const SimplifyStats& s : stats)
    for (const std::string& w : s.warnings) std::fprintf(stderr, "oocsimp: warning: %s\n", with_flags(w).c_str());
}

// simplify --lods: the levels, then (with --measure) each against the input, then the
// description OUT.lods.json, and a line per level.
int run_simplify_lods(SimplifyArgs& a) {
  std::vector<SimplifyStats> stats;
  simplify_lods_file(a.in, a.outputs, a.options, a.lod, &stats);
  // The levels are in place now: a description of the ones they replaced must not
  // outlive a failure to describe them (measuring or writing).
  const std::string description = lod_description_path(a.outputs.mesh);
  try {
    describe_levels(a, stats, description);
  } catch (...) {
    std::remove(description.c_str());
    throw;
  }
  return kOk;
}

int run_simplify(SimplifyArgs& a) {
  resolve_simplify_args(a);
  ProgressReporter progress(a.quiet);
  a.options.progress = progress.callback();
  a.options.release_memory = release_free_heap;
  a.options.budget_counts_process = true;
  if (a.lods.given()) return run_simplify_lods(a);
  SimplifyStats stats;
  simplify_file(a.in, a.outputs, a.options, &stats);
  if (!a.quiet) {
    // stdout may carry the mesh or the stats: then the summary goes to stderr.
    std::FILE* to = a.outputs.mesh == "-" || a.outputs.stats == "-" ? stderr : stdout;
    if (a.options.method == ClusterMethod::floating) {
      // The spill's parts that exist: on disk, in memory or both.
      char disk[96] = "", memory[64] = "";
      if (stats.spill_bytes)
        std::snprintf(disk, sizeof disk, ", spill %.1f MiB on disk (%.1f MiB raw)",
                      double(stats.spill_bytes) / 1048576.0, double(stats.spill_raw_bytes) / 1048576.0);
      if (stats.spill_bytes_in_memory)
        std::snprintf(memory, sizeof memory, ", %.1f MiB of spill held in memory",
                      double(stats.spill_bytes_in_memory) / 1048576.0);
      std::fprintf(to, "tiles   %" PRIu64 " tiles%s, %" PRIu64 " rounds%s%s\n", stats.tiles,
                   stats.resumed ? " (kept by an earlier run)" : "", stats.rounds, disk, memory);
    }
    if (a.options.target.given() || a.options.method == ClusterMethod::qem)
      std::fprintf(
          to, "refine  %" PRIu64 " intermediate triangles, %" PRIu64 " collapses, largest error %.3g (cost %.3g)%s\n",
          stats.intermediate_triangles, stats.collapses, stats.largest_collapse_error, stats.largest_collapse_cost,
          stats.target_missed ? ", target missed" : "");
    if (stats.phase1_peak_anon_bytes)
      std::fprintf(to, "phases  peak anonymous: phase 1 (clustering) %.1f MiB, phase 2 (collapse) %.1f MiB\n",
                   double(stats.phase1_peak_anon_bytes) / 1048576.0, double(stats.phase2_peak_anon_bytes) / 1048576.0);
    std::string phases;
    for (const PhaseTime& p : stats.phases) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s%s %.3f", phases.empty() ? "" : ", ", p.name.c_str(), p.seconds);
      phases += buf;
    }
    const std::string thick = a.options.thick_edges ? ", " + std::to_string(stats.output_edges) + " edges, " +
                                                          std::to_string(stats.output_points) + " points"
                                                    : std::string();
    double mtri = stats.seconds_total > 0 ? double(stats.input_triangles) / stats.seconds_total / 1e6 : 0;
    std::fprintf(to,
                 "input   %" PRIu64 " vertices, %" PRIu64
                 " triangles\n"
                 "output  %" PRIu64 " vertices, %" PRIu64
                 " triangles%s (%s, grid %ux%ux%u, cell %.6g)\n"
                 "time    %.3f s (%s): %.2f Mtri/s\n"
                 "memory  peak RSS %.1f MiB, peak anonymous %.1f MiB\n",
                 stats.input_vertices, stats.input_triangles, stats.output_vertices, stats.output_triangles,
                 thick.c_str(), method_name(a.options.method), stats.grid_dims[0], stats.grid_dims[1],
                 stats.grid_dims[2], stats.cell_size, stats.seconds_total, phases.c_str(), mtri,
                 double(stats.peak_rss_bytes) / 1048576.0, double(stats.peak_anon_bytes) / 1048576.0);
  }
  // Not silenced by --quiet: the output lacks part of the input.
  std::string skipped = skipped_input_summary(a.in, stats);
  if (!skipped.empty()) std::fprintf(stderr, "oocsimp: warning: %s\n", skipped.c_str());
  for (const std::string& w : stats.warnings) std::fprintf(stderr, "oocsimp: warning: %s\n", with_flags(w).c_str());
  return kOk;
}

// The thick edges and points of `m` (read through its triangle stream): counts and
// the range and mean of their thicknesses.
void print_thick_primitives(MeshInput& m) {
  struct Tally {
    std::uint64_t count = 0;
    double least = HUGE_VAL, most = 0, sum = 0;
  } edges, points;
  m.triangles->set_primitive_sink([&](const LinePrimitive* p, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) {
      Tally& t = p[k].a == p[k].b ? points : edges;
      ++t.count;
      t.least = std::min(t.least, double(p[k].thickness));
      t.most = std::max(t.most, double(p[k].thickness));
      t.sum += p[k].thickness;
    }
  });
  std::vector<std::uint64_t> chunk(3 * 65536);
  while (m.triangles->read(chunk.data(), 65536) > 0) {
  }
  for (const auto& [name, t] : {std::pair<const char*, const Tally&>{"edges", edges}, {"points", points}})
    if (t.count > 0 && t.most == 0)
      std::printf("%-9s %" PRIu64 " (no thickness)\n", name, t.count);
    else if (t.count > 0)
      std::printf("%-9s %" PRIu64 " (thickness %.6g to %.6g, mean %.6g)\n", name, t.count, t.least, t.most,
                  t.sum / double(t.count));
}

int run_info(const std::string& in, const std::string& tmp) {
  OpenOptions open;
  open.temp_dir = tmp;
  MeshInput m = open_mesh_input(in, open);
  const MeshInfo& i = m.info;
  std::printf("file      %s\n", i.path.c_str());
  std::printf("format    %s%s\n", i.format.c_str(), i.compressed ? " (zstd)" : "");
  std::printf("vertices  %" PRIu64, i.vertex_count);
  if (i.unwelded_vertex_count) std::printf(" (welded from %" PRIu64 " stored)", i.unwelded_vertex_count);
  std::printf("\n");
  std::printf("faces     %" PRIu64 "\n", i.face_count);
  if (i.edge_count > 0 || i.point_count > 0) print_thick_primitives(m);
  for (const auto& e : i.elements) std::printf("element   %s\n", e.c_str());
  for (const auto& c : i.comments) std::printf("header    %s\n", c.c_str());
  std::printf("positions %s\n", i.positions_in_place ? "read in place (mmap)" : "converted to a temporary array");
  // What simplify carries by default (--attributes all), with the range of each.
  if (m.attributes.empty()) std::printf("attributes none carried\n");
  for (const VertexAttribute& a : m.attributes.attributes)
    std::printf("attribute %s %s, carried (values %.9g to %.9g)\n", a.name.c_str(), attribute_type_name(a.type), a.min,
                a.max);
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

int run_generate(const std::string& tris_text, const std::string& shape, const std::string& seed_text,
                 const std::string& out, bool ascii, bool attributes, bool quiet) {
  GenerateOptions o;
  o.triangles = whole_number("--tris", tris_text, 1, ~std::uint64_t(0));
  o.seed = whole_number("--seed", seed_text, 0, ~std::uint64_t(0));
  o.ascii = ascii;
  o.attributes = attributes;
  if (shape == "sphere")
    o.shape = SyntheticShape::sphere;
  else if (shape == "terrain")
    o.shape = SyntheticShape::terrain;
  else if (shape == "parts")
    o.shape = SyntheticShape::parts;
  else if (shape == "branches")
    o.shape = SyntheticShape::branches;
  else
    throw UsageError("unknown shape \"" + shape + "\" (sphere, terrain, parts or branches)");
  check_generate_output(out);
  ProgressReporter progress(quiet);
  o.progress = progress.callback();
  GenerateResult r = generate_mesh(out, o);
  if (!quiet)
    std::fprintf(out == "-" ? stderr : stdout, "%s: %" PRIu64 " vertices, %" PRIu64 " triangles\n", out.c_str(),
                 r.vertices, r.triangles);
  return kOk;
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

int run_render(const std::string& in, const std::string& out, RenderOptions options, const std::string& tmp,
               bool quiet) {
  ProgressReporter progress(quiet);
  options.progress = progress.callback();
  const auto t0 = std::chrono::steady_clock::now();
  const RenderStats s = render_file(in, out, options, tmp);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!quiet)
    std::fprintf(stderr,
                 "render  %" PRIu64 " triangles, %" PRIu64 " edges, %" PRIu64 " points, %ux%u pixels (%" PRIu64
                 " covered, %.3g model units each), %.3f s\n",
                 s.triangles, s.edges, s.points, options.width, options.height, s.covered_pixels, s.pixel_size,
                 seconds);
  return kOk;
}

// Low & Tan §4: the level for a viewing distance. X defaults to 5, the accurate end of
// the paper's 5-10 (a higher X trades visual accuracy for speed).
int run_lod_select(const std::string& path, const std::string& distance, const std::string& fov,
                   const std::string& height, const std::string& factor, bool json) {
  const std::vector<LodLevel> levels = read_lod_levels(path);
  const double r = pixel_size_at(positive_number("--distance", distance), positive_number("--fov", fov, 179.999),
                                 double(whole_number("--height", height, 1, 1u << 20)));
  const double x = factor.empty() ? 5.0 : positive_number("--factor", factor);
  if (x < 1) bad_value("--factor", factor, "a number of at least 1");
  const LodChoice c = choose_lod(levels, r, x);
  const LodLevel& l = levels[c.level];
  if (json) {
    std::puts(lod_choice_json(levels, c, r, x).c_str());
    return kOk;
  }
  std::printf("level      %zu: %s (cell %.6g)%s\n", c.level, l.file.c_str(), l.cell,
              c.finest_too_coarse ? ", the finest there is: its cell spans more than the factor's pixels" : "");
  std::printf("pixel      %.6g model units (R = 2 D tan(FOV/2) / H); cells up to %.6g (factor %g)\n", r, x * r, x);
  std::printf("thick line T / R = T x %.6g pixels for an edge of thickness T\n", 1 / r);
  return kOk;
}

int run_measure(const std::string& a, const std::string& b, MeasureOptions options, bool json, bool quiet) {
  ProgressReporter progress(quiet);
  options.progress = progress.callback();
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

}  // namespace

int main(int argc, char** argv) {
  install_signal_cleanup();
  tune_allocator_for_tiles();
  CLI::App app{"oocsimp: out-of-core simplification of huge triangle meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("oocsimp ") + version());

  const char* const common = "Options";
  const char* const floating_group = "Floating method only (--method floating, the default)";

  SimplifyArgs sa;
  CLI::App* simplify = app.add_subcommand("simplify", "Simplify a mesh file (PLY, OBJ, STL, optionally .zst)");
  simplify->footer(
      "Give at most one of --cell, --grid and --ratio; without any, --ratio 0.1 (keep about a tenth of "
      "the triangles).\n");
  simplify->add_option("input", sa.in, "Input mesh")->required();
  simplify
      ->add_option("-o,--output", sa.outputs.mesh,
                   "Output mesh; the format from the name: .ply, .obj, .stl or .off, + .zst compresses; - writes "
                   "binary PLY to stdout")
      ->required()
      ->group(common);
  sa.cell.option = simplify->add_option("--cell", sa.cell.text, "Cell side in model units")->group(common);
  sa.grid.option =
      simplify
          ->add_option("--grid", sa.grid.text,
                       "Cells along the longest bounding-box axis, 1 to " + std::to_string(GridSpec::kMaxDim))
          ->group(common);
  sa.ratio.option = simplify
                        ->add_option("--ratio", sa.ratio.text,
                                     "Approximate fraction of the triangles to keep, in (0, 1] (default 0.1)")
                        ->group(common);
  sa.cell.option->excludes(sa.grid.option)->excludes(sa.ratio.option);
  sa.grid.option->excludes(sa.ratio.option);
  sa.target_tris.option =
      simplify
          ->add_option("--target-tris", sa.target_tris.text,
                       "Exactly this many output triangles (at least 4): clustering to a few times that, then quadric "
                       "edge collapse")
          ->group(common);
  sa.target_ratio.option =
      simplify->add_option("--target-ratio", sa.target_ratio.text, "Exactly this fraction of the input's triangles")
          ->group(common);
  sa.max_error.option =
      simplify
          ->add_option("--max-error", sa.max_error.text,
                       "Stop collapsing before an error above this, in model units (with or without a count)")
          ->group(common);
  sa.refine_option = simplify
                         ->add_option("--refine", sa.refine,
                                      "With a target: qem (edge collapse to it exactly, the default) or none "
                                      "(clustering alone, at a cell chosen for about the target)")
                         ->check(CLI::IsMember({"qem", "none"}))
                         ->group(common);
  sa.lods.option = simplify
                       ->add_option("--lods", sa.lods.text,
                                    "Write K levels of detail OUT.lod0 ... OUT.lod{K-1} at cells C, C*F, C*F^2, ... "
                                    "and their description OUT.lods.json (floating cells bin and grade once)")
                       ->group(common);
  sa.lod_factor.option =
      simplify
          ->add_option("--lod-factor", sa.lod_factor.text, "With --lods: the cell grows F times a level (default 2)")
          ->group(common);
  simplify
      ->add_flag("--measure", sa.measure,
                 "With --lods: measure each level's RMS and Hausdorff distance to the input (oocsimp measure's "
                 "symmetric figures) into OUT.lods.json")
      ->group(common);
  sa.intermediate_factor.option =
      simplify
          ->add_option("--intermediate-factor", sa.intermediate_factor.text,
                       "With a target: phase 1 clusters to about this many times the target, at least 1 (default 4; "
                       "less when --mem cannot hold that)")
          ->group(common);
  simplify
      ->add_option("--method", sa.method,
                   "floating (Low & Tan, the default), uniform (OoCS grid) or qem (edge collapse of the whole "
                   "input in memory; with a target or --ratio's default share, exactly)")
      ->check(CLI::IsMember(method_names()))
      ->group(common);
  sa.threads.option =
      simplify->add_option("--threads", sa.threads.text, "Worker threads (default: all cores)")->group(common);
  simplify->add_option("--tmp", sa.options.temp_dir, "Folder for temporary files (default $TMPDIR or /tmp)")
      ->group(common);
  simplify->add_option("--stats", sa.outputs.stats, "Write statistics as JSON to this file (- for stdout)")
      ->group(common);
  simplify
      ->add_flag("--force", sa.outputs.replace_input,
                 "Allow the output to be the input (replaced only after a successful run)")
      ->group(common);
  simplify->add_flag("--quiet", sa.quiet, "No progress and no summary")->group(common);
  simplify->add_flag("--ascii", sa.outputs.ascii, "Write ascii PLY or STL instead of binary")->group(common);
  simplify
      ->add_flag(
          "--normals", sa.outputs.normals,
          "Write per-vertex normals nx, ny, nz (area-weighted from the output's triangles; carried ones replaced)")
      ->group(common);
  simplify
      ->add_flag("--thick-edges", sa.options.thick_edges,
                 "Keep parts thinner than a cell as thick edges and points (Low & Tan 1997 sec. 3.3; "
                 "PLY element edge and point with a thickness, OBJ l and p lines)")
      ->group(common);
  simplify
      ->add_option("--precision", sa.precision,
                   "Output coordinates: float, double or auto (double when the input holds more than float "
                   "precision, the default)")
      ->check(CLI::IsMember({"auto", "float", "double"}))
      ->group(common);
  sa.mem.option = simplify
                      ->add_option("--mem", sa.mem.text,
                                   "Working-set budget of the floating tiles and of vertex welding, e.g. 256M or 2G "
                                   "(default: a quarter of physical memory)")
                      ->group(common);
  simplify
      ->add_option("--attributes", sa.attributes,
                   "Vertex attributes to carry: all (the default), none, or NAME,NAME... (as info lists them)")
      ->group(common);
  simplify->add_flag("--weld", sa.options.weld, "Merge PLY/OBJ vertices at exactly the same position (STL always is)")
      ->group(common);
  sa.floating_only = {
      simplify->add_option("--cell-shape", sa.cell_shape, "Cell shape (default cube)")
          ->check(CLI::IsMember({"cube", "sphere"})),
      simplify->add_option("--assign", sa.assign, "Vertex in several cells: nearest (centre, the default) or heaviest")
          ->check(CLI::IsMember({"nearest", "heaviest"})),
      simplify->add_option("--rep", sa.rep, "Representative vertex (default quadric)")
          ->check(CLI::IsMember({"quadric", "centre", "mean"})),
      sa.tile.option = simplify->add_option("--tile", sa.tile.text,
                                            "Tile side in model units (default: from --mem); refused when the "
                                            "tiles' buffers (9 KiB each) exceed a quarter of --mem"),
      simplify->add_flag("--keep-tmp", sa.options.floating.keep_temp,
                         "Keep the binned tiles in --tmp and reuse them on the next run of the same input"),
      simplify
          ->add_option("--spill-compress", sa.spill,
                       "zstd on the triangle, stitch and kept-triangle spills: auto (when they would not fit in "
                       "half the available memory, or with --keep-tmp, the default), zstd or none")
          ->check(CLI::IsMember({"auto", "zstd", "none"})),
  };
  for (CLI::Option* o : sa.floating_only) o->group(floating_group);

  std::string in, out, tmp, shape = "sphere";
  bool quiet = false, ascii = false;
  CLI::App* info = app.add_subcommand("info", "Print format, element counts, properties and bounding box");
  info->add_option("input", in, "Input mesh")->required();
  info->add_option("--tmp", tmp, "Folder for temporary files (default $TMPDIR or /tmp)");

  std::string tris_text, seed_text = "1";
  CLI::App* generate = app.add_subcommand("generate", "Write a synthetic dense mesh, streamed in O(1) memory");
  generate->add_option("--tris", tris_text, "Number of triangles (approximately), at least 1")->required();
  generate->add_option("--shape", shape, "Shape (default sphere; branches: a leafless tree of thin tubes)")
      ->check(CLI::IsMember({"sphere", "terrain", "parts", "branches"}));
  generate->add_option("--seed", seed_text, "Random seed (default 1)");
  generate->add_option("-o,--output", out, "Output PLY: .ply or .ply.zst (compressed), - for stdout")->required();
  generate->add_flag("--ascii", ascii, "Write ascii PLY");
  bool generate_attributes = false;
  generate->add_flag("--attributes", generate_attributes,
                     "Also write uchar red, green, blue (linear in x, y, z over the bounding box) and float nx, ny, "
                     "nz (the unit surface normal) per vertex");
  generate->add_flag("--quiet", quiet, "No progress");

  std::string second, samples_text, measure_seed_text, measure_threads_text;
  MeasureOptions measure_options;
  bool json = false;
  CLI::App* measure = app.add_subcommand("measure", "Hausdorff, mean and RMS distance between two surfaces");
  measure->add_option("a", in, "Mesh A, streamed (the original; any size)")->required();
  measure->add_option("b", second, "Mesh B, loaded into memory (e.g. the simplification)")->required();
  auto* samples = measure->add_option("--samples", samples_text, "Points sampled on each surface (default 1000000)");
  auto* measure_seed = measure->add_option("--seed", measure_seed_text, "Random seed of the samples (default 1)");
  auto* measure_threads = measure->add_option("--threads", measure_threads_text, "Worker threads (default: all cores)");
  measure->add_option("--tmp", measure_options.temp_dir, "Folder for temporary files (default $TMPDIR or /tmp)");
  measure->add_flag("--json", json, "Print the report as JSON");
  measure->add_flag("--quiet", quiet, "No progress");

  std::string lod_distance, lod_fov, lod_height, lod_factor;
  bool lod_json = false;
  CLI::App* lod_select =
      app.add_subcommand("lod-select", "Pick the level of detail for a viewing distance (Low & Tan §4)");
  lod_select->add_option("lods", in, "OUT.lods.json, written by simplify --lods")->required();
  lod_select->add_option("--distance", lod_distance, "Distance from the camera, model units")->required();
  lod_select->add_option("--fov", lod_fov, "Vertical field of view, degrees")->required();
  lod_select->add_option("--height", lod_height, "Image height, pixels")->required();
  lod_select->add_option("--factor", lod_factor, "Pixels a cell may span, at least 1 (default 5)");
  lod_select->add_flag("--json", lod_json, "Print the choice as JSON");

  std::string render_size, render_view, render_shading = "flat";
  CLI::App* render = app.add_subcommand("render", "Draw a mesh file into a PNG (software rasteriser, streamed)");
  render->add_option("input", in, "Mesh file (PLY, OBJ, STL, optionally .zst)")->required();
  render->add_option("-o,--output", out, "PNG file")->required();
  render->add_option("--size", render_size, "Image size WIDTHxHEIGHT (default 1024x768)");
  render->add_option("--view", render_view,
                     "Camera direction AZIMUTH,ELEVATION in degrees (default 30,20; 0,90 looks straight down)");
  render->add_option("--shading", render_shading, "flat (default) or smooth (the file's vertex normals)")
      ->check(CLI::IsMember({"flat", "smooth"}));
  bool render_thick = false;
  render->add_flag("--thick-edges", render_thick,
                   "Draw edges T/R pixels wide and points as discs T/R across (T their thickness, R the pixel size; "
                   "Low & Tan 1997 sec. 3.3); one pixel wide without");
  render->add_option("--tmp", tmp, "Folder for temporary files (default $TMPDIR or /tmp)");
  render->add_flag("--quiet", quiet, "No progress or summary");

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
    if (*simplify) return run_simplify(sa);
    if (*info) return run_info(in, tmp);
    if (*lod_select) return run_lod_select(in, lod_distance, lod_fov, lod_height, lod_factor, lod_json);
    if (*render) {
      RenderOptions o;
      parse_render_args(render_size, render_view, &o);
      o.shading = render_shading == "smooth" ? Shading::smooth : Shading::flat;
      o.thick_edges = render_thick;
      return run_render(in, out, o, tmp, quiet);
    }
    if (*generate) return run_generate(tris_text, shape, seed_text, out, ascii, generate_attributes, quiet);
    if (*measure) {
      constexpr std::uint64_t kMost = ~std::uint64_t(0);
      if (samples->count() > 0) measure_options.samples = whole_number("--samples", samples_text, 1, kMost);
      if (measure_seed->count() > 0) measure_options.seed = whole_number("--seed", measure_seed_text, 0, kMost);
      if (measure_threads->count() > 0)
        measure_options.threads = unsigned(whole_number("--threads", measure_threads_text, 1, kMaxThreads));
      return run_measure(in, second, measure_options, json, quiet);
    }
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
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kIo;
  }
  return kUsage;
}
