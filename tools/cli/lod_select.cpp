// oocsimp lod-select: the level of detail for a viewing distance (Low & Tan §4).
#include "commands.hpp"

namespace oocsimp_cli {

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

}  // namespace oocsimp_cli
