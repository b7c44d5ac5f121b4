// --method qem on the generated city block (generate --shape boxes): closed boxes
// tessellated into long thin triangles, with zero-area slivers. Every box is exactly
// 8 corners and 12 triangles, so every target down to 12 triangles a box has an answer
// without error, and the expected figures follow from that geometry alone: the count
// asked, 8 vertices and 12 triangles a box, a closed manifold surface, and distances
// of rounding size.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "oocsimp/generate.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

// The generated block: about 40000 triangles, so 40000 / kBoxesTrianglesEach = 6 boxes
// and enough faces for the collapse's passes (CollapseSettings::pass_faces) to run.
struct City {
  std::string path;
  std::uint64_t boxes = 0;
  double largest_coordinate = 0;
};

City city(const ScratchDir& d, std::uint64_t seed) {
  City c;
  c.path = d.file("city-" + std::to_string(seed) + ".ply");
  GenerateOptions g;
  g.shape = SyntheticShape::boxes;
  g.triangles = 40000;
  g.seed = seed;
  generate_mesh(c.path, g);
  c.boxes = g.triangles / kBoxesTrianglesEach;
  for (double x : load_mesh(c.path).positions) c.largest_coordinate = std::max(c.largest_coordinate, std::fabs(x));
  return c;
}

// Edges that are not in exactly two faces running them in opposite directions: holes,
// non-manifold edges and flipped neighbours all count.
std::size_t bad_edges(const LoadedMesh& m) {
  std::map<std::pair<std::uint64_t, std::uint64_t>, int> directed;
  for (std::size_t t = 0; t < m.triangles.size(); t += 3)
    for (int k = 0; k < 3; ++k) ++directed[{m.triangles[t + std::size_t(k)], m.triangles[t + std::size_t(k + 1) % 3]}];
  std::size_t bad = 0;
  for (const auto& e : directed) {
    const auto twin = directed.find({e.first.second, e.first.first});
    bad += e.second != 1 || twin == directed.end() || twin->second != 1;
  }
  return bad;
}

struct Collapsed {
  LoadedMesh mesh;
  DistanceReport distance;
};

Collapsed collapse(const ScratchDir& d, const City& c, std::uint64_t target, double max_error = 0) {
  SimplifyOptions o;
  o.method = ClusterMethod::qem;
  o.target.triangles = target;
  o.target.max_error = max_error;
  const std::string out = d.file("out.ply");
  simplify_file(c.path, out, o, nullptr);
  Collapsed r;
  r.mesh = load_mesh(out);
  MeasureOptions mo;
  mo.samples = OOCSIMP_TEST_UNDER_ASAN ? 20000 : 100000;
  r.distance = measure_surface_distance(c.path, out, mo);
  return r;
}

// The result is the input's surface: a box's corners are input vertices, a collapse
// that keeps a vertex keeps its position, and a placement computed at a corner (three
// planes meeting) is written as the float nearest it, the corner itself. The
// distances left are the rounding of the distance queries, about 1e-16 of the
// diagonal; a box whose corner is cut is off by 1e-3 of it or more. Hausdorff: at most
// the float rounding of each coordinate (2^-24 of the largest); RMS: 1e-9.
void check_exact(const Collapsed& r, const City& c) {
  const DistanceStats rms = r.distance.fraction_of_diagonal(r.distance.symmetric);
  INFO("rms/diagonal " << rms.rms << ", Hausdorff/diagonal " << rms.max);
  CHECK(rms.rms <= 1e-9);
  CHECK(r.distance.symmetric.max <= std::sqrt(3.0) * std::ldexp(c.largest_coordinate, -24));
  CHECK(bad_edges(r.mesh) == 0);
}

}  // namespace

TEST_CASE("qem takes a block of boxes to 12 triangles a box without error, closed", "[boxes][collapse]") {
  ScratchDir d;
  // Seeds whose blocks the passes once cut (RMS 0.7% to 1.3% of the diagonal at 12 a box).
  for (std::uint64_t seed : {2, 3}) {
    if (OOCSIMP_TEST_UNDER_ASAN && seed != 2) continue;
    INFO("seed " << seed);
    const City c = city(d, seed);
    const Collapsed r = collapse(d, c, 12 * c.boxes);
    CHECK(r.mesh.triangle_count() == 12 * c.boxes);
    CHECK(r.mesh.vertex_count() == 8 * c.boxes);  // V = 2 + E - F = 2 + 18 - 12 a closed box
    check_exact(r, c);
  }
}

TEST_CASE("qem to moderate targets of a block of boxes has no error either", "[boxes][collapse]") {
  ScratchDir d;
  for (std::uint64_t seed : {2, 3}) {
    if (OOCSIMP_TEST_UNDER_ASAN && seed != 3) continue;
    const City c = city(d, seed);
    // Twice the least count (once cut by 0.3% to 0.7% of the diagonal), and 2% of the
    // input.
    for (std::uint64_t target : {24 * c.boxes, std::uint64_t(std::llround(0.02 * 40000))}) {
      INFO("seed " << seed << ", target " << target);
      const Collapsed r = collapse(d, c, target);
      CHECK(r.mesh.triangle_count() == target);
      check_exact(r, c);
    }
  }
}

TEST_CASE("a small --max-error takes a block of boxes down to 12 triangles a box, not above", "[boxes][collapse]") {
  ScratchDir d;
  const City c = city(d, 2);
  // Below 12 triangles a box a collapse removes a corner, which moves the surface by a
  // good part of a box's side (0.05 at least); above, some collapse costs nothing. So
  // with any maximum between the rounding of the quadrics (about 1e-8 here) and that,
  // the collapse stops at exactly 12 a box.
  const Collapsed r = collapse(d, c, 4, 1e-6);
  CHECK(r.mesh.triangle_count() == 12 * c.boxes);
  check_exact(r, c);
}
