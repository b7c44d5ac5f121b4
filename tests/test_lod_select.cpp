// LOD selection (Low & Tan 1997 §4, src/lod/lod_levels.cpp): R = 2 D tan(FOV/2) / H
// and the coarsest level whose cell is at most X R, on hand-computed cases.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "oocsimp/error.hpp"
#include "oocsimp/lod.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

const char* kThreeLevels =
    R"({"levels": [{"file": "out.lod0.ply", "cell": 0.01, "vertices": 100, "triangles": 200, "edges": 3, "points": 1},
                   {"file": "out.lod1.ply", "cell": 0.02}, {"file": "out.lod2.ply", "cell": 0.04}]})";

}  // namespace

TEST_CASE("the pixel size R = 2 D tan(FOV/2) / H", "[lod]") {
  CHECK(pixel_size_at(1, 90, 2) == Approx(1.0).epsilon(1e-15));            // tan 45 = 1
  CHECK(pixel_size_at(10, 60, 768) == Approx(20 / std::sqrt(3.0) / 768));  // tan 30 = 1 / sqrt 3
  CHECK(pixel_size_at(3, 120, 100) == Approx(6 * std::sqrt(3.0) / 100));   // tan 60 = sqrt 3
  CHECK_THROWS_AS(pixel_size_at(0, 60, 100), UsageError);
  CHECK_THROWS_AS(pixel_size_at(1, 180, 100), UsageError);
  CHECK_THROWS_AS(pixel_size_at(1, 0, 100), UsageError);
  CHECK_THROWS_AS(pixel_size_at(1, 60, 0.5), UsageError);
}

TEST_CASE("the coarsest level whose cell spans at most X pixels", "[lod]") {
  ScratchDir d;
  write_file(d.file("out.lods.json"), kThreeLevels);
  const std::vector<LodLevel> levels = read_lod_levels(d.file("out.lods.json"));
  REQUIRE(levels.size() == 3);
  CHECK(levels[0].file == "out.lod0.ply");
  CHECK(levels[0].triangles == 200);
  CHECK(levels[0].edges == 3);
  CHECK(levels[2].cell == 0.04);
  const double r = 0.015;                         // cells of 0.01, 0.02, 0.04 against X R
  CHECK(choose_lod(levels, r, 1).level == 0);     // 0.015: only 0.01
  CHECK(choose_lod(levels, r, 2).level == 1);     // 0.03
  CHECK(choose_lod(levels, r, 2.67).level == 2);  // 0.04005
  CHECK(choose_lod(levels, r, 10).level == 2);
  const LodChoice near = choose_lod(levels, 0.001, 5);  // 0.005: finer than any level
  CHECK(near.level == 0);
  CHECK(near.finest_too_coarse);
  CHECK_FALSE(choose_lod(levels, r, 1).finest_too_coarse);
  CHECK(choose_lod(levels, 0.01, 1).level == 0);  // a cell equal to X R is taken
  CHECK_THROWS_AS(choose_lod(levels, r, 0.5), UsageError);
}

TEST_CASE("lod-select prints the level, its file and the thick-line scale", "[lod][cli]") {
  ScratchDir d;
  write_file(d.file("out.lods.json"), kThreeLevels);
  // D = 10, FOV = 60, H = 768: R = 0.0150352, X = 5 (default) -> cells up to 0.0752.
  CliResult r = run_cli("lod-select " + q(d.file("out.lods.json")) + " --distance 10 --fov 60 --height 768");
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("level      2: out.lod2.ply") != std::string::npos);
  CHECK(r.out.find("66.51") != std::string::npos);  // 1 / R
  r = run_cli("lod-select " + q(d.file("out.lods.json")) + " --distance 10 --fov 60 --height 768 --factor 1 --json");
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("\"level\":0") != std::string::npos);
  CHECK(r.out.find("\"file\":\"out.lod0.ply\"") != std::string::npos);
}

TEST_CASE("lod-select: bad descriptions exit 3, bad numbers exit 2, a missing file 4", "[lod][cli]") {
  ScratchDir d;
  const std::string args = " --distance 10 --fov 60 --height 768";
  for (const char* bad : {"{\"levels\": [", "[]", "{\"levels\": []}", "{\"levels\": [{\"cell\": 1}]}",
                          "{\"levels\": [{\"file\": \"a\", \"cell\": -1}]}",
                          "{\"levels\": [{\"file\": \"a\", \"cell\": 2}, {\"file\": \"b\", \"cell\": 1}]}",
                          "{\"levels\": [{\"file\": \"a\", \"cell\": 1, \"triangles\": -3}]}"}) {
    INFO(bad);
    write_file(d.file("bad.json"), bad);
    const CliResult r = run_cli("lod-select " + q(d.file("bad.json")) + args);
    CHECK(r.exit_code == 3);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.find("bad.json") != std::string::npos);
  }
  write_file(d.file("ok.json"), kThreeLevels);
  for (const char* numbers : {" --distance 0 --fov 60 --height 768", " --distance 1 --fov 180 --height 768",
                              " --distance 1 --fov 60 --height 0", " --distance 1 --fov 60 --height 768 --factor 0.5",
                              " --distance x --fov 60 --height 768"}) {
    INFO(numbers);
    CHECK(run_cli("lod-select " + q(d.file("ok.json")) + numbers).exit_code == 2);
  }
  CHECK(run_cli("lod-select " + q(d.file("none.json")) + args).exit_code == 4);
}
