#include <catch2/catch.hpp>

#include <cctype>
#include <cmath>
#include <map>
#include <stdexcept>

#include "oocsimp/error.hpp"
#include "oocsimp/measure.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

// An axis-aligned square [x0, x0+size] x [y0, y0+size] at height z as a two-triangle OBJ.
std::string square_obj(double x0, double y0, double size, double z) {
  std::string s;
  const double corners[4][2] = {{x0, y0}, {x0 + size, y0}, {x0 + size, y0 + size}, {x0, y0 + size}};
  for (const auto& c : corners)
    s += "v " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(z) + "\n";
  return s + "f 1 2 3\nf 1 3 4\n";
}

// Appends to square_obj() a zero-area triangle: three collinear points along y = 0.5
// at height z.
std::string with_degenerate_triangle(const std::string& square, double z) {
  std::string zs = std::to_string(z);
  return square + "v 0 0.5 " + zs + "\nv 0.5 0.5 " + zs + "\nv 1 0.5 " + zs + "\nf 5 6 7\n";
}

DistanceReport measure(const std::string& a, const std::string& b, std::uint64_t samples, std::uint64_t seed = 1,
                       unsigned threads = 0) {
  MeasureOptions o;
  o.samples = samples;
  o.seed = seed;
  o.threads = threads;
  return measure_surface_distance(a, b, o);
}

bool same(const DistanceStats& x, const DistanceStats& y) {
  return x.samples == y.samples && x.max == y.max && x.mean == y.mean && x.rms == y.rms;
}
bool same(const DistanceReport& x, const DistanceReport& y) {
  return same(x.a_to_b, y.a_to_b) && same(x.b_to_a, y.b_to_a) && same(x.symmetric, y.symmetric) &&
         x.a_area == y.a_area && x.b_area == y.b_area;
}

void check_sample_count(const DistanceStats& s, std::uint64_t requested) {
  INFO("samples " << s.samples << " of " << requested);
  CHECK(double(s.samples) >= 0.98 * double(requested));
  CHECK(double(s.samples) <= 1.02 * double(requested));
}

// A minimal JSON reader (objects, arrays, strings without escapes, numbers, literals),
// enough to check that the CLI's output is well-formed and has the expected keys.
struct JsonValue {
  double number = 0;
  std::map<std::string, JsonValue> members;
  bool is_object = false;
  const JsonValue& at(const std::string& key) const {
    auto it = members.find(key);
    if (it == members.end()) throw std::runtime_error("missing key " + key);
    return it->second;
  }
};

class JsonReader {
 public:
  explicit JsonReader(const std::string& text) : s_(text) {}
  JsonValue document() {
    JsonValue v = value();
    skip_space();
    if (i_ != s_.size()) fail("trailing characters");
    return v;
  }

 private:
  JsonValue value() {
    skip_space();
    JsonValue v;
    if (peek() == '{') {
      v.is_object = true;
      ++i_;
      skip_space();
      if (peek() == '}') return ++i_, v;
      for (;;) {
        skip_space();
        std::string key = string();
        skip_space();
        expect(':');
        v.members[key] = value();
        skip_space();
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect('}');
        return v;
      }
    }
    if (peek() == '[') {
      ++i_;
      skip_space();
      if (peek() == ']') return ++i_, v;
      for (;;) {
        value();
        skip_space();
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect(']');
        return v;
      }
    }
    if (peek() == '"') {
      string();
      return v;
    }
    std::size_t used = 0;
    v.number = std::stod(s_.substr(i_), &used);  // throws on anything else
    i_ += used;
    return v;
  }
  std::string string() {
    expect('"');
    std::size_t end = s_.find('"', i_);
    if (end == std::string::npos) fail("unterminated string");
    std::string out = s_.substr(i_, end - i_);
    i_ = end + 1;
    return out;
  }
  void skip_space() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected ") + c);
    ++i_;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error("JSON: " + what + " at " + std::to_string(i_));
  }

  const std::string& s_;
  std::size_t i_ = 0;
};

// A sphere from `oocsimp generate` and its simplification on a coarse grid.
struct SpherePair {
  ScratchDir dir;
  std::string original = dir.file("sphere.ply"), simplified = dir.file("sphere-32.ply");
  SpherePair() {
    REQUIRE(run_cli("generate --tris 100000 --quiet -o " + q(original)).exit_code == 0);
    REQUIRE(
        run_cli("simplify --quiet --method uniform " + q(original) + " -o " + q(simplified) + " --grid 32").exit_code ==
        0);
  }
};

}  // namespace

TEST_CASE("a mesh is at distance zero from itself, in any format", "[measure]") {
  ScratchDir d;
  write_cube_ply(d.file("cube.ply"), 12);
  write_zstd_file(d.file("cube.ply.zst"), read_file(d.file("cube.ply")));
  DistanceReport r = measure(d.file("cube.ply"), d.file("cube.ply.zst"), 20000);
  REQUIRE(r.a_diagonal == Approx(std::sqrt(3.0)));
  CHECK(r.a_area == Approx(6.0));
  CHECK(r.b_area == Approx(6.0));
  CHECK(r.a_triangles == 6 * 12 * 12 * 2);
  for (const DistanceStats* s : {&r.a_to_b, &r.b_to_a, &r.symmetric}) {
    CHECK(s->max <= 1e-6 * r.a_diagonal);
    CHECK(s->rms <= 1e-6 * r.a_diagonal);
  }
  check_sample_count(r.a_to_b, 20000);
  check_sample_count(r.b_to_a, 20000);
}

TEST_CASE("parallel unit squares offset by d are d apart everywhere", "[measure]") {
  ScratchDir d;
  const double offset = 0.25;
  write_plane_ply(d.file("a.ply"), 9, 0, 0, 0);
  write_plane_ply(d.file("b.ply"), 5, 0, 0, offset);  // a different tessellation of the same square
  DistanceReport r = measure(d.file("a.ply"), d.file("b.ply"), 50000);
  for (const DistanceStats* s : {&r.a_to_b, &r.b_to_a, &r.symmetric}) {
    CHECK(s->max == Approx(offset).margin(1e-7));
    CHECK(s->mean == Approx(offset).margin(1e-7));
    CHECK(s->rms == Approx(offset).margin(1e-7));
  }
  CHECK(r.fraction_of_diagonal(r.symmetric).max == Approx(offset / r.a_diagonal).margin(1e-7));
}

TEST_CASE("a unit square against a centred square of half its side", "[measure]") {
  ScratchDir d;
  write_file(d.file("unit.obj"), square_obj(0, 0, 1, 0));
  write_file(d.file("half.obj"), square_obj(0.25, 0.25, 0.5, 0));
  const std::uint64_t n = 200000;
  DistanceReport r = measure(d.file("unit.obj"), d.file("half.obj"), n);
  check_sample_count(r.a_to_b, n);
  check_sample_count(r.b_to_a, n);

  // B lies inside A: every B sample is on A.
  CHECK(r.b_to_a.max <= 1e-12);

  // From A to B the distance field is 0 on B (area 1/4), the distance t across the four
  // 1/2 x 1/4 strips beside B's edges (area 1/2) and the distance to B's corner in the
  // four 1/4 x 1/4 corner squares (area 1/4). With a = 1/4:
  //   max  = a sqrt(2) (A's corners),
  //   mean = 1/2 * a/2 + 1/4 * a (sqrt(2) + ln(1 + sqrt(2))) / 3,
  //   rms² = 1/2 * a²/3 + 1/4 * 2a²/3.
  const double a = 0.25;
  const double hausdorff = a * std::sqrt(2.0);
  const double mean = 0.5 * a / 2 + 0.25 * a * (std::sqrt(2.0) + std::log(1 + std::sqrt(2.0))) / 3;
  const double rms = std::sqrt(0.5 * a * a / 3 + 0.25 * 2 * a * a / 3);
  CHECK(r.a_to_b.max <= hausdorff + 1e-9);  // samples never exceed the true maximum
  CHECK(r.a_to_b.max >= 0.98 * hausdorff);
  CHECK(r.a_to_b.mean == Approx(mean).epsilon(0.01));
  CHECK(r.a_to_b.rms == Approx(rms).epsilon(0.01));

  CHECK(r.symmetric.max == r.a_to_b.max);
  CHECK(r.symmetric.samples == r.a_to_b.samples + r.b_to_a.samples);
  double union_mean = (r.a_to_b.mean * double(r.a_to_b.samples) + r.b_to_a.mean * double(r.b_to_a.samples)) /
                      double(r.symmetric.samples);
  CHECK(r.symmetric.mean == Approx(union_mean).epsilon(1e-12));
  CHECK(r.fraction_of_diagonal(r.a_to_b).max == Approx(r.a_to_b.max / std::sqrt(2.0)));
}

TEST_CASE("zero-area triangles get no samples and are not part of either surface", "[measure]") {
  ScratchDir d;
  // A has a degenerate triangle lying in B's plane; if it were surface, some B samples
  // would be closer than 0.25 to A. B has one lying in A's plane, the same way round.
  write_file(d.file("a.obj"), with_degenerate_triangle(square_obj(0, 0, 1, 0), 0.25));
  write_file(d.file("b.obj"), with_degenerate_triangle(square_obj(0, 0, 1, 0.25), 0));
  DistanceReport r = measure(d.file("a.obj"), d.file("b.obj"), 20000);
  CHECK(r.a_triangles == 3);
  CHECK(r.a_area == Approx(1.0));
  for (const DistanceStats* s : {&r.a_to_b, &r.b_to_a}) {
    CHECK(s->max == Approx(0.25).margin(1e-6));
    CHECK(s->mean == Approx(0.25).margin(1e-6));
  }
}

TEST_CASE("sample counts follow the request", "[measure]") {
  ScratchDir d;
  write_plane_ply(d.file("a.ply"), 20, 0.3, -0.2, 0);
  write_plane_ply(d.file("b.ply"), 7, 0.3, -0.2, 0.01);
  for (std::uint64_t n : {1000u, 12345u, 100000u}) {
    DistanceReport r = measure(d.file("a.ply"), d.file("b.ply"), n);
    check_sample_count(r.a_to_b, n);
    check_sample_count(r.b_to_a, n);
  }
}

TEST_CASE("a sphere against its simplification: small, nonzero and reproducible", "[measure]") {
  SpherePair sphere;
  DistanceReport one = measure(sphere.original, sphere.simplified, 100000, 7, 1);
  DistanceReport two = measure(sphere.original, sphere.simplified, 100000, 7, 2);
  DistanceReport again = measure(sphere.original, sphere.simplified, 100000, 7, 0);
  DistanceReport other_seed = measure(sphere.original, sphere.simplified, 100000, 8, 0);

  DistanceStats rel = one.fraction_of_diagonal(one.symmetric);
  CHECK(rel.rms > 1e-6);
  CHECK(rel.rms < 1e-2);
  CHECK(one.symmetric.max >= one.symmetric.rms);
  CHECK(one.symmetric.rms >= one.symmetric.mean);
  CHECK(one.symmetric.max == std::max(one.a_to_b.max, one.b_to_a.max));
  CHECK(one.b_triangles < one.a_triangles / 10);

  CHECK(same(one, two));    // any thread count
  CHECK(same(one, again));  // same seed
  CHECK_FALSE(same(one, other_seed));
  CHECK(other_seed.symmetric.rms == Approx(one.symmetric.rms).epsilon(0.05));
}

TEST_CASE("measure rejects bad options and inputs with the library's errors", "[measure]") {
  ScratchDir d;
  write_plane_ply(d.file("a.ply"), 4, 0, 0, 0);
  write_file(d.file("line.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  CHECK_THROWS_AS(measure(d.file("a.ply"), d.file("a.ply"), 0), UsageError);
  CHECK_THROWS_AS(measure(d.file("a.ply"), d.file("missing.ply"), 100), IoError);
  CHECK_THROWS_AS(measure(d.file("line.obj"), d.file("a.ply"), 100), InputError);  // no area
  CHECK_THROWS_AS(measure(d.file("a.ply"), d.file("line.obj"), 100), InputError);
}

TEST_CASE("oocsimp measure prints a table or JSON and maps errors to exit codes", "[measure][cli]") {
  SpherePair sphere;
  const std::string files = q(sphere.original) + " " + q(sphere.simplified);

  CliResult table = run_cli("measure " + files + " --samples 20000 --quiet");
  INFO(table.err);
  REQUIRE(table.exit_code == 0);
  CHECK(table.out.find("symmetric") != std::string::npos);
  CHECK(table.out.find("hausdorff") != std::string::npos);
  CHECK(table.err.empty());

  CliResult json = run_cli("measure " + files + " --samples 20000 --seed 3 --threads 2 --json --quiet");
  REQUIRE(json.exit_code == 0);
  JsonValue doc = JsonReader(json.out).document();
  DistanceReport lib = measure(sphere.original, sphere.simplified, 20000, 3);
  for (const char* direction : {"a_to_b", "b_to_a", "symmetric"}) {
    const JsonValue& s = doc.at(direction);
    for (const char* key : {"samples", "hausdorff", "mean", "rms"}) CHECK_NOTHROW(s.at(key));
    for (const char* key : {"hausdorff", "mean", "rms"}) CHECK_NOTHROW(s.at("of_diagonal").at(key));
  }
  CHECK(doc.at("a_to_b").at("samples").number == double(lib.a_to_b.samples));
  CHECK(doc.at("symmetric").at("hausdorff").number == Approx(lib.symmetric.max).epsilon(1e-8));
  CHECK(doc.at("b_to_a").at("of_diagonal").at("rms").number ==
        Approx(lib.fraction_of_diagonal(lib.b_to_a).rms).epsilon(1e-8));
  CHECK(doc.at("a").at("diagonal").number == Approx(lib.a_diagonal).epsilon(1e-8));
  CHECK(doc.at("b").at("triangles").number == double(lib.b_triangles));
  CHECK(doc.at("memory").at("peak_rss_bytes").number > 0);

  ScratchDir d;
  CliResult missing = run_cli("measure " + q(d.file("missing.ply")) + " " + q(sphere.simplified) + " --quiet");
  CHECK(missing.exit_code == 4);
  CHECK(missing.err.find("missing.ply") != std::string::npos);

  std::string truncated = read_file(sphere.simplified);
  truncated.resize(truncated.size() / 2);
  write_file(d.file("truncated.ply"), truncated);
  CliResult malformed = run_cli("measure " + q(sphere.original) + " " + q(d.file("truncated.ply")) + " --quiet");
  CHECK(malformed.exit_code == 3);
  CHECK(malformed.err.find("truncated.ply") != std::string::npos);

  CHECK(run_cli("measure " + files + " --samples 0 --quiet").exit_code == 2);
  CHECK(run_cli("measure " + q(sphere.original) + " --quiet").exit_code == 2);
}
