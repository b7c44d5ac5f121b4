// The targets beside the core library, linked from an installed copy: a generated
// sphere, simplified with a progress bar, measured against itself simplified.
#include <cstdio>
#include <string>

#include "oocsimp/generate.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/oocsimp.hpp"
#include "oocsimp/progress_reporter.hpp"

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
  oocsimp::simplify_file(in, out, false, o, nullptr);
  oocsimp::MeasureOptions m;
  m.samples = 10000;
  oocsimp::DistanceReport r = oocsimp::measure_surface_distance(in, out, m);
  std::printf("RMS %.3g of the diagonal\n", r.fraction_of_diagonal(r.symmetric).rms);
  return r.symmetric.rms > 0 && r.symmetric.rms < 0.01 * r.a_diagonal ? 0 : 1;
}
