// oocsimp generate: synthetic test meshes (oocsimp/generate.hpp).
#include "commands.hpp"

namespace oocsimp_cli {

namespace {

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

}  // namespace

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

}  // namespace oocsimp_cli
