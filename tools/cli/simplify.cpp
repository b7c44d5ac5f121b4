// oocsimp simplify: one mesh, levels of detail, a part of a distributed run or, under
// an MPI launcher, the whole distributed run (docs/cli.md).
#include "commands.hpp"
#include "mpi_run.hpp"

namespace oocsimp_cli {

namespace {

// The size of the output: cell, grid or ratio, or an exact target, and levels of detail.
void add_size_options(CLI::App* cmd, SimplifyArgs& a) {
  add_given(cmd, "--cell", &a.cell, "Cell side in model units (default: from --ratio)");
  add_given(cmd, "--grid", &a.grid,
            "Cells along the longest bounding-box axis, 1 to " + std::to_string(kMaxGridDivisions) +
                " (default: from --ratio)");
  add_given(cmd, "--ratio", &a.ratio, "Approximate fraction of the triangles to keep, in (0, 1] (default 0.1)");
  a.cell.option->excludes(a.grid.option)->excludes(a.ratio.option);
  a.grid.option->excludes(a.ratio.option);
  add_given(cmd, "--target-tris", &a.target_tris,
            "Exactly this many output triangles (at least 4), by quadric edge collapse; with --method floating, "
            "uniform or curvature, clustering to a few times that first (default: no target)");
  add_given(cmd, "--target-ratio", &a.target_ratio,
            "Exactly this fraction of the input's triangles (default: no target)");
  add_given(cmd, "--max-error", &a.max_error,
            "Stop collapsing before an error above this (with or without a count): in model units, or with % a "
            "percentage of the bounding box's diagonal (0.1%; default: no limit)");
  a.refine = add_enum_option(
      cmd, "--refine", &a.options.target.refine, refine_method_names(),
      "With a target: " +
          value_list(refine_method_names(),
                     {{RefineMethod::qem, "edge collapse to it exactly, the default"},
                      {RefineMethod::none, "clustering alone, at a cell chosen for about the target"}}));
  add_given(cmd, "--lods", &a.lods,
            "Write K levels of detail OUT.lod0 ... OUT.lod{K-1} at cells C, C*F, C*F^2, ... and their description "
            "OUT.lods.json (floating cells bin and grade once); with a target, at the target halved per level, "
            "each going on from the finer level's edge collapse (default: one output, no levels)");
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
                "A cell of side s is split where a child's curvatures differ from the cell's by more than "
                "this / s (default 0.5)"),
      add_given(cmd, "--max-depth", &a.max_depth, "Splits of a grid cell, 0 to 6 (default 0)"),
  };
  for (CLI::Option* o : a.curvature_only) o->group("Curvature method only (--method curvature)");
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

// --max-error: a length in model units, or "0.1%", a percentage of the bounding
// box's diagonal, which the library turns into a length once it has read the input.
void set_max_error(const std::string& text, TargetOptions* target) {
  if (!text.empty() && text.back() == '%') {
    const std::string number = text.substr(0, text.size() - 1);
    char* end = nullptr;
    const double percent = std::strtod(number.c_str(), &end);
    if (number.empty() || *end != '\0' || !(percent > 0 && percent <= 100))
      bad_value("--max-error", text, "a length in model units, or a percentage above 0 and at most 100 (0.1%)");
    target->max_error_of_diagonal = percent / 100;
  } else {
    target->max_error = positive_number("--max-error", text);
  }
}

SimplifyPlan check_simplify_args(const SimplifyArgs& a) {
  SimplifyPlan p{a.options, {}, {}};
  SimplifyOptions& o = p.options;
  if (a.target_tris.given()) o.target.triangles = whole_number("--target-tris", a.target_tris.text, 4, kMost);
  if (a.target_ratio.given()) o.target.ratio = positive_number("--target-ratio", a.target_ratio.text, 1.0);
  if (!a.lock_vertices.empty()) o.locked_vertices = read_vertex_list(a.lock_vertices);
  if (a.max_error.given()) set_max_error(a.max_error.text, &o.target);
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
  if (a.mem.given()) o.memory_budget = memory_budget_of(a.mem, minimum_memory_budget());
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

}  // namespace

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
  cmd->add_option("--stats", a.outputs.stats,
                  "Write statistics as JSON to this file (- for stdout; default: none written)");
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
                  "where they are: fixed in the edge collapse, each its own cluster in clustering (default: none)");
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
            "docs/cluster.md; default: the whole run in this process)")
      ->group("Distributed runs");
  cmd->add_option("--work-dir", a.work_dir, "With --part: the folder shared by the parts and the merge (default: none)")
      ->group("Distributed runs");
  return cmd;
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

}  // namespace oocsimp_cli
