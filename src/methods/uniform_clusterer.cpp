// Uniform-grid vertex clustering with quadric representatives: Lindstrom,
// "Out-of-Core Simplification of Large Polygonal Models" (SIGGRAPH 2000), OoCS.
//
// Two streaming passes over the input, then a solve (cluster/uniform_cells does each):
//   1. vertices: per cell, the sum and count of the vertex positions in it (the
//      anchor of the quadric solve);
//   2. triangles: per cell, the sum of the area-weighted plane quadrics of every
//      triangle with a corner in it (and the weighted sums of the corners' attribute
//      values); triangles whose corners fall in three different cells survive, each
//      unordered cell triple once;
//   3. solve: the cells the surviving triangles use become the output vertices, each
//      at the point that minimises its quadric (see minimize_quadric).
// Memory holds the occupied cells and the surviving triangles, never the input, and
// stays within --mem (TableBudget) or the run stops: the checks between the steps
// are the check_* functions below.
#include "methods/uniform_clusterer.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "cluster/uniform_cells.hpp"
#include "methods/cluster_methods.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/phase_timer.hpp"
#include "grid/occupancy.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

// Up front, before any table grows: the occupied cells alone, estimated from a
// sample of the vertices (a lower estimate); kept triangles and output come on top.
void check_estimated_cells_fit(const TableBudget& budget, const OccupancyGrowth& occupancy, const GridSpec& grid,
                               std::uint64_t vertices) {
  const auto estimate = std::uint64_t(occupancy.occupied_by(grid_resolution(grid), vertices));
  budget.check(estimate * kCellEntryBytes, "about " + std::to_string(estimate) + " occupied cells, estimated");
}

// The cells are known after pass 1, before the faces are read: with the fewest kept
// triangles (none) and their output indices, do they fit?
void check_cell_table_fits(const TableBudget& budget, const UniformCells& cells) {
  budget.check(cells.cell_bytes() + 2 * sizeof(std::uint32_t) * cells.cell_count(),
               std::to_string(cells.cell_count()) + " occupied cells");
}

// Pass 2's attribute sums next to the cells.
void check_attribute_sums_fit(const TableBudget& budget, const UniformCells& cells) {
  if (cells.attribute_count() == 0) return;
  const std::uint64_t bytes = std::uint64_t(cells.cell_count()) * cells.attribute_width() * sizeof(double);
  budget.check(cells.cell_bytes() + bytes, std::to_string(cells.cell_count()) + " occupied cells with " +
                                               std::to_string(cells.attribute_count()) + " attributes each");
}

std::string output_tables(std::size_t cells, std::size_t triangles) {
  return std::to_string(cells) + " occupied cells and " + std::to_string(triangles) + " output triangles";
}

// The output tables next to the cells: first the numbering and the triangles (those
// in the heap when `place` puts them there)...
void check_numbering_fits(const TableBudget& budget, const UniformCells& cells, const ArrayPlace& place) {
  const std::uint64_t triangle_bytes = place.heap_bytes(3 * sizeof(std::uint32_t) * cells.kept_count());
  budget.check(cells.cell_bytes() + cells.attribute_sum_bytes() + cells.chosen_bytes() + cells.kept_bytes() +
                   2 * sizeof(std::uint32_t) * cells.cell_count() + triangle_bytes,
               output_tables(cells.cell_count(), cells.kept_count()));
}

// ... then (numbering and kept triangles freed) the positions and attribute values
// of the output vertices of `order`.
void check_positions_fit(const TableBudget& budget, const UniformCells& cells, const std::vector<std::uint32_t>& order,
                         const OutputMesh& mesh, const ArrayPlace& place) {
  const std::size_t triangles = mesh.triangle_count();
  const std::uint64_t triangle_bytes = mesh.triangles.mapped() ? 0 : 3 * sizeof(std::uint32_t) * triangles;
  budget.check(cells.cell_bytes() + cells.attribute_sum_bytes() + cells.chosen_bytes() +
                   sizeof(std::uint32_t) * order.capacity() + triangle_bytes +
                   place.heap_bytes(3 * sizeof(double) * order.size()) +
                   place.heap_bytes(cells.attribute_count() * sizeof(double) * order.size()),
               output_tables(cells.cell_count(), triangles));
}

void fill_stats(const SkippedFaces& skipped, std::uint64_t triangles, const UniformCells& cells, const OutputMesh& mesh,
                PhaseTimer* clock, SimplifyStats* stats) {
  stats->input_triangles = triangles;
  stats->skipped = skipped;
  stats->occupied_cells = cells.cell_count();
  stats->output_vertices = mesh.vertex_count();
  stats->output_triangles = mesh.triangle_count();
  stats->output_edges = mesh.primitives.edge_count();
  stats->output_points = mesh.primitives.point_count();
  clock->move_to(&stats->phases);
}

// After the passes: the output vertices numbered and placed.
OutputMesh solve(UniformCells& cells, const RunPlan& plan, const TableBudget& budget, std::vector<Quadric>* quadrics,
                 std::size_t locked, SimplifyStats* stats) {
  // The hash indexes are not needed any more; free them before the output arrays
  // are allocated, which keeps the peak down.
  cells.release_indexes();
  // The chunks' tables were freed on several threads: let the caller's allocator give
  // that memory back before the output arrays come (see RunPlan::release_memory).
  if (plan.release_memory) plan.release_memory();
  const ArrayPlace place = ArrayPlace::within(plan.budget_bytes, plan.temp_dir);
  check_numbering_fits(budget, cells, place);
  OutputMesh mesh;
  const std::vector<std::uint32_t> order = cells.number_output_vertices(&mesh, place);
  // A locked vertex whose neighbours all fall in one other cell makes no triangle with
  // two other clusters: it is dropped, and said so.
  warn_dropped_locks(locked - cells.locked_output_count(order), locked, stats);
  check_positions_fit(budget, cells, order, mesh, place);
  cells.solve_representatives(order, &mesh, quadrics, place);
  return mesh;
}

}  // namespace

OutputMesh cluster_uniform(MeshInput& input, const RunPlan& plan, const GridSpec& grid, SimplifyStats* stats,
                           std::vector<Quadric>* quadrics) {
  return cluster_cells(input, plan, grid, ClusterCellSource(), stats, quadrics);
}

OutputMesh cluster_cells(MeshInput& input, const RunPlan& plan, const GridSpec& grid, const ClusterCellSource& source,
                         SimplifyStats* stats, std::vector<Quadric>* quadrics) {
  const ProgressCallback& progress = plan.progress;
  const OccupancyGrowth occupancy = sampled_occupancy_growth(input.positions, input.info.bounds);
  const TableBudget budget(MemoryBudget(plan.budget_bytes, plan.budget_counts_process), grid, occupancy,
                           input.positions.count);
  check_estimated_cells_fit(budget, occupancy, grid, input.positions.count);
  const LockedVertices locked(plan.locked_vertices, input.positions, grid);
  UniformCells cells(grid, input.attributes, source.clusters, &locked);

  PhaseTimer clock;
  cells.add_vertices(input.positions, budget, progress);
  check_cell_table_fits(budget, cells);
  clock.end("vertices");

  check_attribute_sums_fit(budget, cells);
  cells.start_face_sums(plan.thick_edges);
  const std::uint64_t triangles = cells.add_triangles(input, budget, progress);
  clock.end("faces");
  if (source.matches) {
    cells.choose_vertices(input.positions, source.matches, source.context, progress);
    clock.end("vertices chosen");
  }

  ProgressPhase solve_phase(progress, "solve", 0, "cell");
  OutputMesh mesh = solve(cells, plan, budget, quadrics, locked.size(), stats);
  clock.end("solve");
  if (stats) fill_stats(input.triangles->skipped(), triangles, cells, mesh, &clock, stats);
  return mesh;
}

OutputMesh merge_uniform_chunks(MeshInput& input, const RunPlan& plan, const GridSpec& grid,
                                const UniformChunkSource& chunks, SimplifyStats* stats,
                                std::vector<Quadric>* quadrics) {
  const OccupancyGrowth occupancy = sampled_occupancy_growth(input.positions, input.info.bounds);
  const TableBudget budget(MemoryBudget(plan.budget_bytes, plan.budget_counts_process), grid, occupancy,
                           input.positions.count);
  check_estimated_cells_fit(budget, occupancy, grid, input.positions.count);
  UniformCells cells(grid, input.attributes);

  PhaseTimer clock;
  {
    ProgressPhase phase(plan.progress, "merge cell means", chunks.vertex_chunks, "chunk");
    VertexChunkSums v;
    for (std::uint64_t j = 0; j < chunks.vertex_chunks; ++j) {
      chunks.vertices(j, &v);
      cells.merge_vertex_chunk(v);
      budget.check(cells.cell_bytes(), std::to_string(cells.cell_count()) + " occupied cells");
      phase.set(j + 1);
    }
  }
  check_cell_table_fits(budget, cells);
  clock.end("vertices");
  check_attribute_sums_fit(budget, cells);
  cells.start_face_sums(false);
  std::uint64_t triangles = 0;
  {
    ProgressPhase phase(plan.progress, "merge cell quadrics", chunks.face_chunks, "chunk");
    FaceChunkSums f;
    for (std::uint64_t j = 0; j < chunks.face_chunks; ++j) {
      chunks.faces(j, &f);
      cells.merge_face_chunk(f);
      triangles += f.triangles;
      budget.check(cells.cell_bytes() + cells.kept_bytes(), std::to_string(cells.cell_count()) +
                                                                " occupied cells and " +
                                                                std::to_string(cells.kept_count()) + " kept triangles");
      phase.set(j + 1);
    }
  }
  clock.end("faces");
  ProgressPhase solve_phase(plan.progress, "solve", 0, "cell");
  OutputMesh mesh = solve(cells, plan, budget, quadrics, 0, stats);
  clock.end("solve");
  if (stats) fill_stats(chunks.skipped, triangles, cells, mesh, &clock, stats);
  return mesh;
}

}  // namespace oocsimp
