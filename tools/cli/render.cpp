// oocsimp render: a picture of a mesh, PNG or JPEG.
#include "commands.hpp"

namespace oocsimp_cli {

namespace {

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

}  // namespace

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
