// oocsimp merge: the part files of a distributed run into its output (docs/cluster.md).
#include "commands.hpp"

namespace oocsimp_cli {

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

}  // namespace oocsimp_cli
