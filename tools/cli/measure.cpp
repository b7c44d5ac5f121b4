// oocsimp measure: the symmetric surface distances between two meshes.
#include "commands.hpp"

namespace oocsimp_cli {

namespace {

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

}  // namespace

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

}  // namespace oocsimp_cli
