// plan_run (api/run_plan.cpp): the user's options settled once, before any method
// runs. Expected values come from the options' documented defaults and from the
// input's geometry, not from the methods.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "api/simplify.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/names.hpp"

using namespace oocsimp;

namespace {

// A box 3 x 4 x 12 (diagonal 13) as one tetrahedron's corners at opposite ends.
struct Tetrahedron {
  std::vector<double> positions{0, 0, 0, 3, 0, 0, 0, 4, 0, 3, 4, 12};
  std::vector<std::uint32_t> indices{0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
  MeshView view() const {
    MeshView v;
    v.positions = positions.data();
    v.position_type = ScalarType::f64;
    v.vertex_count = 4;
    v.indices = indices.data();
    v.triangle_count = 4;
    return v;
  }
};

}  // namespace

TEST_CASE("plan_run settles every default: method, budget, temporary folder", "[run_plan]") {
  const Tetrahedron t;
  MeshInput input = open_mesh_view(t.view());
  SimplifyOptions o;
  const RunPlan plain = plan_run(input, o);
  CHECK(plain.method == ClusterMethod::floating);  // automatic without a target
  CHECK(plain.budget_bytes == default_memory_budget());
  CHECK(plain.temp_dir == default_temp_dir());
  CHECK(!plain.target.given());  // a clustering without a target has none

  o.target.triangles = 100;
  o.memory_budget = std::uint64_t(64) << 20;
  o.temp_dir = "/somewhere";
  const RunPlan targeted = plan_run(input, o);
  CHECK(targeted.method == ClusterMethod::qem);  // automatic with a target
  CHECK(targeted.budget_bytes == (std::uint64_t(64) << 20));
  CHECK(targeted.temp_dir == "/somewhere");
  CHECK(targeted.target.triangles == 100);
  CHECK(targeted.target.ratio == 0);
}

TEST_CASE("plan_run gives the qem method alone the default share, and a fraction of the diagonal in units",
          "[run_plan]") {
  const Tetrahedron t;
  MeshInput input = open_mesh_view(t.view());
  SimplifyOptions o;
  o.method = ClusterMethod::qem;
  const RunPlan alone = plan_run(input, o);
  CHECK(alone.target.given());
  CHECK(alone.target.ratio == kDefaultRatio);
  CHECK(alone.target.triangles == 0);

  SimplifyOptions e;
  e.target.max_error_of_diagonal = 0.01;
  const RunPlan error = plan_run(input, e);
  CHECK(error.target.max_error == Approx(0.13).epsilon(1e-12));  // 1% of sqrt(3^2 + 4^2 + 12^2) = 13
  CHECK(error.target.max_error_of_diagonal == 0);
  CHECK(error.target.ratio == 0);  // a maximum error alone asks for no count
}

TEST_CASE("plan_run sorts the locked vertices and keeps each once", "[run_plan]") {
  const Tetrahedron t;
  MeshInput input = open_mesh_view(t.view());
  SimplifyOptions o;
  o.locked_vertices = {3, 1, 3, 0, 1};
  CHECK(plan_run(input, o).locked_vertices == std::vector<std::uint64_t>{0, 1, 3});
}

TEST_CASE("plan_run refuses what a run cannot take, naming the option", "[run_plan]") {
  const Tetrahedron t;
  MeshInput input = open_mesh_view(t.view());
  const auto refused = [&](const SimplifyOptions& o) -> std::string {
    try {
      plan_run(input, o);
    } catch (const UsageError& e) {
      return e.what();
    }
    return "";
  };
  SimplifyOptions both;
  both.target.triangles = 10;
  both.target.ratio = 0.5;
  CHECK(refused(both).find("at most one of options.target.triangles and options.target.ratio") != std::string::npos);
  SimplifyOptions sized;
  sized.method = ClusterMethod::qem;
  sized.sizing.grid = 10;
  CHECK(refused(sized).find("apply to the clustering methods") != std::string::npos);
  SimplifyOptions small;
  small.memory_budget = 1 << 20;
  CHECK(refused(small).find("below the minimum") != std::string::npos);
  SimplifyOptions lock;
  lock.locked_vertices = {4};
  CHECK(refused(lock).find("names vertex 4") != std::string::npos);
  SimplifyOptions fraction;
  fraction.target.max_error_of_diagonal = 2;
  CHECK(refused(fraction).find("at most 1 (100%)") != std::string::npos);
}
