// The 4-k hierarchy (Velho 1999): level ratios, topology at every level and for
// regions (manifold, Euler characteristic, boundary loops, no face of no area, none
// turned over), crack-free region extraction checked edge by edge, the queries, the
// .4k file's round trip and its damage handling, and the same bytes for any thread
// count. Expected values come from the shapes (a sphere's Euler characteristic is 2,
// its faces face away from its centre; a height field's faces face up) and from the
// input mesh measured by the same independent counting.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "common/math_constants.hpp"
#include "hierarchy/four_face_simplifier.hpp"
#include "hierarchy/four_k_mesh.hpp"
#include "io/attribute_array.hpp"
#include "io/content_hash.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

struct Mesh {
  std::vector<double> positions;
  std::vector<std::uint32_t> triangles;
};

MeshView view_of(const Mesh& m) {
  MeshView v;
  v.positions = m.positions.data();
  v.position_type = ScalarType::f64;
  v.vertex_count = m.positions.size() / 3;
  v.indices = m.triangles.data();
  v.triangle_count = m.triangles.size() / 3;
  return v;
}

// A unit sphere as latitude rings (a triangle fan at each pole), rings x segments.
Mesh uv_sphere(int rings, int segments) {
  Mesh m;
  m.positions = {0, 0, 1};
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double theta = kPi * i / rings, phi = 2 * kPi * j / segments;
      m.positions.insert(m.positions.end(),
                         {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    }
  m.positions.insert(m.positions.end(), {0, 0, -1});
  const std::uint32_t south = std::uint32_t(m.positions.size() / 3 - 1);
  auto at = [&](int ring, int j) { return std::uint32_t(1 + (ring - 1) * segments + (j % segments)); };
  for (int j = 0; j < segments; ++j) m.triangles.insert(m.triangles.end(), {0, at(1, j), at(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const std::uint32_t a = at(i, j), b = at(i, j + 1), c = at(i + 1, j), d = at(i + 1, j + 1);
      m.triangles.insert(m.triangles.end(), {a, c, d});
      m.triangles.insert(m.triangles.end(), {a, d, b});
    }
  for (int j = 0; j < segments; ++j)
    m.triangles.insert(m.triangles.end(), {at(rings - 1, j + 1), at(rings - 1, j), south});
  return m;
}

// z = 0.1 sin(3x) cos(2y) over a grid of n x n squares on the unit square.
Mesh height_field(int n) {
  Mesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = double(j) / n, y = double(i) / n;
      m.positions.insert(m.positions.end(), {x, y, 0.1 * std::sin(3 * x) * std::cos(2 * y)});
    }
  auto at = [&](int i, int j) { return std::uint32_t(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.insert(m.triangles.end(), {at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      m.triangles.insert(m.triangles.end(), {at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  return m;
}

Mesh generated(SyntheticShape shape, std::uint64_t triangles, const ScratchDir& tmp) {
  GenerateOptions g;
  g.shape = shape;
  g.triangles = triangles;
  const std::string path = tmp.file("generated.ply");
  generate_mesh(path, g);
  const LoadedMesh loaded = load_mesh(path);
  Mesh m;
  m.positions = loaded.positions;
  for (std::uint64_t v : loaded.triangles) m.triangles.push_back(std::uint32_t(v));
  return m;
}

// Every face's normal along `outward(centroid)` (positive dot product).
template <class Outward>
std::size_t turned_faces(const SimplifiedMesh& m, const Outward& outward) {
  std::size_t turned = 0;
  for (std::size_t f = 0; f < m.triangles.size(); f += 3) {
    const double* a = &m.positions[3 * m.triangles[f]];
    const double* b = &m.positions[3 * m.triangles[f + 1]];
    const double* c = &m.positions[3 * m.triangles[f + 2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double centre[3] = {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3};
    const std::array<double, 3> out = outward(centre);
    if (!(n[0] * out[0] + n[1] * out[1] + n[2] * out[2] > 0)) ++turned;
  }
  return turned;
}

// The volume a closed mesh encloses, positive when its faces face out.
double signed_volume(const SimplifiedMesh& m) {
  double six = 0;
  for (std::size_t f = 0; f < m.triangles.size(); f += 3) {
    const double* a = &m.positions[3 * m.triangles[f]];
    const double* b = &m.positions[3 * m.triangles[f + 1]];
    const double* c = &m.positions[3 * m.triangles[f + 2]];
    six += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return six / 6;
}

SimplifiedMesh level(const MeshHierarchy& h, std::uint32_t j,
                     HierarchyPlacement placement = HierarchyPlacement::quadric) {
  HierarchyQuery q;
  q.level = j;
  q.placement = placement;
  return extract_mesh(h, q);
}

// A generated mesh, and the PLY in `tmp` it is written to for the distance measure.
struct WrittenMesh {
  Mesh mesh;
  std::string path;
};
WrittenMesh written(SyntheticShape shape, std::uint64_t triangles, const ScratchDir& tmp) {
  WrittenMesh w{generated(shape, triangles, tmp), tmp.file("input.ply")};
  write_mesh(w.path, w.mesh.positions, w.mesh.triangles, MeshFormat::ply_binary, ScalarType::f64, nullptr);
  return w;
}

// The symmetric distance between the meshes at two paths, as fractions of the first's
// bounding-box diagonal (fewer samples under the sanitizers).
DistanceStats distance_between(const std::string& a, const std::string& b) {
  MeasureOptions mo;
  mo.samples = OOCSIMP_TEST_UNDER_ASAN ? 20000 : 100000;
  const DistanceReport d = measure_surface_distance(a, b, mo);
  return d.fraction_of_diagonal(d.symmetric);
}

}  // namespace

TEST_CASE("each level of a sphere keeps it closed, manifold, of Euler characteristic 2 and facing out", "[hierarchy]") {
  const Mesh sphere = uv_sphere(60, 80);
  const MeshHierarchy h = build_hierarchy(view_of(sphere), {});
  REQUIRE(h.levels.size() > 10);
  CHECK(h.levels.back().triangles <= 8);
  for (std::uint32_t j = 0; j < h.levels.size(); ++j) {
    const SimplifiedMesh m = level(h, j);
    const Topology t = topology(m.positions, m.triangles);
    INFO("level " << j << ", " << t.faces << " faces");
    CHECK(t.faces == h.levels[j].triangles);
    CHECK(t.vertices == h.levels[j].vertices);
    CHECK(t.manifold);
    CHECK(t.boundary_edges == 0);
    CHECK(t.euler() == 2);
    CHECK(t.zero_area == 0);
    // Facing out: the enclosed volume is positive, and while the faces are small
    // beside the sphere, each faces away from its centre.
    CHECK(signed_volume(m) > 0);
    if (t.faces >= 200)
      CHECK(turned_faces(m, [](const double* c) { return std::array<double, 3>{c[0], c[1], c[2]}; }) == 0);
  }
}

// The root-mean-square distance of a mesh's surface from the unit sphere, |(|x| - 1)|
// at 10 points of each face (its corners, edge midpoints, thirds and centroid),
// weighted by the face's area.
double rms_off_unit_sphere(const SimplifiedMesh& m) {
  static const double kPoints[10][3] = {{1, 0, 0},
                                        {0, 1, 0},
                                        {0, 0, 1},
                                        {.5, .5, 0},
                                        {0, .5, .5},
                                        {.5, 0, .5},
                                        {2. / 3, 1. / 6, 1. / 6},
                                        {1. / 6, 2. / 3, 1. / 6},
                                        {1. / 6, 1. / 6, 2. / 3},
                                        {1. / 3, 1. / 3, 1. / 3}};
  double sum = 0, weight = 0;
  for (std::size_t f = 0; f < m.triangles.size(); f += 3) {
    const double* c[3];
    for (int k = 0; k < 3; ++k) c[k] = &m.positions[3 * m.triangles[f + std::size_t(k)]];
    const double u[3] = {c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2]};
    const double w[3] = {c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2]};
    const double area =
        0.5 * std::sqrt(std::pow(u[1] * w[2] - u[2] * w[1], 2) + std::pow(u[2] * w[0] - u[0] * w[2], 2) +
                        std::pow(u[0] * w[1] - u[1] * w[0], 2));
    for (const auto& b : kPoints) {
      double p[3];
      for (int d = 0; d < 3; ++d) p[d] = b[0] * c[0][d] + b[1] * c[1][d] + b[2] * c[2][d];
      const double off = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1;
      sum += area * off * off;
      weight += area;
    }
  }
  return std::sqrt(sum / weight);
}

TEST_CASE("vertices placed at their quadrics' minima bring each level closer to the sphere it stands for",
          "[hierarchy]") {
  // Kept in place, every vertex lies on the unit sphere and every face is a chord
  // inside it; the quadric of the faces a vertex stands for is least a little outside,
  // where the faces straddle the sphere, as an edge collapse places its vertex.
  const Mesh sphere = uv_sphere(60, 80);
  const MeshHierarchy h = build_hierarchy(view_of(sphere), {});
  std::uint32_t checked = 0;
  for (std::uint32_t j = 2; j < h.levels.size() && h.levels[j].triangles >= 200; j += 2) {
    const SimplifiedMesh kept = level(h, j, HierarchyPlacement::kept), placed = level(h, j);
    const double off_kept = rms_off_unit_sphere(kept), off_placed = rms_off_unit_sphere(placed);
    INFO("level " << j << ", " << h.levels[j].triangles << " faces: " << off_kept << " kept, " << off_placed
                  << " placed");
    CHECK(placed.triangles == kept.triangles);
    CHECK(off_placed < 0.8 * off_kept);
    ++checked;
  }
  CHECK(checked >= 3);
}

TEST_CASE("each level of a height field keeps one outline, Euler characteristic 1 and every face up", "[hierarchy]") {
  const Mesh field = height_field(60);
  const MeshHierarchy h = build_hierarchy(view_of(field), {});
  REQUIRE(h.levels.size() > 5);
  for (std::uint32_t j = 0; j < h.levels.size(); ++j) {
    const SimplifiedMesh m = level(h, j);
    const Topology t = topology(m.positions, m.triangles);
    INFO("level " << j << ", " << t.faces << " faces");
    CHECK(t.manifold);
    CHECK(t.boundary_loops == 1);
    CHECK(t.euler() == 1);
    CHECK(t.zero_area == 0);
    CHECK(turned_faces(m, [](const double*) { return std::array<double, 3>{0, 0, 1}; }) == 0);
  }
}

TEST_CASE("levels of CAD parts stay on the input's surface while it has vertices to spare", "[hierarchy]") {
  // The generated parts are boxes and cylinders tessellated more finely than their
  // shape needs (flat faces, straight rulings): down to a sixth of the faces, every
  // level can remove only vertices whose faces are coplanar and stay on the surface.
  // What is left is the rounding of the input's float positions, which lie on their
  // planes to about 3e-8 of the diagonal. A swap
  // priced by the quadric of every face at an end of its new edge (not the plane of
  // the face it replaces) took swaps across bends there: 1.6e-3 from level 1 on.
  ScratchDir tmp;
  const WrittenMesh parts = written(SyntheticShape::parts, 60000, tmp);
  const MeshHierarchy h = build_hierarchy(view_of(parts.mesh), {});
  std::uint32_t checked = 0;
  for (std::uint32_t j = 1; j < h.levels.size() && 6 * h.levels[j].triangles >= h.levels[0].triangles; ++j) {
    const SimplifiedMesh m = level(h, j);
    const std::string out = tmp.file("level.ply");
    write_mesh(out, m.positions, m.triangles, MeshFormat::ply_binary, ScalarType::f64, nullptr);
    INFO("level " << j << ", " << h.levels[j].triangles << " faces");
    CHECK(distance_between(parts.path, out).max < 1e-6);
    ++checked;
  }
  CHECK(checked >= 4);
}

TEST_CASE("a sphere's levels are within 1.3x of the edge collapse's RMS at their counts", "[hierarchy]") {
  // The aim for the hierarchy's quality: each level as close to the input as oocsimp's
  // QEM edge collapse brought to the same triangle count, measured the same way
  // (symmetric RMS distance). The first level of a smooth sphere is where independent
  // sets hurt most (at 70% of the triangles every removal is cheap, and a set leaves
  // cheap ones waiting beside those it took): on this 20k sphere two sets a level came
  // to 1.32x there, the default three to 1.12x.
  ScratchDir tmp;
  const WrittenMesh sphere = written(SyntheticShape::sphere, 20000, tmp);
  const MeshHierarchy h = build_hierarchy(view_of(sphere.mesh), {});
  for (const std::uint32_t j : {1u, 2u, 3u, 5u}) {
    REQUIRE(j < h.levels.size());
    const SimplifiedMesh m = level(h, j);
    const std::string out = tmp.file("level.ply"), qem = tmp.file("qem.ply");
    write_mesh(out, m.positions, m.triangles, MeshFormat::ply_binary, ScalarType::f64, nullptr);
    SimplifyOptions o;
    o.method = ClusterMethod::qem;
    o.target.triangles = m.triangles.size() / 3;
    simplify_file(sphere.path, qem, o, nullptr);
    const double ours = distance_between(sphere.path, out).rms, collapse = distance_between(sphere.path, qem).rms;
    INFO("level " << j << ", " << m.triangles.size() / 3 << " faces: RMS " << ours << " against " << collapse);
    CHECK(ours < 1.3 * collapse);
  }
}

TEST_CASE("every level holds at most 0.75 of the triangles of the level before", "[hierarchy]") {
  // Velho reports 0.66-0.74 a level. Late levels of a rough height field remove a few
  // vertices each (the flip and crease guards refuse the rest), so there a level
  // takes several independent sets, and a last level that stays above 0.75 joins the
  // one before. Also with Velho's own levels (level_ratio 0: all a set can take), and
  // with Velho's levels of one set (the default has three).
  ScratchDir tmp;
  for (const SyntheticShape shape : {SyntheticShape::sphere, SyntheticShape::terrain, SyntheticShape::parts})
    for (const int mode : {0, 1, 2, 3}) {
      const Mesh m = generated(shape, 20000, tmp);
      HierarchyOptions options;
      options.independent = mode != 1;
      if (mode == 2) {
        options.level_ratio = 0;
        options.sets_per_level = 1;
      }
      if (mode == 3) options.sets_per_level = 1;
      const MeshHierarchy h = build_hierarchy(view_of(m), options);
      REQUIRE(h.levels.size() > 5);
      for (std::size_t j = 1; j < h.levels.size(); ++j) {
        INFO("shape " << int(shape) << ", mode " << mode << ", level " << j << " of " << h.levels.size());
        CHECK(double(h.levels[j].triangles) <= 0.75 * double(h.levels[j - 1].triangles));
        // While there is plenty to remove, a level ends near --level-ratio whatever
        // its sets: each of two ends at sqrt(0.7) of its start.
        if (mode != 2 && h.levels[j - 1].triangles >= 4000)
          CHECK(double(h.levels[j].triangles) >= 0.69 * double(h.levels[j - 1].triangles));
      }
      // The parts keep their topology at every level, whatever it is.
      const Topology finest = topology(m.positions, m.triangles);
      for (std::uint32_t j = 0; j < h.levels.size(); j += 3) {
        const SimplifiedMesh l = level(h, j);
        const Topology t = topology(l.positions, l.triangles);
        INFO("shape " << int(shape) << ", mode " << mode << ", level " << j);
        CHECK(t.manifold);
        CHECK(t.euler() == finest.euler());
        CHECK(t.boundary_loops == finest.boundary_loops);
        CHECK(t.zero_area == 0);
      }
    }
}

TEST_CASE("a region keeps every finest face that meets it, and the mesh around it has no crack", "[hierarchy]") {
  const Mesh sphere = uv_sphere(60, 80);
  const MeshHierarchy h = build_hierarchy(view_of(sphere), {});
  const std::uint32_t coarse = std::uint32_t(h.levels.size() / 2);
  for (const bool ball : {false, true}) {
    HierarchyQuery q;
    q.level = coarse;
    if (ball) {
      q.region = HierarchyQuery::Region::sphere;
      q.centre = {1, 0, 0};
      q.radius = 0.3;
    } else {
      q.region = HierarchyQuery::Region::box;
      q.box.min = {-0.2, -0.2, 0.8};
      q.box.max = {0.2, 0.2, 1.2};
    }
    const SimplifiedMesh m = extract_mesh(h, q);
    // Edge by edge: each directed edge once, and its reverse there too.
    const Topology t = topology(m.positions, m.triangles);
    CHECK(t.manifold);
    CHECK(t.boundary_edges == 0);
    CHECK(t.euler() == 2);
    CHECK(m.triangles.size() / 3 > h.levels[coarse].triangles);
    // Every finest face meeting the region is there, by its corners' positions.
    std::set<std::array<double, 9>> faces;
    for (std::size_t f = 0; f < m.triangles.size(); f += 3) {
      std::array<double, 9> key{};
      for (int k = 0; k < 3; ++k)
        for (int d = 0; d < 3; ++d)
          key[std::size_t(3 * k + d)] = m.positions[3 * m.triangles[f + std::size_t(k)] + std::size_t(d)];
      faces.insert(key);
    }
    std::size_t meeting = 0, kept = 0;
    for (std::size_t f = 0; f < sphere.triangles.size(); f += 3) {
      std::array<double, 9> key{};
      bool in = false;
      for (int k = 0; k < 3; ++k) {
        const double* p = &sphere.positions[3 * sphere.triangles[f + std::size_t(k)]];
        for (int d = 0; d < 3; ++d) key[std::size_t(3 * k + d)] = p[d];
        // A corner inside is enough for the face to meet the region.
        in = in || (ball ? std::hypot(p[0] - 1, p[1], p[2]) <= 0.3
                         : std::fabs(p[0]) <= 0.2 && std::fabs(p[1]) <= 0.2 && p[2] >= 0.8);
      }
      if (!in) continue;
      ++meeting;
      kept += faces.count(key);
    }
    CHECK(meeting > 20);
    CHECK(kept == meeting);
  }
}

TEST_CASE("a triangle count gives the finest state at or below it, an error bound the records within it",
          "[hierarchy]") {
  const Mesh sphere = uv_sphere(40, 60);
  const MeshHierarchy h = build_hierarchy(view_of(sphere), {});
  for (const std::uint64_t n : {std::uint64_t(3000), std::uint64_t(1001), std::uint64_t(100)}) {
    HierarchyQuery q;
    q.triangles = n;
    const SimplifiedMesh m = extract_mesh(h, q);
    // A removal inside takes two faces: the first state at or below n.
    CHECK(m.triangles.size() / 3 <= n);
    CHECK(m.triangles.size() / 3 + 2 > n);
    CHECK(topology(m.positions, m.triangles).euler() == 2);
  }
  // The bound of a level's largest record error takes that level at least.
  for (std::uint32_t j = 1; j < h.levels.size(); j += 4) {
    HierarchyQuery q;
    q.error = h.levels[j].largest_error;
    const SimplifiedMesh m = extract_mesh(h, q);
    INFO("level " << j);
    CHECK(m.triangles.size() / 3 <= h.levels[j].triangles);
    const Topology t = topology(m.positions, m.triangles);
    CHECK(t.manifold);
    CHECK(t.euler() == 2);
  }
  HierarchyQuery none;
  none.error = 0;
  CHECK(extract_mesh(h, none).triangles.size() == sphere.triangles.size());
}

TEST_CASE("queries beyond the hierarchy are refused, saying what there is", "[hierarchy]") {
  const Mesh sphere = uv_sphere(20, 30);
  const MeshHierarchy h = build_hierarchy(view_of(sphere), {});
  HierarchyQuery q;
  q.level = std::uint32_t(h.levels.size());
  CHECK_THROWS_WITH(extract_mesh(h, q), Catch::Contains("levels 0 to " + std::to_string(h.levels.size() - 1)));
  q = {};
  q.triangles = 2;
  CHECK_THROWS_WITH(extract_mesh(h, q), Catch::Contains(std::to_string(h.levels.back().triangles) + " triangles"));
  q = {};
  q.level = 1;
  q.region = HierarchyQuery::Region::sphere;
  q.centre = {5, 5, 5};
  q.radius = 0.5;
  CHECK_THROWS_WITH(extract_mesh(h, q), Catch::Contains("meets no face") && Catch::Contains("bounds"));
  q = {};
  CHECK_THROWS_AS(extract_mesh(h, q), UsageError);
  q.level = 1;
  q.placement = HierarchyPlacement(7);
  CHECK_THROWS_WITH(extract_mesh(h, q), Catch::Contains("query.placement 7"));
}

TEST_CASE("vertices that share a position stay together when the others are placed", "[hierarchy]") {
  // A uv sphere cut along one meridian: the seam's vertices are two copies each, one
  // per side, as a texture seam has them. Placed each at its own quadric's minimum
  // (each side's quadric holds its own faces' planes) the two sides would part.
  Mesh cut = uv_sphere(40, 60);
  const std::size_t n = cut.positions.size() / 3;
  std::vector<std::uint32_t> copy(n, 0);
  for (std::uint32_t v = 1; v + 1 < n; ++v)
    if ((v - 1) % 60 == 0) {  // segment 0 of each ring: phi = 0
      copy[v] = std::uint32_t(cut.positions.size() / 3);
      cut.positions.insert(cut.positions.end(),
                           {cut.positions[3 * v], cut.positions[3 * v + 1], cut.positions[3 * v + 2]});
    }
  // The faces of the last segment (between phi = 354 and 360 degrees) take the copies.
  for (std::size_t f = 0; f < cut.triangles.size(); f += 3) {
    bool last_segment = false;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = cut.triangles[f + std::size_t(k)];
      last_segment = last_segment || (v > 0 && v + 1 < n && (v - 1) % 60 == 59);
    }
    if (!last_segment) continue;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& v = cut.triangles[f + std::size_t(k)];
      if (v < n && copy[v]) v = copy[v];
    }
  }
  const MeshHierarchy h = build_hierarchy(view_of(cut), {});
  std::uint32_t moved = 0, pairs = 0;
  for (std::uint32_t j = 1; j < h.levels.size() && h.levels[j].triangles >= 500; ++j) {
    const SimplifiedMesh kept = level(h, j, HierarchyPlacement::kept), placed = level(h, j);
    REQUIRE(placed.positions.size() == kept.positions.size());
    std::map<std::array<double, 3>, std::vector<std::size_t>> at;
    for (std::size_t v = 0; v < kept.positions.size() / 3; ++v)
      at[{kept.positions[3 * v], kept.positions[3 * v + 1], kept.positions[3 * v + 2]}].push_back(v);
    for (const auto& [where, vertices] : at) {
      if (vertices.size() < 2) continue;
      ++pairs;
      for (std::size_t v : vertices)
        for (int d = 0; d < 3; ++d) CHECK(placed.positions[3 * v + std::size_t(d)] == where[std::size_t(d)]);
    }
    moved += placed.positions != kept.positions;
  }
  CHECK(pairs > 100);
  CHECK(moved > 0);
}

TEST_CASE("a vertex where two fans meet is split, an edge of three faces cut (refused without repair)", "[hierarchy]") {
  // Two tetrahedra sharing vertex 0.
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0, 0, -1, 0, 0, 0, -1};
  m.triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 0, 5, 4, 0, 4, 6, 0, 6, 5, 4, 5, 6};
  const MeshHierarchy h = build_hierarchy(view_of(m), {});
  CHECK(h.positions.size() / 3 == 8);  // one copy of vertex 0
  const SimplifiedMesh finest = level(h, 0);
  CHECK(topology(finest.positions, finest.triangles).manifold);
  // Three faces on edge 0-1.
  Mesh fin;
  fin.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1};
  fin.triangles = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  HierarchyOptions strict;
  strict.repair = false;
  CHECK_THROWS_WITH(build_hierarchy(view_of(fin), strict),
                    Catch::Contains("edge from vertex") && Catch::Contains("--repair"));
  const MeshHierarchy repaired = build_hierarchy(view_of(fin), {});
  const SimplifiedMesh fin_finest = level(repaired, 0);
  CHECK(fin_finest.triangles.size() == 9);
  CHECK(topology(fin_finest.positions, fin_finest.triangles).manifold);
}

namespace {

// The unit cube, 12 faces wound outwards.
Mesh unit_cube() {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  m.triangles = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                 3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  return m;
}

// Six times the signed volume the faces enclose: positive when they face out.
double six_volume(const std::vector<double>& p, const std::vector<std::uint32_t>& t) {
  double v = 0;
  for (std::size_t f = 0; f < t.size(); f += 3) {
    const double* a = &p[3 * t[f]];
    const double* b = &p[3 * t[f + 1]];
    const double* c = &p[3 * t[f + 2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v;
}

}  // namespace

TEST_CASE("hierarchy repairs a soup's winding and non-manifold edges, and says so", "[hierarchy][cli]") {
  // A cube with two faces wound inwards, as CAD exports often have: the two turn, the
  // other ten keep their winding, and the cube stays closed (Euler characteristic 2).
  Mesh cube = unit_cube();
  for (std::size_t f : {2, 7}) std::swap(cube.triangles[3 * f + 1], cube.triangles[3 * f + 2]);
  HierarchyOptions strict;
  strict.repair = false;
  CHECK_THROWS_WITH(build_hierarchy(view_of(cube), strict), Catch::Contains("--repair"));
  const SimplifiedMesh turned = level(build_hierarchy(view_of(cube), {}), 0);
  const Topology t = topology(turned.positions, turned.triangles);
  CHECK(t.manifold);
  CHECK(t.euler() == 2);
  CHECK(t.boundary_edges == 0);
  CHECK(six_volume(turned.positions, turned.triangles) == Approx(6.0));  // facing out: volume 1
  // The same cube wound inwards everywhere but two faces: the majority's winding wins.
  Mesh inside = unit_cube();
  for (std::size_t f = 0; f < 12; ++f)
    if (f != 2 && f != 7) std::swap(inside.triangles[3 * f + 1], inside.triangles[3 * f + 2]);
  const SimplifiedMesh in = level(build_hierarchy(view_of(inside), {}), 0);
  CHECK(six_volume(in.positions, in.triangles) == Approx(-6.0));

  // Two cubes sharing an edge (four faces on it) and a Moebius-like strip: each side
  // of a cut edge gets its own copies of the edge's ends; every face is kept.
  // The second is the first moved by (1, 1, 0): its edge from vertex 0 to 4 is the
  // first's from 2 (1, 1, 0) to 6 (1, 1, 1); its other six vertices are new.
  Mesh two = unit_cube();
  const Mesh second = unit_cube();
  const std::uint32_t renumber[8] = {2, 8, 9, 10, 6, 11, 12, 13};
  for (const std::uint32_t v : {1, 2, 3, 5, 6, 7}) {
    two.positions.push_back(second.positions[3 * v] + 1);
    two.positions.push_back(second.positions[3 * v + 1] + 1);
    two.positions.push_back(second.positions[3 * v + 2]);
  }
  for (const std::uint32_t v : second.triangles) two.triangles.push_back(renumber[v]);
  const SimplifiedMesh pair = level(build_hierarchy(view_of(two), {}), 0);
  CHECK(pair.triangles.size() == 72);
  const Topology pt = topology(pair.positions, pair.triangles);
  CHECK(pt.manifold);
  CHECK(pt.euler() == 4);  // two closed surfaces again
  Mesh strip;              // a band of 4 quads whose ends meet with a half twist
  strip.positions = {0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 1, 2, 1, 1, 1, 0, 2, 1, 1, 2};
  strip.triangles = {0, 2, 1, 1, 2, 3, 2, 4, 3, 3, 4, 5, 4, 6, 5, 5, 6, 7, 6, 1, 7, 7, 1, 0};
  const SimplifiedMesh band = level(build_hierarchy(view_of(strip), {}), 0);
  CHECK(band.triangles.size() == 24);
  CHECK(topology(band.positions, band.triangles).manifold);

  // The command line: repaired with a warning by default, refused with --no-repair
  // (exit 3, one line naming the file and the option).
  ScratchDir d;
  std::vector<float> p(cube.positions.begin(), cube.positions.end());
  write_binary_ply(d.file("cad.ply"), p, cube.triangles);
  const CliResult r = run_cli("hierarchy --quiet " + d.file("cad.ply") + " -o " + d.file("c.4k"));
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.err, Catch::Contains("warning") && Catch::Contains("repaired: 2 faces turned"));
  CHECK(file_exists(d.file("c.4k")));
  const CliResult no = run_cli("hierarchy --quiet --no-repair " + d.file("cad.ply") + " -o " + d.file("n.4k"));
  CHECK(no.exit_code == 3);
  CHECK(std::count(no.err.begin(), no.err.end(), '\n') == 1);
  CHECK_THAT(no.err, Catch::Contains("cad.ply") && Catch::Contains("--repair"));
  CHECK_FALSE(file_exists(d.file("n.4k")));
}

TEST_CASE("the .4k file reads back as written, and the same bytes come for any thread count", "[hierarchy][file]") {
  ScratchDir tmp;
  const Mesh sphere = uv_sphere(30, 40);
  HierarchyOptions one;
  one.threads = 1;
  const MeshHierarchy h = build_hierarchy(view_of(sphere), one);
  HierarchyOptions two;
  two.threads = 2;
  const std::string a = tmp.file("a.4k"), b = tmp.file("b.4k");
  write_hierarchy(h, a);
  write_hierarchy(build_hierarchy(view_of(sphere), two), b);
  CHECK(read_file(a) == read_file(b));
  // Velho's levels of one set: the same bytes too, and other records than the default's.
  one.sets_per_level = two.sets_per_level = 1;
  const std::string c = tmp.file("c.4k"), d = tmp.file("d.4k");
  write_hierarchy(build_hierarchy(view_of(sphere), one), c);
  write_hierarchy(build_hierarchy(view_of(sphere), two), d);
  CHECK(read_file(c) == read_file(d));
  CHECK(read_file(c) != read_file(a));
  CHECK(is_hierarchy_file(a));
  const MeshHierarchy back = read_hierarchy(a);
  CHECK(back.face_corners == h.face_corners);
  CHECK(back.first_new_face == h.first_new_face);
  REQUIRE(back.levels.size() == h.levels.size());
  for (std::uint32_t j = 0; j < h.levels.size(); j += 2) {
    const SimplifiedMesh x = level(h, j), y = level(back, j);
    CHECK(x.triangles == y.triangles);
    // The view's positions are double, and the file keeps them so.
    CHECK(x.positions == y.positions);
  }
}

TEST_CASE("a vertex of many faces keeps its fan in order as swaps take it down to four", "[hierarchy]") {
  // A closed fan of 14 faces around vertex 0 (more than a vertex's faces kept in its
  // own block), brought to valence 4 by swaps, one ring vertex at a time, then
  // removed: after each step the fan is the ring without the vertices swapped out,
  // each swap's new edge exists, and every vertex's faces are listed in the order
  // they were made (faces are numbered as made: ascending numbers).
  const std::uint32_t n = 14;
  const double pi = std::acos(-1.0);
  std::vector<Vec3d> positions = {{0, 0, 0}};
  std::vector<std::uint32_t> faces;
  for (std::uint32_t i = 0; i < n; ++i) {
    positions.push_back({std::cos(2 * pi * i / n), std::sin(2 * pi * i / n), 0});
    faces.insert(faces.end(), {0, 1 + i, 1 + (i + 1) % n});
  }
  FourKMesh mesh(positions, faces);
  std::vector<std::uint32_t> ring;
  for (std::uint32_t i = 1; i <= n; ++i) ring.push_back(i);
  FourKMesh::Fan fan;
  REQUIRE(mesh.fan(0, &fan));
  CHECK(fan.closed);
  CHECK(fan.ring == ring);
  while (ring.size() > 4) {
    // Every other ring vertex, so that the remaining ring stays convex.
    const std::size_t at = ring.size() % 2 == 0 ? 1 : 2;
    const std::uint32_t prev = ring[at - 1], mid = ring[at], next = ring[at + 1];
    HierarchyRecord swap;
    swap.swap = true;
    swap.vertex = 0;
    swap.face_count = 2;
    swap.faces[0] = mesh.face_with_edge(mid, 0);
    swap.faces[1] = mesh.face_with_edge(0, mid);
    REQUIRE(swap.faces[0] != HierarchyRecord::kNoFace);
    REQUIRE(swap.faces[1] != HierarchyRecord::kNoFace);
    CHECK_FALSE(mesh.has_edge(prev, next));
    mesh.apply(swap);
    ring.erase(ring.begin() + std::ptrdiff_t(at));
    CHECK(mesh.has_edge(prev, next));
    CHECK(mesh.has_face(prev, mid, next));
    REQUIRE(mesh.fan(0, &fan));
    CHECK(fan.ring == ring);
    CHECK(mesh.around(0).size() == ring.size());
    CHECK(mesh.live_faces() == n);
    for (std::uint32_t v = 0; v <= n; ++v) {
      const FourKMesh::Incidences faces = mesh.around(v);
      for (std::size_t i = 1; i < faces.size(); ++i) CHECK(faces[i - 1].face < faces[i].face);
    }
  }
  HierarchyRecord removal;
  removal.vertex = 0;
  removal.face_count = 4;
  for (int i = 0; i < 4; ++i) removal.faces[i] = mesh.face_with_edge(0, ring[std::size_t(i)]);
  mesh.apply(removal);
  CHECK_FALSE(mesh.vertex_alive(0));
  CHECK(mesh.live_faces() == n - 2);
  CHECK(mesh.live_vertices() == n);
  for (std::uint32_t v = 1; v <= n; ++v) CHECK(mesh.vertex_alive(v));
}

TEST_CASE("a removal may make a crease up to 150 degrees where the old ones are milder", "[hierarchy]") {
  // v at the centre of a saddle: a and c at height 1, b and d at -1, on the unit
  // circle. Its four faces meet at creases of acos(1/3) = 70.5 degrees; either
  // diagonal makes a roof (or valley) whose faces slope by atan(2), a crease of
  // 2 atan(2) = 126.9 degrees. Under a right angle v could not go at all.
  const std::uint32_t v = 0, a = 1, b = 2, c = 3, d = 4;
  std::vector<Vec3d> positions = {{0, 0, 0}, {1, 0, 1}, {0, 1, -1}, {-1, 0, 1}, {0, -1, -1}};
  const std::vector<std::uint32_t> faces = {v, a, b, v, b, c, v, c, d, v, d, a};
  FourKMesh mesh(std::move(positions), faces);
  const HierarchyOptions options;
  FourFaceSimplifier simplifier(&mesh, options);
  simplifier.assign_quadrics();
  std::vector<HierarchyRecord> records;
  simplifier.simplify_level(&records);
  CHECK_FALSE(mesh.vertex_alive(v));
  CHECK(mesh.live_faces() == 2);
}

TEST_CASE("on a flat patch, where every swap costs 0, the swap that makes the rounder faces goes first",
          "[hierarchy]") {
  // v of valence 5 in the plane z = 0, one ring vertex pulled in: bringing v to
  // valence 4 takes one swap, which cuts the ring's ear at one vertex. Every choice
  // stays in the plane (S = 0), so the rounder faces decide: the ear whose two new
  // faces have the largest least compactness (Velho eq. 4, 4 sqrt(3) area over the
  // sum of the squared sides), worked out here.
  const double ring[5][2] = {{0.45, 0.05}, {0.25, 0.97}, {-0.8, 0.6}, {-0.85, -0.55}, {0.35, -0.9}};
  std::vector<Vec3d> positions = {{0, 0, 0}};
  for (const auto& r : ring) positions.push_back({r[0], r[1], 0});
  std::vector<std::uint32_t> faces;
  for (std::uint32_t i = 0; i < 5; ++i) faces.insert(faces.end(), {0, 1 + i, 1 + (i + 1) % 5});
  auto compactness = [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {  // in the plane z = 0
    const Vec3d &a = positions[x], &b = positions[y], &c = positions[z];
    const double area = 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    auto d2 = [](const Vec3d& p, const Vec3d& q) { return (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y); };
    return 4 * std::sqrt(3.0) * area / (d2(a, b) + d2(b, c) + d2(c, a));
  };
  std::uint32_t best_mid = 0;
  double best = -1;
  for (std::uint32_t i = 0; i < 5; ++i) {
    const std::uint32_t prev = 1 + (i + 4) % 5, mid = 1 + i, next = 1 + (i + 1) % 5;
    const double least = std::min(compactness(0, prev, next), compactness(prev, mid, next));
    if (least > best) {
      best = least;
      best_mid = mid;
    }
  }
  FourKMesh mesh(positions, faces);
  const HierarchyOptions options;
  FourFaceSimplifier simplifier(&mesh, options);
  simplifier.assign_quadrics();
  std::vector<HierarchyRecord> records;
  simplifier.simplify_level(&records);
  REQUIRE(records.size() == 2);
  REQUIRE(records[0].swap);
  // Face i is (v, ring i, ring i + 1): the swap at ring vertex m replaces faces m - 1
  // and m (ring numbers from 0).
  const std::uint32_t m = best_mid - 1;
  const std::set<std::uint32_t> replaced(records[0].faces, records[0].faces + 2);
  CHECK(replaced == std::set<std::uint32_t>{(m + 4) % 5, m});
  CHECK_FALSE(records[1].swap);
  CHECK_FALSE(mesh.vertex_alive(0));
}

TEST_CASE("plans made ahead on other threads, or kept by entries that went back, give the walk's records",
          "[hierarchy]") {
  // A level's walk may make the plans of its next entries on several threads, and an
  // entry whose cost rose keeps its plan; either is taken only where nothing it read
  // has changed since. Under one thread nothing is made ahead. The parts have flat
  // patches whose zero costs tie (runs of neighbours in the queue), the height field
  // and the sphere smooth costs. The run that works ahead has an arena of two
  // threads whatever the machine's cores.
  ScratchDir tmp;
  const Mesh parts = generated(SyntheticShape::parts, 60000, tmp);
  const Mesh field = height_field(150);
  const Mesh sphere = uv_sphere(100, 120);
  for (const Mesh* m : {&parts, &field, &sphere}) {
    struct Run {
      std::vector<HierarchyRecord> records;
      FourFaceSimplifier::WalkStats stats;
    };
    auto run = [&] {
      std::vector<Vec3d> positions;
      for (std::size_t i = 0; i < m->positions.size(); i += 3)
        positions.push_back({m->positions[i], m->positions[i + 1], m->positions[i + 2]});
      FourKMesh mesh(std::move(positions), m->triangles);
      const HierarchyOptions options;
      FourFaceSimplifier simplifier(&mesh, options);
      simplifier.assign_quadrics();
      Run r;
      for (int level = 0; level < 8; ++level) simplifier.simplify_level(&r.records);
      r.stats = simplifier.walk_stats();
      return r;
    };
    Run alone, ahead;
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
      alone = run();
    }
    {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
      tbb::task_arena arena(2);
      arena.execute([&] { ahead = run(); });
    }
    INFO(m->triangles.size() / 3 << " faces, " << alone.records.size() << " records; plans made ahead "
                                 << ahead.stats.made_ahead << ", kept " << alone.stats.kept << " and "
                                 << ahead.stats.kept);
    CHECK(alone.stats.made_ahead == 0);
    // (About 5% of the records on the parts, whose zero costs tie in runs of
    // neighbours; a quarter or more on the others. On the parts the entries that go
    // back do not come out again before their set ends, so no plan is kept there.)
    CHECK(ahead.stats.made_ahead > alone.records.size() / 40);
    if (m != &parts) CHECK(alone.stats.kept > 0);
    REQUIRE(alone.records.size() == ahead.records.size());
    bool same = true;
    for (std::size_t i = 0; i < alone.records.size() && same; ++i) {
      const HierarchyRecord &a = alone.records[i], &b = ahead.records[i];
      same = a.swap == b.swap && a.vertex == b.vertex && a.face_count == b.face_count && a.error == b.error &&
             std::equal(a.faces, a.faces + 4, b.faces);
    }
    CHECK(same);
  }
}

TEST_CASE("a damaged, truncated, foreign or other-version .4k file is refused naming the byte", "[hierarchy][file]") {
  ScratchDir tmp;
  const Mesh sphere = uv_sphere(30, 40);
  const std::string path = tmp.file("h.4k");
  write_hierarchy(build_hierarchy(view_of(sphere), {}), path);
  const std::string bytes = read_file(path);
  auto refused = [&](const std::string& damaged) {
    write_file(path, damaged);
    try {
      read_hierarchy(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = char(flipped[bytes.size() / 2] ^ 0x10);
  CHECK_THAT(refused(flipped), Catch::Contains("h.4k: byte ") && Catch::Contains("do not match their checksum"));
  CHECK_THAT(refused(bytes.substr(0, bytes.size() - 5)), Catch::Contains("truncated"));
  CHECK_THAT(refused(bytes.substr(0, 30)), Catch::Contains("byte"));
  CHECK_THAT(refused("ply\nformat binary_little_endian 1.0\n"), Catch::Contains("byte 0: not an oocsimp hierarchy"));
  std::string version = bytes;
  version[8] = 3;
  CHECK_THAT(refused(version), Catch::Contains("version 3") && Catch::Contains("reads versions 1 to 2"));
  std::string header = bytes;
  header[20] = char(header[20] ^ 1);
  CHECK_THAT(refused(header), Catch::Contains("byte 56") && Catch::Contains("header"));
}

TEST_CASE("an attribute whose name a .4k file cannot hold is refused before the work", "[hierarchy][cli]") {
  // The .4k reader takes an attribute's name only as a PLY property name (printable
  // ASCII without blanks). A PLY whose property name has other bytes reads, and a
  // hierarchy built from it would not read back: the build refuses it up front (exit
  // 3, naming the input and the way out), leaving no file; without attributes it runs.
  ScratchDir tmp;
  const std::string in = tmp.file("t.ply"), h = tmp.file("t.4k");
  write_file(in,
             "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
             "property uchar t\xe9mp\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0 1\n1 0 0 2\n0 1 0 3\n0 0 1 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  CliResult r = run_cli("hierarchy " + in + " -o " + h + " --quiet");
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Catch::Contains(in) && Catch::Contains("t?mp") && Catch::Contains("--attributes"));
  CHECK_FALSE(file_exists(h));
  r = run_cli("hierarchy " + in + " -o " + h + " --quiet --attributes none");
  CHECK(r.exit_code == 0);
  CHECK(run_cli("info " + h).exit_code == 0);
}

TEST_CASE("hierarchy, extract and info on the command line, with exit codes", "[hierarchy][cli]") {
  ScratchDir tmp;
  const std::string in = tmp.file("s.ply"), h = tmp.file("s.4k"), out = tmp.file("l.ply");
  const Mesh sphere = uv_sphere(30, 40);
  std::vector<float> p(sphere.positions.begin(), sphere.positions.end());
  write_binary_ply(in, p, sphere.triangles);
  CliResult r = run_cli("hierarchy " + in + " -o " + h);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.out, Catch::Contains("records"));
  r = run_cli("info " + h);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.out, Catch::Contains("4-k hierarchy, version 2"));
  r = run_cli("extract " + h + " -o " + out + " --level 2");
  CHECK(r.exit_code == 0);
  const LoadedMesh l = load_mesh(out);
  CHECK(topology(l.positions, std::vector<std::uint32_t>(l.triangles.begin(), l.triangles.end())).euler() == 2);
  // --placement kept: the same faces, every vertex where the input has it (float
  // positions, on the unit sphere to float precision); the default moves some.
  const std::string kept = tmp.file("k.ply");
  CHECK(run_cli("extract " + h + " -o " + kept + " --level 2 --placement kept").exit_code == 0);
  const LoadedMesh k = load_mesh(kept);
  CHECK(k.triangles == l.triangles);
  double kept_off = 0, placed_off = 0;
  for (std::size_t v = 0; v < k.positions.size(); v += 3) {
    kept_off = std::max(kept_off, std::fabs(std::hypot(k.positions[v], k.positions[v + 1], k.positions[v + 2]) - 1));
    placed_off =
        std::max(placed_off, std::fabs(std::hypot(l.positions[v], l.positions[v + 1], l.positions[v + 2]) - 1));
  }
  CHECK(kept_off < 1e-6);
  CHECK(placed_off > 1e-4);
  r = run_cli("extract " + h + " -o " + out + " --level 2 --placement moved");
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("--placement"));
  r = run_cli("extract " + h + " -o " + out + " --level 999");
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("--level 999 is beyond the last"));
  r = run_cli("extract " + h + " -o " + out + " --level 1 --sphere 9,9,9,1");
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("meets no face"));
  r = run_cli("extract " + h + " -o " + out + " --level 1 --tris 10");
  CHECK(r.exit_code == 2);
  r = run_cli("extract " + in + " -o " + out + " --level 1");
  CHECK(r.exit_code == 3);
  CHECK_THAT(r.err, Catch::Contains("not an oocsimp hierarchy"));
  for (const char* sets : {"0", "17", "two"}) {
    r = run_cli("hierarchy " + in + " -o " + h + " --sets " + sets + " --quiet");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--sets"));
  }
  CHECK(run_cli("hierarchy " + in + " -o " + h + " --sets 2 --quiet").exit_code == 0);
}

TEST_CASE("an input over the budget is simplified out of core first, its quadrics kept when asked",
          "[hierarchy][cli]") {
  // 32 MiB hold a hierarchy of 32 MiB / 400 bytes = 83886 triangles; the sphere has
  // 99600, so the edge collapse brings it to that count first (even, as a closed
  // surface's count is). Either way every level stays closed, manifold and of Euler
  // characteristic 2; starting from the collapse's quadrics changes the records.
  ScratchDir tmp;
  const std::string in = tmp.file("s.ply"), plain = tmp.file("plain.4k"), kept = tmp.file("kept.4k"),
                    out = tmp.file("l.ply");
  const Mesh sphere = uv_sphere(250, 200);
  REQUIRE(sphere.triangles.size() / 3 == 99600);
  std::vector<float> p(sphere.positions.begin(), sphere.positions.end());
  write_binary_ply(in, p, sphere.triangles);
  CliResult r = run_cli("hierarchy " + in + " -o " + plain + " --mem 32M");
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.out, Catch::Contains("(simplified out of core to 83886 first)"));
  r = run_cli("hierarchy " + in + " -o " + kept + " --mem 32M --reuse-quadrics");
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.out, Catch::Contains("(simplified out of core to 83886 first, its quadrics kept)"));
  CHECK(read_file(plain) != read_file(kept));
  // On an input that fits there is nothing to reuse, and the run says so.
  r = run_cli("hierarchy " + in + " -o " + kept + " --reuse-quadrics --quiet");
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.err, Catch::Contains("--reuse-quadrics: the input fitted --mem"));
  r = run_cli("hierarchy " + in + " -o " + kept + " --mem 32M --reuse-quadrics --quiet");
  REQUIRE(r.exit_code == 0);
  for (const std::string& h : {plain, kept}) {
    const MeshHierarchy built = read_hierarchy(h);
    REQUIRE(built.levels.size() > 4);
    CHECK(built.levels[0].triangles == 83886);
    for (std::uint32_t j = 0; j < built.levels.size(); j += 3) {
      const SimplifiedMesh m = level(built, j);
      const Topology t = topology(m.positions, m.triangles);
      INFO(h << " level " << j << ": " << t.faces << " faces");
      CHECK(t.manifold);
      CHECK(t.boundary_edges == 0);
      CHECK(t.euler() == 2);
    }
  }
}

namespace {

// A coloured uv sphere: red from the height, quality x * y (as float), both functions
// of the position, which a 4-k hierarchy never moves.
struct ColouredSphere {
  Mesh mesh = uv_sphere(30, 40);
  std::vector<std::uint8_t> red;
  std::vector<float> quality;
  ColouredSphere() {
    for (std::size_t v = 0; v < mesh.positions.size(); v += 3) {
      red.push_back(red_at(mesh.positions[v + 2]));
      quality.push_back(quality_at(mesh.positions[v], mesh.positions[v + 1]));
    }
  }
  static std::uint8_t red_at(double z) { return std::uint8_t(std::lround(127.5 * (z + 1))); }
  static float quality_at(double x, double y) { return float(x * y); }
  MeshView view() const {
    MeshView v = view_of(mesh);
    v.attributes.add({"red", AttributeType::u8, 0, 255}, red.data(), 1);
    v.attributes.add({"quality", AttributeType::f32, -1, 1}, quality.data(), sizeof(float));
    return v;
  }
};

// Whether every vertex of `m` carries red and quality as functions of its position.
bool carries_sphere_values(const SimplifiedMesh& m) {
  if (m.attributes.attributes.size() != 2 || m.attributes.attributes[0].name != "red" ||
      m.attributes.attributes[1].name != "quality" || m.attributes.values.size() != 2 * (m.positions.size() / 3))
    return false;
  for (std::size_t v = 0; v < m.positions.size() / 3; ++v) {
    const double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
    if (m.attributes.values[2 * v] != ColouredSphere::red_at(z)) return false;
    if (m.attributes.values[2 * v + 1] != double(ColouredSphere::quality_at(x, y))) return false;
  }
  return true;
}

// The header's and the blocks' checksums made right again after `bytes` were edited,
// with the body now `body` bytes long (the file format of docs/hierarchy.md).
std::string with_checksums(std::string bytes, std::uint64_t body) {
  constexpr std::size_t kHeader = 64, kBlock = std::size_t(1) << 20;
  std::memcpy(&bytes[48], &body, 8);
  const std::uint64_t header_hash = content_hash(bytes.data(), 56);
  std::memcpy(&bytes[56], &header_hash, 8);
  bytes.resize(kHeader + body);
  for (std::size_t at = 0; at < body; at += kBlock) {
    const std::uint64_t h = content_hash(bytes.data() + kHeader + at, std::min<std::size_t>(kBlock, body - at));
    bytes.append(reinterpret_cast<const char*>(&h), 8);
  }
  return bytes;
}

}  // namespace

TEST_CASE("every extracted mesh carries its vertices' attributes, through the file and the command line",
          "[hierarchy][attributes]") {
  ScratchDir tmp;
  const ColouredSphere sphere;
  const MeshHierarchy h = build_hierarchy(sphere.view(), {});
  REQUIRE(h.attributes.attributes.size() == 2);
  CHECK(h.attributes.attributes[0].type == AttributeType::u8);
  const std::string path = tmp.file("c.4k");
  write_hierarchy(h, path);
  const MeshHierarchy back = read_hierarchy(path);
  CHECK(back.file_version == 2);
  CHECK(back.attributes.values == h.attributes.values);
  CHECK(back.attributes.attributes[1].type == AttributeType::f32);
  // The values as functions of the position hold where the vertices stay; placed at
  // their quadrics' minima, the same vertices carry the same values.
  const HierarchyPlacement kept = HierarchyPlacement::kept;
  for (std::uint32_t j = 0; j < h.levels.size(); j += 2) {
    INFO("level " << j);
    CHECK(carries_sphere_values(level(h, j, kept)));
    CHECK(carries_sphere_values(level(back, j, kept)));
    const SimplifiedMesh placed = level(back, j);
    CHECK(placed.attributes.values == level(back, j, kept).attributes.values);
    CHECK(placed.triangles == level(back, j, kept).triangles);
  }
  HierarchyQuery region;
  region.level = std::uint32_t(h.levels.size() - 1);
  region.region = HierarchyQuery::Region::sphere;
  region.centre = {0, 0, 1};
  region.radius = 0.3;
  region.placement = kept;
  CHECK(carries_sphere_values(extract_mesh(back, region)));

  // Texture coordinates too: kept in place, u and v stay exact.
  std::vector<float> u, v;
  for (std::size_t i = 0; i < sphere.mesh.positions.size(); i += 3) {
    u.push_back(float(sphere.mesh.positions[i]));
    v.push_back(float(sphere.mesh.positions[i + 1]));
  }
  MeshView mapped = view_of(sphere.mesh);
  mapped.attributes.add({"u", AttributeType::f32, -1, 1}, u.data(), sizeof(float));
  mapped.attributes.add({"v", AttributeType::f32, -1, 1}, v.data(), sizeof(float));
  const MeshHierarchy uv = build_hierarchy(mapped, {});
  REQUIRE(uv.attributes.attributes.size() == 2);
  const SimplifiedMesh coarse = level(uv, std::uint32_t(uv.levels.size() / 2), kept);
  bool exact = coarse.attributes.values.size() == 2 * (coarse.positions.size() / 3);
  for (std::size_t i = 0; exact && i < coarse.positions.size() / 3; ++i)
    exact = coarse.attributes.values[2 * i] == double(float(coarse.positions[3 * i])) &&
            coarse.attributes.values[2 * i + 1] == double(float(coarse.positions[3 * i + 1]));
  CHECK(exact);

  // The command line: a PLY with the two properties in, the same values out, and
  // none with --attributes none.
  const std::string in = tmp.file("c.ply"), out = tmp.file("l.ply"), bare = tmp.file("bare.4k");
  SimplifiedMesh finest = level(h, 0);
  write_mesh(in, finest.positions, finest.triangles, MeshFormat::ply_binary, ScalarType::f64, &finest.attributes);
  REQUIRE(run_cli("hierarchy " + in + " -o " + path + " --quiet").exit_code == 0);
  CliResult r = run_cli("info " + path);
  CHECK_THAT(r.out, Catch::Contains("attributes red (uchar) quality (float)"));
  REQUIRE(run_cli("extract " + path + " -o " + out + " --level 3 --placement kept").exit_code == 0);
  MeshInput from_file = open_mesh_input(out);
  SimplifiedMesh extracted;
  extracted.attributes.attributes = from_file.attributes.attributes;
  for (std::uint64_t v = 0; v < from_file.positions.count; ++v) {
    const Vec3d p = from_file.positions.get(v);
    extracted.positions.insert(extracted.positions.end(), {p.x, p.y, p.z});
    for (std::size_t j = 0; j < from_file.attributes.size(); ++j)
      extracted.attributes.values.push_back(attribute_value(from_file.attributes, v, j));
  }
  CHECK(extracted.positions.size() / 3 == h.levels[3].vertices);
  CHECK(carries_sphere_values(extracted));
  REQUIRE(run_cli("hierarchy " + in + " -o " + bare + " --attributes none --quiet").exit_code == 0);
  CHECK(read_hierarchy(bare).attributes.empty());
  CHECK(run_cli("hierarchy " + in + " -o " + bare + " --attributes green --quiet").exit_code == 2);
}

TEST_CASE("a version 1 .4k file (no attributes) still reads, and a damaged attribute is named", "[hierarchy][file]") {
  ScratchDir tmp;
  const Mesh sphere = uv_sphere(20, 24);
  const MeshHierarchy h = build_hierarchy(view_of(sphere), {});
  const std::string path = tmp.file("h.4k");
  write_hierarchy(h, path);
  const std::string v2 = read_file(path);
  std::uint64_t body;
  std::memcpy(&body, &v2[48], 8);
  // Version 1 is version 2 without the attribute section: here its count, 0.
  std::string v1 = v2;
  v1[8] = 1;
  v1 = with_checksums(v1.substr(0, std::size_t(64 + body - 4)), body - 4);
  write_file(path, v1);
  const MeshHierarchy old = read_hierarchy(path);
  CHECK(old.file_version == 1);
  CHECK(old.records.size() == h.records.size());
  CHECK(level(old, 3).triangles == level(h, 3).triangles);

  // A coloured one whose first attribute's type byte is 9, checksums made right.
  const ColouredSphere coloured;
  write_hierarchy(build_hierarchy(coloured.view(), {}), path);
  std::string bytes = read_file(path);
  std::memcpy(&body, &bytes[48], 8);
  // The section: the count (4 bytes), red's and quality's type, name and range (4 +
  // name + 16 bytes each), then 1 + 4 bytes a vertex; it ends the body.
  const std::size_t section = 4 + (4 + 3 + 16) + (4 + 7 + 16) + 5 * (coloured.mesh.positions.size() / 3);
  const std::size_t type_at = std::size_t(64 + body) - section + 4;
  REQUIRE(bytes[type_at] == char(AttributeType::u8));
  bytes[type_at] = 9;
  write_file(path, with_checksums(bytes, body));
  auto refusal = [&] {
    try {
      read_hierarchy(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(refusal(), Catch::Contains("byte " + std::to_string(type_at) + ": an attribute of no known type"));

  // Names go into every extracted PLY's header: a blank, a control byte, a repeat or
  // x, y, z is refused, naming the name's first byte.
  const Mesh small = uv_sphere(10, 12);
  std::vector<float> one(small.positions.size() / 3, 0.5f);
  MeshView view = view_of(small);
  view.attributes.add({"aaa", AttributeType::f32, 0, 1}, one.data(), sizeof(float));
  view.attributes.add({"bbb", AttributeType::f32, 0, 1}, one.data(), sizeof(float));
  write_hierarchy(build_hierarchy(view, {}), path);
  const std::string named = read_file(path);
  std::memcpy(&body, &named[48], 8);
  const std::size_t second = named.find("bbb");
  REQUIRE(second != std::string::npos);
  for (const char* bad : {"a b", "a\nb", "aaa",
                          "\x01"
                          "bb"}) {
    std::string edited = named;
    edited.replace(second, 3, bad);
    write_file(path, with_checksums(edited, body));
    INFO(bad);
    CHECK_THAT(refusal(), Catch::Contains("byte " + std::to_string(second) + ": the attribute name"));
  }
  view.attributes = {};
  view.attributes.add({"q", AttributeType::f32, 0, 1}, one.data(), sizeof(float));
  write_hierarchy(build_hierarchy(view, {}), path);
  std::string x = read_file(path);
  std::memcpy(&body, &x[48], 8);
  const std::size_t q_at = x.rfind(std::string("\x01\x00q", 3));
  REQUIRE(q_at != std::string::npos);
  x[q_at + 2] = 'x';
  write_file(path, with_checksums(x, body));
  CHECK_THAT(refusal(), Catch::Contains("\"x\" is x, y, z or an earlier attribute's"));
}
