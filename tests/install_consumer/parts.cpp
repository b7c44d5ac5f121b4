// The targets beside the core library, linked from an installed copy: a generated
// sphere, simplified with a progress bar, measured against itself simplified, and
// drawn into a PNG.
#include <cstdio>
#include <string>

#include "oocsimp/generate.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/oocsimp.hpp"
#include "oocsimp/progress_reporter.hpp"
#include "oocsimp/render.hpp"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const std::string in = std::string(argv[1]) + "/sphere.ply", out = std::string(argv[1]) + "/small.ply";
  oocsimp::ProgressReporter bar(/*quiet=*/false);
  oocsimp::GenerateOptions g;
  g.triangles = 20000;
  g.progress = bar.callback();
  oocsimp::generate_mesh(in, g);
  oocsimp::SimplifyOptions o;
  o.progress = bar.callback();
  oocsimp::simplify_file(in, out, o, nullptr);
  oocsimp::MeasureOptions m;
  m.samples = 10000;
  oocsimp::DistanceReport r = oocsimp::measure_surface_distance(in, out, m);
  std::printf("RMS %.3g of the diagonal\n", r.fraction_of_diagonal(r.symmetric).rms);
  oocsimp::RenderOptions picture;
  picture.width = 64;
  picture.height = 48;
  const oocsimp::RenderStats drawn = oocsimp::render_file(out, std::string(argv[1]) + "/small.png", picture);
  return r.symmetric.rms > 0 && r.symmetric.rms < 0.01 * r.a_diagonal && drawn.covered_pixels > 0 ? 0 : 1;
}
