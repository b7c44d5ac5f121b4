// plan_run: the user's SimplifyOptions settled once into the RunPlan the methods read.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "api/simplify.hpp"
#include "common/vec3_math.hpp"
#include "methods/multiphase.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/names.hpp"
#include "runtime/memory_budget.hpp"

namespace oocsimp {

namespace {

// A max_error given as a fraction of the bounding box's diagonal, as the length it
// stands for on this input: what the collapse compares its errors with.
TargetOptions target_in_units(const MeshInput& input, TargetOptions t) {
  if (t.max_error_of_diagonal == 0) return t;
  if (t.max_error != 0)
    throw UsageError("options.target.max_error",
                     "give options.target.max_error in model units or as a fraction of the diagonal, not both");
  if (!(t.max_error_of_diagonal > 0 && t.max_error_of_diagonal <= 1))
    throw UsageError("options.target.max_error",
                     "options.target.max_error as a fraction of the bounding box's diagonal must be above 0 and at "
                     "most 1 (100%)");
  const double diagonal = input.info.bounds.empty() ? 0 : input.info.bounds.diagonal();
  t.max_error = t.max_error_of_diagonal * diagonal;
  if (!(t.max_error > 0))
    throw UsageError("options.target.max_error",
                     input.info.path +
                         ": the bounding box has no diagonal to take "
                         "options.target.max_error as a fraction of; give it in model units");
  t.max_error_of_diagonal = 0;
  return t;
}

// Throws UsageError unless target `t` of a run by `method` is consistent: at most one
// of triangles and ratio, no CellSizing `s` beside them, triangles at least 4, ratio in
// (0, 1], max_error positive and finite.
void check_target(const TargetOptions& t, const CellSizing& s, ClusterMethod method) {
  if (t.triangles != 0 && t.ratio != 0)
    throw UsageError("give at most one of options.target.triangles and options.target.ratio");
  if (t.given() && (s.cell != 0 || s.grid != 0 || s.ratio != 0))
    throw UsageError(
        "a target (options.target.triangles, options.target.ratio, options.target.max_error) sets the cell itself: "
        "give no options.sizing.cell, options.sizing.grid or options.sizing.ratio with it");
  if (method == ClusterMethod::qem && (s.cell != 0 || s.grid != 0 || s.ratio != 0))
    throw UsageError(
        "options.sizing.cell",
        "options.sizing.cell, options.sizing.grid and options.sizing.ratio apply to the clustering methods; the qem "
        "method takes options.target.triangles, options.target.ratio or options.target.max_error");
  if (t.triangles != 0 && t.triangles < kLeastTarget)
    throw UsageError("options.target.triangles", "options.target.triangles must be at least 4");
  if (t.ratio != 0 && !(t.ratio > 0 && t.ratio <= 1))
    throw UsageError("options.target.ratio", "options.target.ratio must be in (0, 1]");
  if (t.max_error != 0 && !(t.max_error > 0 && std::isfinite(t.max_error)))
    throw UsageError("options.target.max_error", "options.target.max_error must be a positive number");
  if (!(t.intermediate_factor >= 1 && std::isfinite(t.intermediate_factor)))
    throw UsageError("options.target.intermediate_factor", "options.target.intermediate_factor must be at least 1");
}

// The clusterers work, and a float output is written, within the float range: an
// input coordinate beyond it (possible in double input) is rejected up front, naming
// the first such vertex, whatever the output precision.
void check_float_range(const MeshInput& input) {
  const Box3d& b = input.info.bounds;
  constexpr double kMax = std::numeric_limits<float>::max();
  if (b.empty() || (std::max({-b.min.x, -b.min.y, -b.min.z, b.max.x, b.max.y, b.max.z}) <= kMax)) return;
  for (std::uint64_t i = 0; i < input.positions.count; ++i) {
    Vec3d p = input.positions.get(i);
    for (double c : {p.x, p.y, p.z})
      if (std::isfinite(c) && std::abs(c) > kMax) {  // non-finite vertices are skipped, not out of range
        std::ostringstream msg;
        msg << input.info.path << ": vertex " << i << " has the coordinate " << c
            << ", beyond the float range oocsimp works in";
        throw InputError(msg.str());
      }
  }
}

// The representative rules and the curvature method's numbers, each refused naming
// its option.
void check_method_options(const MeshInput& input, const SimplifyOptions& options) {
  const ClusterMethod m = resolved_method(options);
  if (m == ClusterMethod::floating && options.floating.representative == RepresentativeRule::vertex)
    throw UsageError("options.floating.representative",
                     "options.floating.representative vertex applies to the curvature method; floating takes "
                     "quadric, centre or mean");
  if (m != ClusterMethod::curvature) return;
  const CurvatureClusterOptions& c = options.curvature;
  if (c.representative != RepresentativeRule::vertex && c.representative != RepresentativeRule::quadric)
    throw UsageError("options.curvature.representative", std::string("options.curvature.representative ") +
                                                             representative_name(c.representative) +
                                                             ": the curvature method takes vertex or quadric");
  if (!(c.tolerance > 0) || !std::isfinite(c.tolerance))
    throw UsageError("options.curvature.tolerance", "options.curvature.tolerance must be a positive finite number");
  if (c.max_depth > 6) throw UsageError("options.curvature.max_depth", "options.curvature.max_depth must be 0 to 6");
  const Box3d& b = input.info.bounds;
  const double diagonal = b.empty() ? 0 : length(b.max - b.min);
  if (!(c.radius >= 0) || !std::isfinite(c.radius) || c.radius > diagonal) {
    std::ostringstream msg;
    msg << "options.curvature.radius " << c.radius
        << ": expected a positive finite length no longer than the bounding box's diagonal (" << diagonal << ")";
    throw UsageError("options.curvature.radius", msg.str());
  }
}

// What every run checks before its work: the budget's minimum, thick edges' methods,
// the locks, the methods' own options, the float range.
void check_run_options(const MeshInput& input, const SimplifyOptions& options) {
  // Said before starting, in bytes when it is no whole MiB ("0 MiB" for 1K would
  // not be what was given).
  const std::uint64_t minimum = minimum_memory_budget(), budget = options.memory_budget;
  if (budget != 0 && budget < minimum)
    throw UsageError("options.memory_budget", "options.memory_budget " +
                                                  (budget % (1u << 20) == 0 ? std::to_string(budget >> 20) + " MiB"
                                                                            : std::to_string(budget) + " bytes") +
                                                  " is below the minimum of " + std::to_string(minimum >> 20) + " MiB");
  // Thick edges come from clustering; a collapse to a target does not make them (yet),
  // and saying so beats dropping them.
  const ClusterMethod method = resolved_method(options);
  if (options.thick_edges && (method == ClusterMethod::qem || options.target.given()))
    throw UsageError("options.thick_edges",
                     "options.thick_edges needs a clustering method without a target (options.method floating or "
                     "uniform; exact targets do not make thick edges yet)");
  // A locked vertex is the edge collapse's fixed point, and a clustering method's
  // cluster of its own (in a phase 1 before a target too, whose collapse then holds it).
  for (std::uint64_t v : options.locked_vertices)
    if (v >= input.positions.count)
      throw UsageError("options.locked_vertices", "options.locked_vertices names vertex " + std::to_string(v) +
                                                      ", not below the input's vertex count " +
                                                      std::to_string(input.positions.count));
  // Floating cells find the boundary in their tiles, which hold every face of the
  // vertices they own; the uniform grid streams its faces and cannot.
  if (options.lock_boundary && method != ClusterMethod::qem && method != ClusterMethod::floating)
    throw UsageError("options.lock_boundary",
                     std::string("options.lock_boundary holds the boundary in the edge collapse (options.method qem, "
                                 "the default with a target) and in floating cells, not in ") +
                         method_name(method) + " clustering, which does not find the mesh's boundary");
  // A phase 1 keeps the boundary, but the collapse after it would hold its tears as
  // boundary too, and stall.
  if (options.lock_boundary && method == ClusterMethod::floating && options.target.given() &&
      options.target.refine == RefineMethod::qem)
    throw UsageError("options.lock_boundary",
                     "options.lock_boundary with a target is held by the edge collapse (options.method qem, the "
                     "default with a target), not by a floating phase 1, whose tears the collapse would hold too");
  check_method_options(input, options);
  check_float_range(input);
}

}  // namespace

RunPlan plan_run(const MeshInput& input, const SimplifyOptions& options) {
  const TargetOptions target = target_in_units(input, options.target);
  check_run_options(input, options);
  RunPlan plan;
  plan.method = resolved_method(options);
  plan.budget_bytes = budget_bytes(options.memory_budget);
  plan.budget_counts_process = options.budget_counts_process;
  plan.temp_dir = options.temp_dir.empty() ? default_temp_dir() : options.temp_dir;
  plan.threads = options.threads;
  plan.target = target;
  if (plan.method == ClusterMethod::qem || plan.target.given()) {
    check_target(plan.target, options.sizing, plan.method);
    // The qem method alone keeps the default share, now exactly.
    if (!plan.target.given()) plan.target.ratio = kDefaultRatio;
  }
  // Sorted, once: the passes look vertices up in it.
  plan.locked_vertices = options.locked_vertices;
  std::sort(plan.locked_vertices.begin(), plan.locked_vertices.end());
  plan.locked_vertices.erase(std::unique(plan.locked_vertices.begin(), plan.locked_vertices.end()),
                             plan.locked_vertices.end());
  plan.sizing = options.sizing;
  plan.floating = options.floating;
  plan.curvature = options.curvature;
  plan.precision = options.precision;
  plan.attributes = options.attributes;
  plan.weld = options.weld;
  plan.thick_edges = options.thick_edges;
  plan.lock_boundary = options.lock_boundary;
  plan.progress = options.progress;
  plan.release_memory = options.release_memory;
  return plan;
}

}  // namespace oocsimp
