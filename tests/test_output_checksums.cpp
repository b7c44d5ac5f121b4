// Output identity across refactorings: the XXH64 of the simplified geometry
// (positions as doubles, then triangle indices) for generated inputs, both methods,
// several cells, both cell shapes, both assignment rules and every representative.
//
// The expected digests were recorded from the code of 2026-12-02 (commit 89c9f18)
// before the floating path was split into stages: the restructuring must
// reproduce that output bit for bit. They are not a statement that the output is
// right (test_floating_clusterer and test_uniform_clusterer check that against
// independent references); a deliberate change of the output updates them, and its
// commit says why.
#include <catch2/catch.hpp>

#include <cinttypes>
#include <cstdio>
#include <string>

#include "io/content_hash.hpp"
#include "oocsimp/generate.hpp"
#include "api/simplify.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

std::uint64_t geometry_digest(const SimplifiedMesh& m) {
  ContentHash h;
  h.add(m.positions.data(), m.positions.size() * sizeof(m.positions[0]));
  h.add(m.triangles.data(), m.triangles.size() * sizeof(m.triangles[0]));
  return h.digest();
}

struct Case {
  const char* name;
  ClusterMethod method;
  std::uint32_t grid;
  CellShape shape;
  AssignRule assign;
  RepresentativeRule representative;
  double tile;                           // in model units; 0 = from the budget
  std::uint64_t sphere, parts, terrain;  // expected digests per generated shape
};

// Tiles of 0.07 units cut the unit-sized shapes into dozens of tiles, so the border
// sweeps and the stitch carry real work.
const Case kCases[] = {
    {"uniform grid 24", ClusterMethod::uniform, 24, CellShape::cube, AssignRule::nearest, RepresentativeRule::quadric,
     0, 0x53a1e9b4bff1debb, 0x9f4a4073ad87737a, 0x68467162d46c8425},
    {"uniform grid 60", ClusterMethod::uniform, 60, CellShape::cube, AssignRule::nearest, RepresentativeRule::quadric,
     0, 0x1f81c41854df052b, 0x04b0c8e75dcf4d30, 0xf07fbc69f7ea9cb4},
    {"floating cube grid 20", ClusterMethod::floating, 20, CellShape::cube, AssignRule::nearest,
     RepresentativeRule::quadric, 0, 0xdbd86d5a21256902, 0x9ba28a10f8314f97, 0xa38835b3feaee3aa},
    {"floating cube grid 48 tiled", ClusterMethod::floating, 48, CellShape::cube, AssignRule::nearest,
     RepresentativeRule::quadric, 0.07, 0xc996fe949dfeb876, 0xeb24be5f29df3bd2, 0x26acaa8cb185f73c},
    {"floating sphere grid 40 tiled", ClusterMethod::floating, 40, CellShape::sphere, AssignRule::nearest,
     RepresentativeRule::quadric, 0.07, 0xb51a8e7d618e1f39, 0x512dbc153f484344, 0x672a6c3acf47fd02},
    {"floating cube heaviest mean", ClusterMethod::floating, 36, CellShape::cube, AssignRule::heaviest,
     RepresentativeRule::mean, 0.07, 0xbe4cd2bb001ce85f, 0xa83a4a9da0273347, 0xaaf25c20861da928},
    {"floating sphere heaviest centre", ClusterMethod::floating, 24, CellShape::sphere, AssignRule::heaviest,
     RepresentativeRule::centre, 0, 0xe422d49c6a4b13d8, 0x13b208a75021b80b, 0xc247aee82d61f0b1},
};

}  // namespace

TEST_CASE("the output of both methods is bit for bit what the pre-stage code gave", "[checksums]") {
  ScratchDir dir;
  const std::pair<SyntheticShape, const char*> shapes[] = {
      {SyntheticShape::sphere, "sphere"}, {SyntheticShape::parts, "parts"}, {SyntheticShape::terrain, "terrain"}};
  std::string record;  // every digest, printed when one differs (to update the table deliberately)
  bool all_equal = true;
  for (const auto& [shape, shape_name] : shapes) {
    GenerateOptions g;
    g.triangles = 60000;
    g.shape = shape;
    g.seed = 7;
    std::string path = dir.file(std::string(shape_name) + ".ply");
    generate_mesh(path, g);
    for (const Case& c : kCases) {
      for (unsigned threads : {1u, 2u}) {
        MeshInput in = open_mesh_input(path);
        SimplifyOptions o;
        o.method = c.method;
        o.sizing.grid = c.grid;
        o.floating.cell_shape = c.shape;
        o.floating.assign = c.assign;
        o.floating.representative = c.representative;
        o.floating.tile_side = c.tile;
        o.threads = threads;
        o.temp_dir = dir.path();
        SimplifiedMesh out = simplify(in, o, nullptr);
        std::uint64_t got = geometry_digest(out);
        std::uint64_t want = shape == SyntheticShape::sphere  ? c.sphere
                             : shape == SyntheticShape::parts ? c.parts
                                                              : c.terrain;
        char line[160];
        std::snprintf(line, sizeof line, "%-8s %-34s threads %u: 0x%016" PRIx64 " (%zu triangles)\n", shape_name,
                      c.name, threads, got, out.triangles.size() / 3);
        record += line;
        INFO(line);
        CHECK(out.triangles.size() / 3 < 3 * g.triangles / 4);  // real simplification, not a copy
        CHECK(got == want);
        all_equal = all_equal && got == want;
      }
    }
  }
  if (!all_equal) WARN("digests now:\n" << record);
}
