// Vertex attributes from reader to writer: colours, normals and scalars
// travel through both clustering methods as area-weighted cluster means.
//
// Expected values come from the functions the attributes were made of (a linear
// function of position: a cluster's mean is the function at its members' mean
// position, which lies in the cell of the output vertex), or, for the weighting
// itself, from an independent whole-mesh computation of each cell's weighted mean.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "common/math_constants.hpp"
#include "io/attribute_array.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/oocsimp.hpp"
#include "api/simplify.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

// The colour channels and the quality as linear functions of position.
double red_of(const double* p) { return 255 * (0.5 + 0.4 * p[0]); }
double green_of(const double* p) { return 255 * (0.5 - 0.3 * p[1]); }
double blue_of(const double* p) { return 255 * (0.5 + 0.2 * p[0] + 0.2 * p[2]); }
double quality_of(const double* p) { return 10 + 3 * p[0] - 2 * p[1] + p[2]; }
// Their gradients' lengths, per unit of model length (colours in units of 255).
const double kRedGradient = 0.4, kGreenGradient = 0.3, kBlueGradient = std::sqrt(0.08);
const double kQualityGradient = std::sqrt(14.0);

// Appends `values` (push_back: GCC 12 warns falsely about vector::insert of an
// initializer list at -O3).
template <class T>
struct Same {
  using type = T;
};
template <class T>
void append(std::vector<T>& v, std::initializer_list<typename Same<T>::type> values) {
  for (const T& x : values) v.push_back(x);
}

struct Mesh {
  std::vector<double> positions;  // 3 per vertex
  std::vector<std::uint32_t> triangles;
};

// A UV sphere of radius 1 about the origin: `rings` latitude bands, `segments`
// longitudes, poles included.
Mesh uv_sphere(int rings, int segments) {
  Mesh m;
  append(m.positions, {0, 0, 1});
  for (int r = 1; r < rings; ++r) {
    double theta = kPi * r / rings;
    for (int s = 0; s < segments; ++s) {
      double phi = 2 * kPi * s / segments;
      m.positions.insert(m.positions.end(),
                         {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    }
  }
  append(m.positions, {0, 0, -1});
  const std::uint32_t south = std::uint32_t(m.positions.size() / 3 - 1);
  auto at = [&](int r, int s) { return std::uint32_t(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) append(m.triangles, {0, at(1, s), at(1, s + 1)});
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      append(m.triangles, {at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      append(m.triangles, {at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  for (int s = 0; s < segments; ++s) append(m.triangles, {south, at(rings - 1, s + 1), at(rings - 1, s)});
  return m;
}

// The generated parts mesh (boxes and cylinders with sharp edges).
Mesh parts_mesh(const ScratchDir& d, std::uint64_t triangles) {
  GenerateOptions g;
  g.triangles = triangles;
  g.shape = SyntheticShape::parts;
  generate_mesh(d.file("parts-geometry.ply"), g);
  LoadedMesh l = load_mesh(d.file("parts-geometry.ply"));
  Mesh m;
  m.positions = l.positions;
  for (std::uint64_t t : l.triangles) m.triangles.push_back(std::uint32_t(t));
  return m;
}

// Which properties a PLY written by write_ply gets.
struct Properties {
  bool colour = true, normal = false, quality = false, texture = false;
};

// Binary (or ascii) little-endian PLY: float x, y, z, then uchar red, green, blue,
// float nx, ny, nz (radial: the sphere's normals), float quality, float u, v, as asked.
void write_ply(const std::string& path, const Mesh& m, const Properties& with, bool ascii = false) {
  const std::size_t n = m.positions.size() / 3;
  std::string s = std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") + " 1.0\nelement vertex " +
                  std::to_string(n) + "\nproperty float x\nproperty float y\nproperty float z\n";
  if (with.colour) s += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (with.normal) s += "property float nx\nproperty float ny\nproperty float nz\n";
  if (with.quality) s += "property float quality\n";
  if (with.texture) s += "property float u\nproperty float v\n";
  s += "element face " + std::to_string(m.triangles.size() / 3) +
       "\nproperty list uchar int vertex_indices\nend_header\n";
  auto put_float = [&](double v) {
    if (ascii) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.9g ", float(v));
      s += buf;
    } else {
      put_le(s, float(v));
    }
  };
  auto put_uchar = [&](double v) {
    const auto c = std::uint8_t(std::lround(std::min(255.0, std::max(0.0, v))));
    if (ascii)
      s += std::to_string(int(c)) + " ";
    else
      s.push_back(char(c));
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = &m.positions[3 * i];
    for (int k = 0; k < 3; ++k) put_float(p[k]);
    if (with.colour) {
      put_uchar(red_of(p));
      put_uchar(green_of(p));
      put_uchar(blue_of(p));
    }
    if (with.normal) {
      const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      for (int k = 0; k < 3; ++k) put_float(p[k] / len);
    }
    if (with.quality) put_float(quality_of(p));
    if (with.texture) {
      put_float(p[0]);
      put_float(p[1]);
    }
    if (ascii) s.back() = '\n';
  }
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    if (ascii) {
      s += "3 " + std::to_string(m.triangles[t]) + " " + std::to_string(m.triangles[t + 1]) + " " +
           std::to_string(m.triangles[t + 2]) + "\n";
    } else {
      s.push_back(char(3));
      for (int k = 0; k < 3; ++k) put_le(s, std::int32_t(m.triangles[t + std::size_t(k)]));
    }
  }
  write_file(path, s);
}

SimplifiedMesh run(const std::string& path, ClusterMethod method, std::uint32_t grid, unsigned threads = 2,
                   double tile = 0, const AttributeSelection& attributes = {}, SimplifyStats* stats = nullptr) {
  OpenOptions open;
  open.attributes = attributes;
  MeshInput in = open_mesh_input(path, open);
  SimplifyOptions o;
  o.method = method;
  o.sizing.grid = grid;
  o.threads = threads;
  o.floating.tile_side = tile;
  o.attributes = attributes;
  return simplify(in, o, stats);
}

int attribute_index(const SimplifiedMesh& m, const std::string& name) {
  for (std::size_t k = 0; k < m.attributes.attributes.size(); ++k)
    if (m.attributes.attributes[k].name == name) return int(k);
  return -1;
}

double value(const SimplifiedMesh& m, std::size_t vertex, int k) {
  return m.attributes.values[m.attributes.attributes.size() * vertex + std::size_t(k)];
}

// The largest error of the output colours against the functions at the output
// positions, in units of 1/255, and the bound for `cell`: 1/255 (the input's and the
// output's rounding to uchar, half a unit each) plus the gradient times the cell's
// diagonal (members and representative lie in one cell).
struct ColourCheck {
  double worst[3] = {0, 0, 0};
  double bound[3] = {0, 0, 0};
};
ColourCheck check_colours(const SimplifiedMesh& m, double cell) {
  ColourCheck c;
  const int k[3] = {attribute_index(m, "red"), attribute_index(m, "green"), attribute_index(m, "blue")};
  REQUIRE(k[0] >= 0);
  REQUIRE(k[1] >= 0);
  REQUIRE(k[2] >= 0);
  const double gradients[3] = {kRedGradient, kGreenGradient, kBlueGradient};
  for (int a = 0; a < 3; ++a) c.bound[a] = 1.0 + 255 * gradients[a] * cell * std::sqrt(3.0);
  for (std::size_t i = 0; i < m.positions.size() / 3; ++i) {
    const double* p = &m.positions[3 * i];
    const double expected[3] = {red_of(p), green_of(p), blue_of(p)};
    for (int a = 0; a < 3; ++a) c.worst[a] = std::max(c.worst[a], std::fabs(value(m, i, k[a]) - expected[a]));
  }
  return c;
}

const ClusterMethod kMethods[] = {ClusterMethod::floating, ClusterMethod::uniform};

}  // namespace

TEST_CASE("colours of a sphere and of the parts mesh follow the linear function they were made of", "[attributes]") {
  ScratchDir d;
  const Mesh sphere = uv_sphere(120, 240);
  write_ply(d.file("sphere.ply"), sphere, {});
  write_ply(d.file("parts.ply"), parts_mesh(d, 60000), {});
  for (const char* name : {"sphere.ply", "parts.ply"})
    for (ClusterMethod method : kMethods)
      for (std::uint32_t grid : {16u, 48u}) {
        SimplifyStats st;
        SimplifiedMesh m = run(d.file(name), method, grid, 2, 0, {}, &st);
        REQUIRE(m.positions.size() > 3 * 20);
        REQUIRE(m.attributes.values.size() == 3 * m.positions.size() / 3);
        const ColourCheck c = check_colours(m, st.cell_size);
        INFO(name << " " << method_name(method) << " grid " << grid);
        for (int a = 0; a < 3; ++a) CHECK(c.worst[a] <= c.bound[a]);
        // Integer types come back whole and in range.
        for (double v : m.attributes.values) CHECK((v == std::round(v) && v >= 0 && v <= 255));
      }
}

TEST_CASE("at fine cells the colours are within 2/255 of the function", "[attributes]") {
  ScratchDir d;
  write_ply(d.file("sphere.ply"), uv_sphere(120, 240), {});
  for (ClusterMethod method : kMethods) {
    SimplifyStats st;
    SimplifiedMesh m = run(d.file("sphere.ply"), method, 512, 2, 0, {}, &st);
    const ColourCheck c = check_colours(m, st.cell_size);
    INFO(method_name(method));
    for (int a = 0; a < 3; ++a) CHECK(c.worst[a] <= 2.0);
  }
}

TEST_CASE("normals of a sphere stay within 2 degrees of radial and of unit length", "[attributes]") {
  ScratchDir d;
  Properties with;
  with.normal = true;
  write_ply(d.file("sphere.ply"), uv_sphere(150, 300), with);
  for (ClusterMethod method : kMethods)
    for (std::uint32_t grid : {64u, 128u}) {
      SimplifiedMesh m = run(d.file("sphere.ply"), method, grid);
      const int nx = attribute_index(m, "nx");
      REQUIRE(nx >= 0);
      double worst = 0, worst_length = 0;
      for (std::size_t i = 0; i < m.positions.size() / 3; ++i) {
        const double* p = &m.positions[3 * i];
        const double n[3] = {value(m, i, nx), value(m, i, nx + 1), value(m, i, nx + 2)};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const double plen = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        const double cosine = (n[0] * p[0] + n[1] * p[1] + n[2] * p[2]) / (len * plen);
        worst = std::max(worst, std::acos(std::min(1.0, cosine)) * 180 / kPi);
        worst_length = std::max(worst_length, std::fabs(len - 1));
      }
      INFO(method_name(method) << " grid " << grid);
      CHECK(worst <= 2.0);
      CHECK(worst_length <= 1e-6);
    }
}

TEST_CASE("a float quality property follows its linear function", "[attributes]") {
  ScratchDir d;
  Properties with;
  with.colour = false;
  with.quality = true;
  write_ply(d.file("sphere.ply"), uv_sphere(120, 240), with);
  for (ClusterMethod method : kMethods) {
    SimplifyStats st;
    SimplifiedMesh m = run(d.file("sphere.ply"), method, 32, 2, 0, {}, &st);
    const int q = attribute_index(m, "quality");
    REQUIRE(q >= 0);
    REQUIRE(m.attributes.attributes[std::size_t(q)].type == AttributeType::f32);
    double worst = 0;
    for (std::size_t i = 0; i < m.positions.size() / 3; ++i)
      worst = std::max(worst, std::fabs(value(m, i, q) - quality_of(&m.positions[3 * i])));
    INFO(method_name(method));
    CHECK(worst <= kQualityGradient * st.cell_size * std::sqrt(3.0) + 1e-5);
  }
}

namespace {

// A plane of (n + 1)^2 vertices with uneven triangles (dense near 0, coarse near 1),
// so that a colour's area-weighted mean differs from the plain mean of a cell's
// vertices; vertex i of the grid is stored as vertex number(i).
template <class Number>
Mesh uneven_plane(int n, Number number) {
  Mesh m;
  const std::size_t count = std::size_t(n + 1) * std::size_t(n + 1);
  m.positions.resize(3 * count);
  auto warp = [](double t) { return t * t; };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const std::size_t at = 3 * std::size_t(number(std::uint32_t(j * (n + 1) + i)));
      m.positions[at] = warp(double(i) / n);
      m.positions[at + 1] = warp(double(j) / n);
      m.positions[at + 2] = 0;
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1), e = c + 1;
      append(m.triangles, {number(a), number(b), number(e), number(a), number(e), number(c)});
    }
  return m;
}

// Checks every output vertex's quality of a uniform run against an independent sum,
// per cell, of (area / 3) * quality over the corners in it; returns how many.
std::size_t check_weighted_quality(const ScratchDir& d, const Mesh& m, std::uint32_t grid_resolution,
                                   unsigned threads) {
  Properties with;
  with.colour = false;
  with.quality = true;
  write_ply(d.file("plane.ply"), m, with);
  SimplifiedMesh out = run(d.file("plane.ply"), ClusterMethod::uniform, grid_resolution, threads);
  MeshInput in = open_mesh_input(d.file("plane.ply"));
  CellSizing sizing;
  sizing.grid = grid_resolution;
  const GridSpec grid = choose_grid(in, sizing, 1);
  std::map<std::uint64_t, std::pair<double, double>> sums;
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const double* p[3];
    for (int k = 0; k < 3; ++k) p[k] = &m.positions[3 * m.triangles[t + std::size_t(k)]];
    const double ux = p[1][0] - p[0][0], uy = p[1][1] - p[0][1], vx = p[2][0] - p[0][0], vy = p[2][1] - p[0][1];
    const double area = 0.5 * std::fabs(ux * vy - uy * vx);
    for (int k = 0; k < 3; ++k) {
      auto& s = sums[grid.key({p[k][0], p[k][1], p[k][2]})];
      s.first += area / 3 * double(float(quality_of(p[k])));
      s.second += area / 3;
    }
  }
  const int q = attribute_index(out, "quality");
  REQUIRE(q >= 0);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < out.positions.size() / 3; ++i) {
    const double* p = &out.positions[3 * i];
    const auto& s = sums.at(grid.key({p[0], p[1], p[2]}));
    CHECK(value(out, i, q) == Approx(s.first / s.second).epsilon(1e-6));
    ++checked;
  }
  return checked;
}

}  // namespace

TEST_CASE("the weights are a third of each incident triangle's area (uniform cells against independent sums)",
          "[attributes]") {
  ScratchDir d;
  const Mesh m = uneven_plane(60, [](std::uint32_t i) { return i; });
  CHECK(check_weighted_quality(d, m, 4, 2) >= 9);
}

TEST_CASE("the weights hold for vertices numbered in any order (corners past a chunk's window of indices)",
          "[attributes]") {
  ScratchDir d;
  // 300^2 triangles' chunks reference vertex numbers scattered over all 301^2 = 90601
  // (more than the window of 65536 a chunk gathers its vertices' weights in): the
  // uniform method adds those corners to their cells directly.
  constexpr std::uint32_t kCount = 301 * 301;
  const Mesh m = uneven_plane(300, [](std::uint32_t i) { return std::uint32_t(std::uint64_t(i) * 7919 % kCount); });
  CHECK(check_weighted_quality(d, m, 12, 1) >= 100);
  const SimplifiedMesh one = run(d.file("plane.ply"), ClusterMethod::uniform, 12, 1);
  const SimplifiedMesh two = run(d.file("plane.ply"), ClusterMethod::uniform, 12, 2);
  CHECK(one.positions == two.positions);
  CHECK(one.attributes.values == two.attributes.values);
}

TEST_CASE("a uniform cell whose triangles have no area takes the plain mean of its corners", "[attributes]") {
  ScratchDir d;
  // Two collinear (zero-area) triangles along one line, each corner in its own
  // vertex, spanning the same three cells of a 4-grid (so one of them is kept), and a
  // triangle with area far from them that gives the box its size.
  Mesh m;
  append(m.positions, {0.02, 0.02, 0.02, 0.52, 0.02, 0.02, 0.92, 0.02, 0.02});
  append(m.positions, {0.07, 0.02, 0.02, 0.57, 0.02, 0.02, 0.97, 0.02, 0.02});
  append(m.positions, {0, 1, 0, 1, 1, 0, 0, 1, 1});
  append(m.triangles, {0, 1, 2, 3, 4, 5, 6, 7, 8});
  Properties with;
  with.colour = false;
  with.quality = true;
  write_ply(d.file("flat.ply"), m, with);
  const SimplifiedMesh out = run(d.file("flat.ply"), ClusterMethod::uniform, 4);
  const int q = attribute_index(out, "quality");
  REQUIRE(q >= 0);
  REQUIRE(out.triangles.size() == 2 * 3);  // one of the collinear pair (same cells), the far one
  // Each corner's cell holds the two corners at the same place on the two triangles.
  std::size_t checked = 0;
  for (int corner = 0; corner < 3; ++corner) {
    const double* a = &m.positions[3 * corner];
    const double* b = &m.positions[3 * (corner + 3)];
    const double expected = 0.5 * (double(float(quality_of(a))) + double(float(quality_of(b))));
    for (std::size_t i = 0; i < out.positions.size() / 3; ++i)
      if (out.positions[3 * i + 1] < 0.5 && std::fabs(out.positions[3 * i] - 0.5 * (a[0] + b[0])) < 0.1) {
        CHECK(value(out, i, q) == Approx(expected).epsilon(1e-6));
        ++checked;
      }
  }
  CHECK(checked == 3);
}

TEST_CASE("attributes keep their names and types through a PLY round trip", "[attributes]") {
  ScratchDir d;
  Properties with;
  with.normal = with.quality = true;
  write_ply(d.file("sphere.ply"), uv_sphere(40, 80), with, true);  // ascii: the converted path
  for (ClusterMethod method : kMethods) {
    REQUIRE(run_cli("simplify " + d.file("sphere.ply") + " -o " + d.file("out.ply") + " --grid 16 --quiet --method " +
                    method_name(method))
                .exit_code == 0);
    const std::string text = read_file(d.file("out.ply"));
    const std::string header = text.substr(0, text.find("end_header"));
    const char* expected[] = {"property float x",    "property uchar red",    "property uchar green",
                              "property uchar blue", "property float nx",     "property float ny",
                              "property float nz",   "property float quality"};
    std::size_t at = 0;
    for (const char* line : expected) {
      at = header.find(line, at);
      INFO(line);
      REQUIRE(at != std::string::npos);
    }
    // Read back, the output offers the same attributes again.
    MeshInput back = open_mesh_input(d.file("out.ply"));
    REQUIRE(back.attributes.size() == 7);
    CHECK(back.attributes.attributes[0].name == "red");
    CHECK(back.attributes.attributes[0].type == AttributeType::u8);
    CHECK(back.attributes.attributes[6].name == "quality");
    CHECK(back.attributes.attributes[6].type == AttributeType::f32);
  }
}

TEST_CASE("with attributes the output is byte-identical for 1 and 2 threads and two tilings", "[attributes]") {
  ScratchDir d;
  Properties with;
  with.normal = with.quality = true;
  write_ply(d.file("parts.ply"), parts_mesh(d, 40000), with);
  for (ClusterMethod method : kMethods) {
    const SimplifiedMesh a = run(d.file("parts.ply"), method, 40, 1);
    const SimplifiedMesh b = run(d.file("parts.ply"), method, 40, 2);
    REQUIRE(a.attributes.values.size() == 7 * a.positions.size() / 3);
    CHECK(a.positions == b.positions);
    CHECK(a.triangles == b.triangles);
    CHECK(a.attributes.values == b.attributes.values);
    if (method == ClusterMethod::floating) {
      for (double tile : {0.13, 0.29}) {
        const SimplifiedMesh t = run(d.file("parts.ply"), method, 40, 2, tile);
        CHECK(a.positions == t.positions);
        CHECK(a.triangles == t.triangles);
        CHECK(a.attributes.values == t.attributes.values);
      }
    }
  }
}

TEST_CASE("attributes change no geometry and --attributes none gives the plain output byte for byte", "[attributes]") {
  ScratchDir d;
  const Mesh sphere = uv_sphere(60, 120);
  Properties with;
  with.normal = with.quality = true;
  write_ply(d.file("coloured.ply"), sphere, with);
  Properties none;
  none.colour = false;
  write_ply(d.file("plain.ply"), sphere, none);
  for (ClusterMethod method : kMethods) {
    const std::string m = std::string(" --grid 24 --quiet --method ") + method_name(method);
    REQUIRE(run_cli("simplify " + d.file("plain.ply") + " -o " + d.file("plain-out.ply") + m).exit_code == 0);
    REQUIRE(run_cli("simplify " + d.file("coloured.ply") + " -o " + d.file("none-out.ply") + m + " --attributes none")
                .exit_code == 0);
    CHECK(read_file(d.file("plain-out.ply")) == read_file(d.file("none-out.ply")));
    const SimplifiedMesh plain = run(d.file("plain.ply"), method, 24);
    const SimplifiedMesh all = run(d.file("coloured.ply"), method, 24);
    CHECK(plain.positions == all.positions);
    CHECK(plain.triangles == all.triangles);
    CHECK(all.attributes.attributes.size() == 7);
  }
}

TEST_CASE("a list of names given to --attributes carries those in that order and an unknown name exits 2",
          "[attributes]") {
  ScratchDir d;
  Properties with;
  with.quality = true;
  write_ply(d.file("s.ply"), uv_sphere(30, 60), with);
  AttributeSelection pick = parse_attribute_selection("quality,red");
  const SimplifiedMesh m = run(d.file("s.ply"), ClusterMethod::floating, 12, 2, 0, pick);
  REQUIRE(m.attributes.attributes.size() == 2);
  CHECK(m.attributes.attributes[0].name == "quality");
  CHECK(m.attributes.attributes[1].name == "red");
  const CliResult r = run_cli("simplify " + d.file("s.ply") + " -o " + d.file("o.ply") + " --attributes red,colour");
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("colour") != std::string::npos);
  CHECK(r.err.find("red, green, blue, quality") != std::string::npos);
  CHECK_FALSE(file_exists(d.file("o.ply")));
  CHECK_THROWS_AS(parse_attribute_selection("red,,blue"), UsageError);
}

TEST_CASE("texture coordinates and face properties are dropped with a warning naming the file", "[attributes]") {
  ScratchDir d;
  Properties with;
  with.texture = true;
  write_ply(d.file("t.ply"), uv_sphere(30, 60), with);
  const CliResult r = run_cli("simplify " + d.file("t.ply") + " -o " + d.file("o.ply") + " --grid 12 --quiet");
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.find("warning: " + d.file("t.ply") + ": texture coordinates (u, v) are dropped") != std::string::npos);
  MeshInput out = open_mesh_input(d.file("o.ply"));
  REQUIRE(out.attributes.size() == 3);  // red, green, blue
  // info lists what is carried and what is not.
  const CliResult info = run_cli("info " + d.file("t.ply"));
  CHECK(info.out.find("attribute red uchar, carried") != std::string::npos);
  CHECK(info.out.find("attribute u float, carried by the edge collapse, dropped by clustering") != std::string::npos);
}

TEST_CASE("OBJ colours (v x y z r g b) are carried and written back as OBJ colours", "[attributes]") {
  ScratchDir d;
  const Mesh sphere = uv_sphere(40, 80);
  std::string s;
  char buf[160];
  for (std::size_t i = 0; i < sphere.positions.size() / 3; ++i) {
    const double* p = &sphere.positions[3 * i];
    std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g %.6f %.6f %.6f\n", p[0], p[1], p[2], red_of(p) / 255,
                  green_of(p) / 255, blue_of(p) / 255);
    s += buf;
  }
  s += "vt 0 0\n";
  for (std::size_t t = 0; t < sphere.triangles.size(); t += 3)
    s += "f " + std::to_string(sphere.triangles[t] + 1) + " " + std::to_string(sphere.triangles[t + 1] + 1) + " " +
         std::to_string(sphere.triangles[t + 2] + 1) + "\n";
  write_file(d.file("c.obj"), s);
  for (ClusterMethod method : kMethods) {
    SimplifyStats st;
    const SimplifiedMesh m = run(d.file("c.obj"), method, 16, 2, 0, {}, &st);
    REQUIRE(m.attributes.attributes.size() == 3);
    CHECK(m.attributes.attributes[0].type == AttributeType::f32);
    double worst = 0;
    for (std::size_t i = 0; i < m.positions.size() / 3; ++i)
      worst = std::max(worst, std::fabs(value(m, i, 0) - red_of(&m.positions[3 * i]) / 255));
    CHECK(worst <= kRedGradient * st.cell_size * std::sqrt(3.0) + 1e-6);
    bool warned = false;
    for (const std::string& w : st.warnings)
      warned = warned || w.find("texture coordinates (u, v) are dropped") != std::string::npos;
    CHECK(warned);
  }
  REQUIRE(run_cli("simplify " + d.file("c.obj") + " -o " + d.file("o.obj") + " --grid 16 --quiet").exit_code == 0);
  MeshInput back = open_mesh_input(d.file("o.obj"));
  REQUIRE(back.attributes.size() == 3);
  CHECK(back.attributes.attributes[2].name == "blue");
  // STL keeps no attributes: the run says so.
  const CliResult stl = run_cli("simplify " + d.file("c.obj") + " -o " + d.file("o.stl") + " --grid 16 --quiet");
  CHECK(stl.exit_code == 0);
  CHECK(stl.err.find("STL and OFF keep no vertex attributes; red, green, blue not written") != std::string::npos);
}

TEST_CASE("welding keeps the attributes of each position's first vertex", "[attributes]") {
  ScratchDir d;
  // Two triangles with their corners apart; the duplicates of the shared edge carry
  // other qualities, which the weld drops.
  write_file(d.file("w.ply"),
             "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
             "property float quality\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0 1\n1 0 0 2\n0 1 0 3\n1 0 0 20\n1 1 0 4\n0 1 0 30\n3 0 1 2\n3 3 4 5\n");
  OpenOptions open;
  open.weld = true;
  MeshInput in = open_mesh_input(d.file("w.ply"), open);
  REQUIRE(in.positions.count == 4);
  REQUIRE(in.attributes.count == 4);
  const double expected[4] = {1, 2, 3, 4};
  for (int i = 0; i < 4; ++i) CHECK(attribute_value(in.attributes, std::uint64_t(i), 0) == expected[i]);
  CHECK(in.attributes.attributes[0].min == 1);
  CHECK(in.attributes.attributes[0].max == 4);
}

TEST_CASE("the in-memory API gives the same mesh as the file path and touches no temp folder", "[attributes][api]") {
  ScratchDir d;
  const Mesh sphere = uv_sphere(80, 160);
  Properties with;
  with.quality = true;
  write_ply(d.file("s.ply"), sphere, with);
  // The same mesh as the caller's arrays: float positions interleaved with a pad (a
  // stride of 16 bytes), colours in three arrays of their own, quality in a fourth.
  const std::size_t n = sphere.positions.size() / 3;
  std::vector<float> xyzw(4 * n);
  std::vector<std::uint8_t> rgb[3];
  std::vector<float> quality(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = &sphere.positions[3 * i];
    for (int k = 0; k < 3; ++k) xyzw[4 * i + std::size_t(k)] = float(p[k]);
    const double c[3] = {red_of(p), green_of(p), blue_of(p)};
    for (int k = 0; k < 3; ++k) rgb[k].push_back(std::uint8_t(std::lround(std::min(255.0, std::max(0.0, c[k])))));
    quality[i] = float(quality_of(p));
  }
  MeshView v;
  v.positions = xyzw.data();
  v.position_stride = 4 * sizeof(float);
  v.vertex_count = n;
  v.indices = sphere.triangles.data();
  v.triangle_count = sphere.triangles.size() / 3;
  const char* names[3] = {"red", "green", "blue"};
  for (int k = 0; k < 3; ++k) v.attributes.add({names[k], AttributeType::u8, 0, 0}, rgb[k].data(), 1);
  v.attributes.add({"quality", AttributeType::f32, 0, 0}, quality.data(), sizeof(float));
  for (ClusterMethod method : kMethods) {
    const SimplifiedMesh from_file = run(d.file("s.ply"), method, 24);
    SimplifyOptions o;
    o.method = method;
    o.sizing.grid = 24;
    o.temp_dir = d.file("no-such-folder");  // a spill file would fail here
    const SimplifiedMesh from_memory = simplify_mesh(v, o);
    INFO(method_name(method));
    CHECK(from_memory.positions == from_file.positions);
    CHECK(from_memory.triangles == from_file.triangles);
    CHECK(from_memory.attributes.values == from_file.attributes.values);
    REQUIRE(from_memory.attributes.attributes.size() == 4);
    CHECK(from_memory.attributes.attributes[3].name == "quality");
    CHECK(from_memory.attributes.attributes[0].type == AttributeType::u8);
  }
  CHECK_FALSE(file_exists(d.file("no-such-folder")));
  // An index out of range is bad input, named by triangle.
  std::vector<std::uint32_t> bad = sphere.triangles;
  bad[7] = std::uint32_t(n);
  v.indices = bad.data();
  try {
    simplify_mesh(v, SimplifyOptions());
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) ==
          "mesh in memory: triangle 2 names vertex " + std::to_string(n) + " of " + std::to_string(n));
  }
}
