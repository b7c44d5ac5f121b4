// Thick edges and points (Low & Tan 1997 §2 step 5, §3.3): thin tubes reduced to
// edges about their diameter thick, tiny closed objects to points, both written and
// read back, drawn at their width, and the same for any threads and tiles.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/math_constants.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/oocsimp.hpp"
#include "oocsimp/render.hpp"
#include "render/rasterizer.hpp"
#include "api/simplify.hpp"
#include "png_support.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

Vec3d vertex(const LoadedMesh& m, std::uint64_t v) {
  return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

double median_thickness(const std::vector<LinePrimitive>& p) {
  std::vector<double> t;
  for (const LinePrimitive& e : p) t.push_back(e.thickness);
  std::sort(t.begin(), t.end());
  return t.empty() ? 0 : t[t.size() / 2];
}

// The area of the output triangles whose centroid lies off the trunk of the branches
// model: farther than `margin` from its axis (x = y = 0.5), or above its top.
double area_off_trunk(const LoadedMesh& m, double margin) {
  double area = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const Vec3d a = vertex(m, m.triangles[3 * t]), b = vertex(m, m.triangles[3 * t + 1]),
                c = vertex(m, m.triangles[3 * t + 2]);
    const double cx = (a.x + b.x + c.x) / 3 - 0.5, cy = (a.y + b.y + c.y) / 3 - 0.5, cz = (a.z + b.z + c.z) / 3;
    if (std::hypot(cx, cy) <= kBranchTrunkRadius + margin && cz <= 0.45 + margin) continue;
    const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z, vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
    area += 0.5 *
            std::sqrt(std::pow(uy * vz - uz * vy, 2) + std::pow(uz * vx - ux * vz, 2) + std::pow(ux * vy - uy * vx, 2));
  }
  return area;
}

SimplifyOptions clustering(ClusterMethod method, double cell, bool thick) {
  SimplifyOptions o;
  o.method = method;
  o.sizing.cell = cell;
  o.thick_edges = thick;
  return o;
}

// A regular octahedron of radius r about c, closed and outward: vertices c +- r e_i.
void add_octahedron(std::vector<float>* p, std::vector<std::uint32_t>* t, double cx, double cy, double cz, double r) {
  const std::uint32_t b = std::uint32_t(p->size() / 3);
  const double v[6][3] = {{r, 0, 0}, {-r, 0, 0}, {0, r, 0}, {0, -r, 0}, {0, 0, r}, {0, 0, -r}};
  for (const auto& d : v) p->insert(p->end(), {float(cx + d[0]), float(cy + d[1]), float(cz + d[2])});
  const std::uint32_t f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                 {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& k : f) t->insert(t->end(), {b + k[0], b + k[1], b + k[2]});
}

}  // namespace

TEST_CASE("thin branches vanish without thick edges and come back as edges 2r thick", "[thick][floating]") {
  ScratchDir d;
  GenerateOptions g;
  g.shape = SyntheticShape::branches;
  g.triangles = 200000;
  generate_mesh(d.file("tree.ply"), g);
  const double cell = 5 * kBranchRadius;
  // The branches' surface: kBranchCount tubes at least 0.25 long.
  const double branch_area = kBranchCount * 2 * kPi * kBranchRadius * 0.25;

  SimplifyStats plain_stats, thick_stats;
  simplify_file(d.file("tree.ply"), d.file("plain.ply"), clustering(ClusterMethod::floating, cell, false),
                &plain_stats);
  simplify_file(d.file("tree.ply"), d.file("thick.ply"), clustering(ClusterMethod::floating, cell, true), &thick_stats);
  const LoadedMesh plain = load_mesh(d.file("plain.ply")), thick = load_mesh(d.file("thick.ply"));

  // Without thick edges, what is left of the branches covers a few percent of them.
  CHECK(plain.edges.empty());
  CHECK(area_off_trunk(plain, cell) < 0.05 * branch_area);
  // With them, the triangles are the same and the branches come back as edges about
  // their diameter thick (Low & Tan §3.3.1: D_A + D_B = 2r on a cylinder).
  CHECK(thick.triangles == plain.triangles);
  CHECK(std::equal(plain.positions.begin(), plain.positions.end(), thick.positions.begin()));
  CHECK(thick.edges.size() >= std::size_t(kBranchCount));
  CHECK(thick_stats.output_edges == thick.edges.size());
  CHECK(std::fabs(median_thickness(thick.edges) - 2 * kBranchRadius) <= 0.3 * 2 * kBranchRadius);
  // The buds that became points are as wide as they are: every vertex of a ball lies
  // r from its centre.
  for (const LinePrimitive& p : thick.points) CHECK(std::fabs(p.thickness - 2 * kBudRadius) <= 0.05 * kBudRadius);
  CHECK(thick_stats.output_points == thick.points.size());

  // The uniform grid makes edges of the same thickness.
  simplify_file(d.file("tree.ply"), d.file("uniform.ply"), clustering(ClusterMethod::uniform, cell, true), nullptr);
  const LoadedMesh uniform = load_mesh(d.file("uniform.ply"));
  CHECK(uniform.edges.size() >= std::size_t(kBranchCount));
  CHECK(std::fabs(median_thickness(uniform.edges) - 2 * kBranchRadius) <= 0.3 * 2 * kBranchRadius);
}

TEST_CASE("thick edges are byte-identical for any threads and tiles", "[thick][determinism]") {
  ScratchDir d;
  GenerateOptions g;
  g.shape = SyntheticShape::branches;
  g.triangles = 100000;
  generate_mesh(d.file("tree.ply"), g);
  for (ClusterMethod method : {ClusterMethod::floating, ClusterMethod::uniform}) {
    INFO(method_name(method));
    std::string first;
    for (unsigned threads : {1u, 2u})
      for (double tile : {0.0, 0.12}) {
        if (method == ClusterMethod::uniform && tile > 0) continue;
        SimplifyOptions o = clustering(method, 5 * kBranchRadius, true);
        o.threads = threads;
        o.floating.tile_side = tile;
        simplify_file(d.file("tree.ply"), d.file("out.ply"), o, nullptr);
        const std::string bytes = read_file(d.file("out.ply"));
        CHECK(bytes.find("element edge") != std::string::npos);
        if (first.empty()) first = bytes;
        CHECK(bytes == first);
      }
  }
}

TEST_CASE("tiny closed objects become points twice their RMS radius wide", "[thick]") {
  ScratchDir d;
  // Six octahedra of radius 0.01, one at the origin (the bounding box starts at its
  // -x, -y, -z vertices) and five 3 apart about the middles of cells of side 1, so
  // that each lies inside one grid cell and far from the others.
  std::vector<float> p;
  std::vector<std::uint32_t> t;
  const double r = 0.01;
  std::vector<Vec3d> centres = {{0, 0, 0}};
  for (int k = 1; k <= 5; ++k) centres.push_back({3 * k + 0.49, 0.49, 0.49});
  for (const Vec3d& c : centres) add_octahedron(&p, &t, c.x, c.y, c.z, r);
  write_binary_ply(d.file("octahedra.ply"), p, t);
  for (ClusterMethod method : {ClusterMethod::uniform, ClusterMethod::floating}) {
    INFO(method_name(method));
    SimplifyStats st;
    simplify_file(d.file("octahedra.ply"), d.file("points.ply"), clustering(method, 1.0, true), &st);
    const LoadedMesh m = load_mesh(d.file("points.ply"));
    CHECK(m.triangle_count() == 0);
    CHECK(m.edges.empty());
    REQUIRE(m.points.size() == centres.size());
    CHECK(st.output_points == centres.size());
    for (const LinePrimitive& pt : m.points) {
      CHECK(pt.thickness == Approx(2 * r).epsilon(1e-4));  // the vertices' RMS distance from their mean is r
      // The point sits at its octahedron (the quadric's minimiser or the mean, in it).
      const Vec3d at = vertex(m, pt.a);
      const Vec3d& c = centres[std::size_t(std::round(at.x / 3))];
      CHECK(std::fabs(at.x - c.x) <= r);
      CHECK(std::fabs(at.y - c.y) <= r);
      CHECK(std::fabs(at.z - c.z) <= r);
    }
    // Without thick edges nothing is left of them.
    simplify_file(d.file("octahedra.ply"), d.file("none.ply"), clustering(method, 1.0, false), nullptr);
    const LoadedMesh none = load_mesh(d.file("none.ply"));
    CHECK(none.vertex_count() == 0);
    CHECK(none.points.empty());
  }
}

TEST_CASE("thick edges and points are written to PLY and OBJ and read back", "[thick][readers][writers]") {
  ScratchDir d;
  const std::vector<double> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 2, 2, 3, 3, 3};
  const std::vector<std::uint32_t> triangles = {0, 1, 2};
  ThickPrimitives prim;
  prim.edges = {2, 3, 3, 4};
  prim.edge_thickness = {0.25f, 0.5f};
  prim.points = {4};
  prim.point_thickness = {0.125f};
  for (const char* name : {"b.ply", "a.ply", "o.obj"}) {
    INFO(name);
    const bool ascii = std::string(name) == "a.ply";
    const MeshFormat format = format_for_path(d.file(name), ascii);
    write_mesh(d.file(name), positions, triangles, format, ScalarType::f32, nullptr, &prim);
    const LoadedMesh m = load_mesh(d.file(name));
    CHECK(m.triangle_count() == 1);
    CHECK(m.info.edge_count == 2);
    CHECK(m.info.point_count == 1);
    REQUIRE(m.edges.size() == 2);
    REQUIRE(m.points.size() == 1);
    CHECK(m.edges[0].a == 2);
    CHECK(m.edges[0].b == 3);
    CHECK(m.edges[1].a == 3);
    CHECK(m.edges[1].b == 4);
    CHECK(m.points[0].a == 4);
    const bool thickness = format != MeshFormat::obj;  // OBJ's l and p have no room for it
    CHECK(m.edges[0].thickness == (thickness ? 0.25f : 0.0f));
    CHECK(m.edges[1].thickness == (thickness ? 0.5f : 0.0f));
    CHECK(m.points[0].thickness == (thickness ? 0.125f : 0.0f));
  }
  CHECK(read_file(d.file("b.ply"))
            .find("element edge 2\nproperty int vertex1\nproperty int vertex2\nproperty float "
                  "thickness\nelement point 1\nproperty int vertex\nproperty float thickness\n") != std::string::npos);
  // An OBJ polyline is its segments, "p" a point per index, negative indices count back.
  write_file(d.file("l.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2/1 3\np -1 1\n");
  const LoadedMesh l = load_mesh(d.file("l.obj"));
  REQUIRE(l.edges.size() == 2);
  CHECK((l.edges[0].a == 0 && l.edges[0].b == 1 && l.edges[1].a == 1 && l.edges[1].b == 2));
  REQUIRE(l.points.size() == 2);
  CHECK((l.points[0].a == 2 && l.points[1].a == 0));
  // A bad index is an input error naming the file and line (exit 3), in both formats.
  write_file(d.file("bad.obj"), "v 0 0 0\nv 1 0 0\nl 1 7\n");
  const CliResult obj = run_cli("info " + q(d.file("bad.obj")));
  CHECK(obj.exit_code == 3);
  CHECK_THAT(obj.err, Catch::Contains(d.file("bad.obj") + ": line 3"));
  write_file(d.file("bad.ply"),
             "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
             "element edge 1\nproperty int vertex1\nproperty int vertex2\nproperty float thickness\nend_header\n"
             "0 0 0\n1 0 0\n0 5 0.1\n");
  const CliResult ply = run_cli("info --quiet " + q(d.file("bad.ply")));
  CHECK(ply.exit_code == 3);
  CHECK_THAT(ply.err, Catch::Contains(d.file("bad.ply") + ": line 14"));  // 11 header lines, 2 vertices
  CHECK(std::count(ply.err.begin(), ply.err.end(), '\n') == 1);
}

TEST_CASE("render draws edges T/R pixels wide and points as discs", "[thick][render]") {
  ScratchDir d;
  // One edge from (0, 0, 0) to (1, 0, 0), thickness 0.1, and one point of width 0.2 at
  // (0.5, 0.5, 0), seen from straight above: no faces at all.
  write_file(d.file("e.ply"),
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element edge 1\nproperty int vertex1\nproperty int vertex2\nproperty float thickness\n"
             "element point 1\nproperty int vertex\nproperty float thickness\nend_header\n"
             "0 0 0\n1 0 0\n0.5 0.5 0\n0 1 0.1\n2 0.2\n");
  // The outline reaches past the vertices by the widths: x from -0.05 to 1.05 (the
  // edge's round ends), y from -0.05 to 0.6 (the edge, the point's disc); the wider,
  // 1.1, x 1.05 over 400 pixels.
  const double pixel = 1.05 * 1.1 / 400;
  const double w = 0.1 / pixel, disc = 0.2 / pixel;
  // A capsule: the line's rectangle and its two half-disc caps; the point's disc.
  const double thick_pixels = (1 / pixel) * w + kPi * w * w / 4 + kPi * disc * disc / 4;
  const CliResult r = run_cli("render --quiet --thick-edges " + q(d.file("e.ply")) + " -o " + q(d.file("t.png")) +
                              " --size 400x400 --view 0,90");
  REQUIRE(r.exit_code == 0);
  CHECK(std::fabs(double(non_white(read_png(d.file("t.png")))) - thick_pixels) <= 0.03 * thick_pixels);
  // Without --thick-edges: one pixel wide, the point one pixel; the outline is the
  // vertices', 1 wide.
  REQUIRE(run_cli("render --quiet " + q(d.file("e.ply")) + " -o " + q(d.file("n.png")) + " --size 400x400 --view 0,90")
              .exit_code == 0);
  const double thin = 400 / 1.05;
  CHECK(std::fabs(double(non_white(read_png(d.file("n.png")))) - thin) <= 4);
  // Through the library, the counts.
  MeshInput m = open_mesh_input(d.file("e.ply"));
  RenderStats st;
  RenderOptions o;
  o.thick_edges = true;
  render_mesh(m, o, &st);
  CHECK(st.triangles == 0);
  CHECK(st.edges == 1);
  CHECK(st.points == 1);
}

TEST_CASE("thick edges: refused with a target, warned about where the format drops them", "[thick][cli]") {
  ScratchDir d;
  std::vector<float> p;
  std::vector<std::uint32_t> t;
  add_octahedron(&p, &t, 0.5, 0.5, 0.5, 0.01);
  add_octahedron(&p, &t, 3.5, 0.5, 0.5, 0.01);
  write_binary_ply(d.file("o.ply"), p, t);
  const CliResult target = run_cli("simplify " + q(d.file("o.ply")) + " -o " + q(d.file("t.ply")) +
                                   " --thick-edges --target-tris 4 --quiet");
  CHECK(target.exit_code == 2);
  CHECK_THAT(target.err, Catch::Contains("--thick-edges"));
  CHECK_FALSE(file_exists(d.file("t.ply")));
  const CliResult stl = run_cli("simplify " + q(d.file("o.ply")) + " -o " + q(d.file("t.stl")) +
                                " --thick-edges --cell 1 --quiet --stats " + q(d.file("s.json")));
  CHECK(stl.exit_code == 0);
  CHECK_THAT(stl.err, Catch::Contains("2 points not written"));
  CHECK_THAT(read_file(d.file("s.json")), Catch::Contains("\"edges\": 0, \"points\": 2"));
  CHECK_THAT(read_file(d.file("s.json")), Catch::Contains("\"thick_edges\": true"));
}

TEST_CASE("thick edges from a mesh in memory touch no temporary folder", "[thick][library]") {
  ScratchDir d;
  GenerateOptions g;
  g.shape = SyntheticShape::branches;
  g.triangles = 50000;
  generate_mesh(d.file("tree.ply"), g);
  const LoadedMesh in = load_mesh(d.file("tree.ply"));
  std::vector<float> xyz(in.positions.begin(), in.positions.end());
  std::vector<std::uint32_t> tri(in.triangles.begin(), in.triangles.end());
  MeshView view;
  view.positions = xyz.data();
  view.vertex_count = in.vertex_count();
  view.indices = tri.data();
  view.triangle_count = in.triangle_count();
  for (ClusterMethod method : {ClusterMethod::floating, ClusterMethod::uniform}) {
    INFO(method_name(method));
    SimplifyOptions o = clustering(method, 5 * kBranchRadius, true);
    o.temp_dir = d.file("no-such-folder");
    const SimplifiedMesh m = simplify_mesh(view, o);
    // The same as from the file.
    o.temp_dir.clear();
    simplify_file(d.file("tree.ply"), d.file("f.ply"), o, nullptr);
    const LoadedMesh f = load_mesh(d.file("f.ply"));
    CHECK(m.primitives.edge_count() == f.edges.size());
    CHECK(m.primitives.point_count() == f.points.size());
    CHECK(m.primitives.edge_count() > 0);
    CHECK(m.triangles.size() == f.triangles.size());
  }
}

TEST_CASE("welded input renumbers the vertices of edges and points too", "[thick][readers]") {
  ScratchDir d;
  // Vertex 3 lies where vertex 0 does: welding makes it vertex 0.
  write_file(d.file("w.ply"),
             "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\n"
             "element edge 1\nproperty int vertex1\nproperty int vertex2\nproperty float thickness\n"
             "element point 1\nproperty int vertex\nproperty float thickness\nend_header\n"
             "0 0 0\n1 0 0\n0 1 0\n0 0 0\n3 0 1 2\n1 3 0.5\n3 0.25\n");
  OpenOptions o;
  o.weld = true;
  MeshInput m = open_mesh_input(d.file("w.ply"), o);
  REQUIRE(m.positions.count == 3);
  std::vector<LinePrimitive> seen;
  m.triangles->set_primitive_sink([&](const LinePrimitive* p, std::size_t n) { seen.insert(seen.end(), p, p + n); });
  std::vector<std::uint64_t> buf(3 * 16);
  while (m.triangles->read(buf.data(), 16) > 0) {
  }
  REQUIRE(seen.size() == 2);
  CHECK(((seen[0].a == 1 && seen[0].b == 0) || (seen[0].a == 0 && seen[0].b == 1)));
  CHECK(seen[0].thickness == 0.5f);
  CHECK(seen[1].a == seen[1].b);
  CHECK(seen[1].a < 3);
  const Vec3d at = m.positions.get(seen[1].a);
  CHECK((at.x == 0 && at.y == 0 && at.z == 0));
}
