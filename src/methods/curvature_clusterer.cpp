// Vertex clustering by principal curvature: Hua, Huang & Li, "Mesh Simplification
// Using Vertex Clustering Based on Principal Curvature". The steps:
//   1. octree: the grid's N cells (§3.3 step 1), each split where the curvatures of
//      its children do not match its own (§3.4: "go on subdividing the bounding box"),
//      all estimated at the cells' scale from per-cell moments of the faces, summed in
//      streaming passes like the quadrics (cluster/cell_moments.hpp);
//   2. with vertex representatives only, every vertex's k1 and k2 by integral
//      invariants (§3.4 eq. 8-18), out of core (curvature/mesh_curvatures.hpp);
//   3. parts: each leaf cut into the connected parts of the surface in it, so two
//      sheets through one cell stay apart (our rule; the paper merges them);
//   4. clusters: OoCS's passes over them (methods/uniform_clusterer.cpp): quadrics
//      summed, triangles over three clusters kept (§3.3 steps 2-4), and each
//      cluster's representative the matching vertex of least quadric error (§3.3
//      step 3, §3.4), or the quadric's minimiser in the leaf.
// The choices are in docs/curvature.md.
#include "methods/curvature_clusterer.hpp"

#include <algorithm>
#include <string>

#include "cluster/curvature_cells.hpp"
#include "curvature/mesh_curvatures.hpp"
#include "methods/uniform_clusterer.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/phase_timer.hpp"

namespace oocsimp {

namespace {

// What the estimator may hold: the budget less what the process holds now.
CurvatureOptions curvature_options(const RunPlan& plan, const MemoryBudget& budget) {
  constexpr std::uint64_t kLeast = 1 << 20;  // 0 would mean "the default budget"
  CurvatureOptions o;
  o.radius = plan.curvature.radius;
  o.neighbourhood = plan.curvature.sphere_neighbourhood ? CurvatureNeighbourhood::sphere : CurvatureNeighbourhood::ball;
  o.tile_side = plan.curvature.tile_side;
  o.threads = plan.threads;
  const std::uint64_t held = budget.held();
  o.memory_budget = std::max(kLeast, budget.bytes() > held ? budget.bytes() - held : 0);
  o.temp_dir = plan.temp_dir;
  o.progress = plan.progress;
  return o;
}

// A vertex against its cluster's cell, for UniformCells::choose_vertices.
struct MatchContext {
  const VertexClusters* clusters;
  const float* k;
};

bool vertex_matches(const void* context, std::uint64_t v, std::uint64_t cluster) {
  const MatchContext& c = *static_cast<const MatchContext*>(context);
  return c.clusters->matches(std::uint32_t(cluster), c.k[2 * v], c.k[2 * v + 1]);
}

void note_estimates(const CurvatureStats& c, SimplifyStats* stats) {
  if (c.none > 0)
    stats->warnings.push_back(std::to_string(c.none) +
                              " vertices have no curvature estimate (no face, no area or too few neighbours within "
                              "the radius): they count as flat");
}

// Steps 2-4 at one grid, from the curvatures `k`; the phases go to `clock`'s stages
// and then to `stats`.
OutputMesh cluster_at(MeshInput& input, const RunPlan& plan, const GridSpec& grid, const float* k,
                      const MemoryBudget& budget, const std::string& temp, PhaseTimer* clock, SimplifyStats* stats,
                      std::vector<Quadric>* quadrics) {
  CurvatureCellSettings settings;
  settings.tolerance = plan.curvature.tolerance;
  settings.max_depth = plan.curvature.max_depth;
  VertexClusters clusters(grid, settings, input.positions.count, temp);
  const bool vertex_rule = plan.curvature.representative == RepresentativeRule::vertex;
  clusters.find_leaves(input, vertex_rule ? k : nullptr, budget, plan.progress);
  clock->end("octree");

  clusters.join_components(input, plan.progress);
  clock->end("parts");

  const MatchContext context{&clusters, k};
  ClusterCellSource source;
  source.clusters = &clusters;
  if (plan.curvature.representative == RepresentativeRule::vertex) {
    source.matches = vertex_matches;
    source.context = &context;
  }
  clock->move_to(&stats->phases);  // the uniform passes' phases follow
  return cluster_cells(input, plan, grid, source, stats, quadrics);
}

// Whether the run reads the vertices' own curvatures: only the vertex representatives
// do; the octree reads the cells' (find_leaves), at the uniform grid's pace.
bool reads_curvatures(const RunPlan& plan) { return plan.curvature.representative == RepresentativeRule::vertex; }

// The levels, with the curvatures from `fill`.
using BudgetedFill = std::function<CurvatureStats(float* k, const MemoryBudget& budget)>;
void run_levels(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids, const LevelSink& sink,
                const SimplifyStats& base, std::vector<Quadric>* quadrics, const BudgetedFill& fill) {
  const MemoryBudget budget(plan.budget_bytes, plan.budget_counts_process);
  PhaseTimer clock;
  const std::string& temp = plan.temp_dir;
  MappedCurvatures k(temp, input.positions.count);
  CurvatureStats estimated;
  if (reads_curvatures(plan)) {
    estimated = fill(k.data(), budget);
    // The tiles' buffers were freed on several threads: let the allocator give them
    // back before the tables come (see SimplifyOptions::release_memory).
    if (plan.release_memory) plan.release_memory();
    clock.end("curvatures");
  }
  for (std::size_t level = 0; level < grids.size(); ++level) {
    if (level > 0) clock.restart();
    input.restart_triangles();
    SimplifyStats stats = base;
    OutputMesh mesh = cluster_at(input, plan, grids[level], k.data(), budget, temp, &clock, &stats, quadrics);
    if (level == 0) note_estimates(estimated, &stats);
    sink(level, mesh, stats);
  }
}

}  // namespace

OutputMesh cluster_curvature(MeshInput& input, const RunPlan& plan, const GridSpec& grid, SimplifyStats* stats,
                             std::vector<Quadric>* quadrics) {
  return single_level(cluster_curvature_levels, input, plan, grid, stats, quadrics);
}

void cluster_curvature_levels(MeshInput& input, const RunPlan& plan, const std::vector<GridSpec>& grids,
                              const LevelSink& sink, const SimplifyStats& base, std::vector<Quadric>* quadrics) {
  run_levels(input, plan, grids, sink, base, quadrics, [&](float* k, const MemoryBudget& budget) {
    return estimate_mesh_curvatures(input, curvature_options(plan, budget), k);
  });
}

CurvaturePartPlan estimate_curvature_part(MeshInput& input, const RunPlan& plan, std::uint32_t part,
                                          std::uint32_t parts, const CurvatureSink& sink, SimplifyStats* stats) {
  CurvaturePartPlan estimate;
  estimate.vertices = input.positions.count;
  estimate.triangles = input.info.face_count;  // as the header says, where nothing is estimated
  if (!reads_curvatures(plan)) return estimate;
  PhaseTimer clock;
  const MemoryBudget budget(plan.budget_bytes, plan.budget_counts_process);
  const VertexDeal deal(input.positions, input.info.bounds, part, parts);
  const CurvatureStats c = estimate_dealt_curvatures(input, curvature_options(plan, budget), deal, sink);
  clock.end("curvatures");
  estimate.triangles = c.triangles;
  estimate.radius = c.radius;
  estimate.invariant = c.invariant;
  estimate.fitted = c.fitted;
  estimate.estimated = 1;
  if (stats) clock.move_to(&stats->phases);
  return estimate;
}

OutputMesh merge_curvature_parts(MeshInput& input, const RunPlan& plan, const GridSpec& grid, const CurvatureFill& fill,
                                 SimplifyStats* stats, std::vector<Quadric>* quadrics) {
  OutputMesh out;
  run_levels(
      input, plan, {grid},
      [&](std::size_t, OutputMesh& m, SimplifyStats& s) {
        out = std::move(m);
        if (stats) *stats = std::move(s);
      },
      stats ? *stats : SimplifyStats(), quadrics, [&](float* k, const MemoryBudget&) { return fill(k); });
  return out;
}

}  // namespace oocsimp
