// `oocsimp render` (src/render): pixel counts against the camera's documented framing,
// the PNG read back through libpng, and hostile meshes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "oocsimp/oocsimp.hpp"
#include "io/attribute_array.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/render.hpp"
#include "render/legend.hpp"
#include "render/rasterizer.hpp"
#include "png_support.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

// The mesh of `from` turned y-up into `to`: (x, y, z) -> (y, z, x) takes the z-up frame
// (x, y, z) to (z, x, y), the frame --up y turns about (azimuth from +z about +y).
void write_y_up_copy(const std::string& from, const std::string& to) {
  const LoadedMesh m = load_mesh(from);
  std::vector<double> turned(m.positions.size());
  for (std::size_t i = 0; i < m.vertex_count(); ++i) {
    turned[3 * i] = m.positions[3 * i + 1];
    turned[3 * i + 1] = m.positions[3 * i + 2];
    turned[3 * i + 2] = m.positions[3 * i];
  }
  write_mesh(to, turned, std::vector<std::uint32_t>(m.triangles.begin(), m.triangles.end()), MeshFormat::ply_binary,
             ScalarType::f64);
}

}  // namespace

TEST_CASE("a unit square facing the camera covers its analytic pixel count", "[render][cli]") {
  ScratchDir d;
  // The square [0, 1]^2 at z = 0 in 8 x 8 cells, seen from straight above.
  write_plane_ply(d.file("square.ply"), 8, 0, 0, 0);
  const CliResult r = run_cli("render --quiet " + q(d.file("square.ply")) + " -o " + q(d.file("s.png")) +
                              " --size 400x300 --view 0,90");
  REQUIRE(r.exit_code == 0);
  const Image image = read_png(d.file("s.png"));
  CHECK(image.width == 400);
  CHECK(image.height == 300);
  // The camera frames the square's outline, 1 x 1 seen from above: 1.05 across the
  // side it fills first, the 300 pixels of the height.
  const double pixel = 1.05 / 300;
  const double expected = 1 / (pixel * pixel);
  CHECK(std::fabs(double(non_white(image)) - expected) <= 0.02 * expected);
  // Centred: as many empty columns left as right, rows above as below.
  const PixelBox b = covered_box(image);
  CHECK(std::abs(int(b.x0) - int(image.width - 1 - b.x1)) <= 1);
  CHECK(std::abs(int(b.y0) - int(image.height - 1 - b.y1)) <= 1);
}

TEST_CASE("render frames the projected outline, not the bounding sphere", "[render][cli]") {
  ScratchDir d;
  // A 4 x 1 strip seen from above: its long side fills 1 / 1.05 of the image's side,
  // the short side a quarter of that, centred; the bounding sphere (diameter sqrt 17)
  // would leave it 3% short along the long side and far from filling a wide image.
  write_binary_ply(d.file("strip.ply"), {0, 0, 0, 4, 0, 0, 4, 1, 0, 0, 1, 0}, {0, 1, 2, 0, 2, 3});
  REQUIRE(
      run_cli("render --quiet " + q(d.file("strip.ply")) + " -o " + q(d.file("s.png")) + " --size 400x400 --view 0,90")
          .exit_code == 0);
  const Image image = read_png(d.file("s.png"));
  const PixelBox b = covered_box(image);
  const double long_side = 400 / 1.05, short_side = long_side / 4;
  const double w = b.x1 - b.x0 + 1, h = b.y1 - b.y0 + 1;
  CHECK(std::fabs(std::max(w, h) - long_side) <= 2);
  CHECK(std::fabs(std::min(w, h) - short_side) <= 2);
  CHECK(std::abs(int(b.x0) - int(image.width - 1 - b.x1)) <= 1);
  CHECK(std::abs(int(b.y0) - int(image.height - 1 - b.y1)) <= 1);
  // Seen from the side, a flat plate fills the width of a wide picture.
  write_plane_ply(d.file("plate.ply"), 8, 0, 0, 0);
  REQUIRE(
      run_cli("render --quiet " + q(d.file("plate.ply")) + " -o " + q(d.file("p.png")) + " --size 600x200 --view 0,10")
          .exit_code == 0);
  const Image plate = read_png(d.file("p.png"));
  const PixelBox pb = covered_box(plate);
  CHECK(std::fabs(double(pb.x1 - pb.x0 + 1) - 600 / 1.05) <= 2);
}

TEST_CASE("render writes JPEG for .jpg and .jpeg, PNG for .png, and refuses other names", "[render][cli]") {
  ScratchDir d;
  write_plane_ply(d.file("p.ply"), 8, 0.2, 0.1, 0);
  for (const char* name : {"x.jpg", "x.JPEG"}) {
    INFO(name);
    REQUIRE(run_cli("render --quiet " + q(d.file("p.ply")) + " -o " + q(d.file(name)) + " --size 120x90").exit_code ==
            0);
    const std::string bytes = read_file(d.file(name));
    REQUIRE(bytes.size() > 3);
    CHECK(bytes.compare(0, 3, "\xFF\xD8\xFF") == 0);  // JPEG's SOI and a marker
    const Image jpeg = read_jpeg(d.file(name));
    CHECK(jpeg.width == 120);
    CHECK(jpeg.height == 90);
    CHECK(non_white(jpeg) > 0);
  }
  REQUIRE(run_cli("render --quiet " + q(d.file("p.ply")) + " -o " + q(d.file("x.png")) + " --size 120x90").exit_code ==
          0);
  CHECK(read_file(d.file("x.png")).compare(0, 8, "\x89PNG\r\n\x1A\n") == 0);
  // The JPEG is the PNG's picture, to within its compression.
  const Image png = read_png(d.file("x.png")), jpeg = read_jpeg(d.file("x.jpg"));
  double diff = 0;
  for (std::size_t i = 0; i < png.rgb.size(); ++i) diff += std::abs(int(png.rgb[i]) - int(jpeg.rgb[i]));
  CHECK(diff / double(png.rgb.size()) < 4);
  for (const char* name : {"x", "x.gif", "x.png.txt"}) {
    INFO(name);
    const CliResult r = run_cli("render " + q(d.file("p.ply")) + " -o " + q(d.file(name)));
    CHECK(r.exit_code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_THAT(r.err, Catch::Contains(".jpg"));
    CHECK_FALSE(file_exists(d.file(name)));
  }
}

TEST_CASE("the library's count of covered pixels is the picture's", "[render]") {
  ScratchDir d;
  write_plane_ply(d.file("p.ply"), 30, 0.3, -0.2, 0.1);
  MeshInput m = open_mesh_input(d.file("p.ply"));
  RenderOptions o;
  o.width = 320;
  o.height = 200;
  RenderStats st;
  const Image image = render_mesh(m, o, &st);
  CHECK(st.triangles == 2 * 30 * 30);
  CHECK(st.covered_pixels == non_white(image));
  CHECK(st.covered_pixels > 0);
  // Seen edge-on, a plane covers (almost) nothing: at most its outline's pixels.
  RenderOptions side = o;
  write_plane_ply(d.file("z.ply"), 30, 0, 0, 0);
  MeshInput z = open_mesh_input(d.file("z.ply"));
  side.elevation_degrees = 0;
  RenderStats edge_on;
  render_mesh(z, side, &edge_on);
  CHECK(edge_on.covered_pixels == 0);
}

TEST_CASE("an empty mesh gives the background, degenerate triangles do not crash", "[render][cli]") {
  ScratchDir d;
  write_binary_ply(d.file("empty.ply"), {}, {});
  REQUIRE(
      run_cli("render --quiet " + q(d.file("empty.ply")) + " -o " + q(d.file("e.png")) + " --size 64x48").exit_code ==
      0);
  const Image empty = read_png(d.file("e.png"));
  CHECK(empty.width == 64);
  CHECK(non_white(empty) == 0);
  // Every triangle degenerate: a repeated corner, collinear corners, all at one point.
  write_binary_ply(d.file("degenerate.ply"), {0, 0, 0, 1, 1, 1, 2, 2, 2, 0, 0, 0, 5, 5, 5},
                   {0, 1, 2, 0, 0, 1, 0, 3, 0, 4, 4, 4});
  REQUIRE(run_cli("render --quiet " + q(d.file("degenerate.ply")) + " -o " + q(d.file("g.png"))).exit_code == 0);
  CHECK(non_white(read_png(d.file("g.png"))) == 0);
}

TEST_CASE("render refuses bad sizes, views and an output over its input with exit 2", "[render][cli]") {
  ScratchDir d;
  write_plane_ply(d.file("p.ply"), 4, 0, 0, 0);
  for (const char* args :
       {"--size 0x10", "--size 100", "--size 20000x10", "--view 30", "--view a,b", "--view nan,3", "--shading phong"}) {
    INFO(args);
    const CliResult r = run_cli("render " + q(d.file("p.ply")) + " -o " + q(d.file("o.png")) + " " + args);
    CHECK(r.exit_code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_FALSE(file_exists(d.file("o.png")));
  }
  const std::string before = read_file(d.file("p.ply"));
  CHECK(run_cli("render " + q(d.file("p.ply")) + " -o " + q(d.file("p.ply"))).exit_code == 2);
  CHECK(read_file(d.file("p.ply")) == before);
  // A missing input: exit 3 or 4 with one line, and no picture left behind.
  const CliResult missing = run_cli("render " + q(d.file("none.ply")) + " -o " + q(d.file("m.png")));
  CHECK(missing.exit_code != 0);
  CHECK_FALSE(file_exists(d.file("m.png")));
}

TEST_CASE("render up y draws a y-up copy of a mesh as up z draws the mesh", "[render][cli]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --shape parts --tris 20000 -o " + q(d.file("z.ply"))).exit_code == 0);
  write_y_up_copy(d.file("z.ply"), d.file("y.ply"));
  auto render = [&](const std::string& in, const std::string& up, const std::string& out) {
    REQUIRE(
        run_cli("render --quiet " + q(d.file(in)) + " -o " + q(d.file(out)) + " --size 320x240 --up " + up).exit_code ==
        0);
    return read_png(d.file(out));
  };
  const Image z = render("z.ply", "z", "z.png"), y = render("y.ply", "y", "y.png"),
              wrong = render("y.ply", "z", "wrong.png");
  auto differing = [](const Image& a, const Image& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.rgb.size(); i += 3)
      n += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2];
    return n;
  };
  // The same picture but for pixels where sums of the same products, taken in another
  // order, round apart.
  CHECK(differing(z, y) <= std::size_t(320 * 240 / 500));
  CHECK(differing(z, wrong) > std::size_t(320 * 240 / 20));
  const CliResult bad = run_cli("render --quiet " + q(d.file("z.ply")) + " -o " + q(d.file("b.png")) + " --up w");
  CHECK(bad.exit_code == 2);
}

namespace {

// A closed cylinder of radius 1 and height 1.5 along axis `along` (0 x, 1 y, 2 z), its
// caps fanned from their centres, as positions and triangles.
void closed_cylinder(int along, std::vector<double>* positions, std::vector<std::uint32_t>* triangles) {
  const std::uint32_t n = 48;
  const auto put = [&](double a, double b, double h) {
    double p[3];
    p[along] = h;
    p[(along + 1) % 3] = a;
    p[(along + 2) % 3] = b;
    positions->insert(positions->end(), {p[0], p[1], p[2]});
  };
  for (int ring = 0; ring < 2; ++ring)
    for (std::uint32_t i = 0; i < n; ++i) {
      const double t = 2 * 3.14159265358979323846 * i / n;
      put(std::cos(t), std::sin(t), 1.5 * ring);
    }
  put(0, 0, 0);
  put(0, 0, 1.5);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    triangles->insert(triangles->end(), {i, j, n + j, i, n + j, n + i});
    triangles->insert(triangles->end(), {2 * n, j, i, 2 * n + 1, n + i, n + j});
  }
}

}  // namespace

TEST_CASE("render up auto takes the way an open surface faces, else a closed one's base, else the format's",
          "[render][cli]") {
  ScratchDir d;
  const auto up_of = [&](const std::string& file) {
    const CliResult r = run_cli("render " + q(d.file(file)) + " -o " + q(d.file("a.png")) + " --size 160x120");
    REQUIRE(r.exit_code == 0);
    const std::size_t at = r.err.find(" up (auto)");
    REQUIRE(at != std::string::npos);
    return r.err.substr(at - 1, 1);
  };
  // A terrain faces +z; its y-up copy faces +y, and is drawn as --up y draws it.
  REQUIRE(run_cli("generate --quiet --shape terrain --tris 20000 -o " + q(d.file("z.ply"))).exit_code == 0);
  write_y_up_copy(d.file("z.ply"), d.file("y.ply"));
  CHECK(up_of("z.ply") == "z");
  CHECK(up_of("y.ply") == "y");
  REQUIRE(run_cli("render --quiet " + q(d.file("y.ply")) + " -o " + q(d.file("given.png")) + " --size 160x120 --up y")
              .exit_code == 0);
  REQUIRE(
      run_cli("render --quiet " + q(d.file("y.ply")) + " -o " + q(d.file("auto.png")) + " --size 160x120").exit_code ==
      0);
  CHECK(read_file(d.file("given.png")) == read_file(d.file("auto.png")));
  // A closed drum stands on a cap: up is its axis.
  for (int along = 0; along < 3; ++along) {
    std::vector<double> p;
    std::vector<std::uint32_t> t;
    closed_cylinder(along, &p, &t);
    write_mesh(d.file("c.ply"), p, t, MeshFormat::ply_binary, ScalarType::f64);
    CHECK(up_of("c.ply") == std::string(1, "xyz"[along]));
  }
  // A sphere has no base and faces no way: z.
  REQUIRE(run_cli("generate --quiet --shape sphere --tris 20000 -o " + q(d.file("s.ply"))).exit_code == 0);
  CHECK(up_of("s.ply") == "z");
  // A wall facing -y (seen from behind in a z-up frame) is no terrain: the fallback, z.
  write_mesh(d.file("wall.ply"), {0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 1}, {0, 2, 1, 2, 3, 1}, MeshFormat::ply_binary,
             ScalarType::f64);
  CHECK(up_of("wall.ply") == "z");
  // The same as glTF, whose frame is y-up: y.
  REQUIRE(run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("s.glb")) + " --target-tris 5000")
              .exit_code == 0);
  CHECK(up_of("s.glb") == "y");
}

namespace {

// The plane z = slope x over [lo, hi]^2 in n x n cells, two triangles each.
void write_grid(const std::string& path, int n, double lo, double hi, double slope) {
  std::vector<float> p;
  std::vector<std::uint32_t> t;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = lo + (hi - lo) * i / n, y = lo + (hi - lo) * j / n;
      p.insert(p.end(), {float(x), float(y), float(slope * x)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1), d = c + 1;
      t.insert(t.end(), {a, b, d, a, d, c});
    }
  write_binary_ply(path, p, t);
}

}  // namespace

TEST_CASE("measure --error-colours writes each vertex's distance, render draws it with a legend",
          "[render][measure][cli]") {
  ScratchDir d;
  // A: the plane z = 0.1 x over [-1, 2]^2; B: the plane z = 0 over [0, 1]^2. A vertex
  // (x, y, 0) of B is 0.1 x / sqrt(1.01) from A, its foot inside A.
  write_grid(d.file("a.ply"), 12, -1, 2, 0.1);
  write_grid(d.file("b.ply"), 4, 0, 1, 0);
  const CliResult r = run_cli("measure --quiet --samples 2000 " + q(d.file("a.ply")) + " " + q(d.file("b.ply")) +
                              " --error-colours " + q(d.file("err.ply")));
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.out, Catch::Contains("colours"));
  MeshInput m = open_mesh_input(d.file("err.ply"));
  REQUIRE(m.positions.count == 25);
  REQUIRE(m.attributes.size() == 4);
  CHECK(m.attributes.attributes[0].name == "quality");
  const double top = 0.1 / std::sqrt(1.01);
  for (std::uint64_t v = 0; v < m.positions.count; ++v) {
    const Vec3d p = m.positions.get(v);
    const double quality = attribute_value(m.attributes, v, 0);
    CHECK(quality == Approx(0.1 * p.x / std::sqrt(1.01)).margin(1e-6));
    const std::uint32_t c = error_ramp_colour(quality / top);
    CHECK(std::fabs(attribute_value(m.attributes, v, 1) - double(c >> 16)) <= 1);
    CHECK(std::fabs(attribute_value(m.attributes, v, 2) - double((c >> 8) & 0xFF)) <= 1);
    CHECK(std::fabs(attribute_value(m.attributes, v, 3) - double(c & 0xFF)) <= 1);
  }
  // The ramp's end and A's diagonal (3 x 3 x 0.3) in the header, for the legend.
  const ErrorRamp ramp = find_error_ramp(m.info.comments);
  REQUIRE(ramp.found);
  CHECK(ramp.top == Approx(top).epsilon(1e-6));
  CHECK(ramp.diagonal == Approx(std::sqrt(9 + 9 + 0.09)).epsilon(1e-6));
  // The ramp's ends: blue for none, red for the largest.
  CHECK(error_ramp_colour(0) == 0x0000FF);
  CHECK(error_ramp_colour(1) == 0xFF0000);
  CHECK(error_ramp_colour(0.5) == 0x00FF00);

  // render: the legend's bar at the right holds the pure ramp, red at its top and blue
  // at its bottom; the model (shaded, so never pure) keeps to the left of it.
  const CliResult pic =
      run_cli("render " + q(d.file("err.ply")) + " -o " + q(d.file("err.png")) + " --size 800x600 --view 0,90");
  REQUIRE(pic.exit_code == 0);
  CHECK_THAT(pic.err, Catch::Contains("legend"));
  const Image image = read_png(d.file("err.png"));
  const std::uint32_t strip = legend_width(800, 600, ramp);
  REQUIRE(strip > 0);
  auto pixel = [&](std::uint32_t x, std::uint32_t y) {
    const std::uint8_t* p = &image.rgb[3 * (std::size_t(y) * image.width + x)];
    return std::uint32_t(p[0]) << 16 | std::uint32_t(p[1]) << 8 | p[2];
  };
  std::size_t red = 0, blue = 0, ramp_top_row = image.height, ramp_bottom_row = 0;
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = image.width - strip; x < image.width; ++x) {
      if (pixel(x, y) == 0xFF0000) ++red, ramp_top_row = std::min<std::size_t>(ramp_top_row, y);
      if (pixel(x, y) == 0x0000FF) ++blue, ramp_bottom_row = std::max<std::size_t>(ramp_bottom_row, y);
    }
  CHECK(red > 0);
  CHECK(blue > 0);
  CHECK(ramp_top_row < ramp_bottom_row);
  // The model fills the width the legend leaves (narrower than the height): B's
  // square, seen from above.
  Image left = image;
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = image.width - strip; x < image.width; ++x)
      for (int k = 0; k < 3; ++k) left.rgb[3 * (std::size_t(y) * image.width + x) + std::size_t(k)] = 255;
  const PixelBox b = covered_box(left);
  CHECK(std::fabs(double(b.x1 - b.x0 + 1) - (800 - strip) / 1.05) <= 2);
  CHECK(b.x1 < image.width - strip);
  // A plain mesh gets no legend and its one surface colour.
  REQUIRE(run_cli("render --quiet " + q(d.file("b.ply")) + " -o " + q(d.file("b.png")) + " --size 800x600").exit_code ==
          0);
  const Image plain = read_png(d.file("b.png"));
  std::size_t tinted = 0;  // grey (0xB4B4BE) and white have red = green; a ramp colour would not
  for (std::size_t i = 0; i < plain.rgb.size(); i += 3) tinted += plain.rgb[i] != plain.rgb[i + 1];
  CHECK(tinted == 0);

  // A name that is not PLY is refused before the work, with exit 2.
  const CliResult bad = run_cli("measure --quiet " + q(d.file("a.ply")) + " " + q(d.file("b.ply")) +
                                " --error-colours " + q(d.file("err.obj")));
  CHECK(bad.exit_code == 2);
  CHECK_FALSE(file_exists(d.file("err.obj")));
}
