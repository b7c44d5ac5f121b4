#include "refine/edge_collapse.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "cluster/plane_quadric.hpp"
#include "common/huge_pages.hpp"
#include "common/vec3_math.hpp"
#include "refine/collapse_passes.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

UnitNormal unit_normal(const Vec3d& normal) {
  const double l = length(normal);
  if (!(l > 0)) return {};
  return {float(normal.x / l), float(normal.y / l), float(normal.z / l)};
}

// Each vertex's sum takes its faces in the order of the list, as one thread would, so
// the bits do not depend on the threads: the vertices are cut into one range per
// thread, and each range's thread walks every face, adding those with a corner in it.
// A face's plane is found once per range its corners fall in (mostly one: a mesh's
// faces use nearby indices).
std::vector<Quadric> face_quadrics(const std::vector<Vec3d>& positions, const std::vector<std::uint32_t>& triangles) {
  std::vector<Quadric> q;
  resize_filled(&q, positions.size());
  const std::size_t n = positions.size();
  const std::size_t ranges = std::size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  tbb::parallel_for(
      std::size_t(0), ranges,
      [&](std::size_t r) {
        const std::uint32_t lo = std::uint32_t(n * r / ranges), hi = std::uint32_t(n * (r + 1) / ranges);
        const auto inside = [&](std::uint32_t v) { return v >= lo && v < hi; };
        for (std::size_t f = 0; f + 2 < triangles.size(); f += 3) {
          const std::uint32_t t[3] = {triangles[f], triangles[f + 1], triangles[f + 2]};
          if (!inside(t[0]) && !inside(t[1]) && !inside(t[2])) continue;
          const Vec3d& p = positions[t[0]];
          const TrianglePlane plane = triangle_plane(positions[t[1]] - p, positions[t[2]] - p);
          if (plane.degenerate()) continue;
          Quadric face;
          add_plane_quadric(&face, plane, dot(plane.m, p));
          for (const std::uint32_t v : t)
            if (inside(v)) q[v].add(face);
        }
      },
      tbb::simple_partitioner());
  return q;
}

namespace {

// Why no collapse is left: every live edge under the first reason valid() gives (or
// a locked end, or none), and the pieces of the edges of one face, by union-find over
// their ends. Run once, when the collapse is stuck.
CollapseStats::StuckEdges stuck_edges(const CollapseState& state) {
  CollapseStats::StuckEdges why;
  std::vector<std::uint32_t> ring, parent(state.vertex_count());
  std::vector<std::uint64_t> boundary(state.vertex_count(), 0);  // edges of one face in each piece, at its root
  for (std::uint32_t v = 0; v < parent.size(); ++v) parent[v] = v;
  const auto root = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (std::uint32_t a = 0; a < state.vertex_count(); ++a) {
    if (!state.alive(a)) continue;
    state.neighbours(a, &ring);
    for (const std::uint32_t b : ring) {
      if (b < a) continue;
      ++why.edges;
      if (state.faces_on_edge(a, b) == 1) {
        const std::uint32_t ra = root(a), rb = root(b);
        if (ra != rb) parent[ra] = rb, boundary[rb] += boundary[ra];
        ++boundary[rb];
      }
      if (state.locked(a) || state.locked(b)) {
        ++why.locked;
        continue;
      }
      std::uint32_t blamed = CollapseState::kNoFace;
      if (state.valid(state.evaluate(a, b), &blamed))
        ++why.overshoot;
      else if (blamed != CollapseState::kNoFace)
        ++why.folds;
      else
        ++why.topology;
    }
  }
  for (std::uint32_t v = 0; v < parent.size(); ++v)
    if (root(v) == v && boundary[v] > 0) {
      ++why.loops;
      why.loops_of_three += boundary[v] == 3;
    }
  return why;
}

}  // namespace

void collapse_state(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                    ProgressPhase* progress) {
  const std::uint64_t passes_to =
      std::max(settings.target_triangles, std::uint64_t(settings.pass_share * double(settings.target_triangles)));
  if (settings.pass_faces && state.triangle_count() >= settings.pass_faces && state.triangle_count() > passes_to)
    collapse_in_passes(state, settings, passes_to, stats, progress);
  collapse_in_order(state, settings, stats, progress);
}

// Large meshes collapse in tiles first, in parallel, in rounds of at most 4x fewer
// faces (a tile's data stays in the caches, which the whole mesh's passes miss): the
// tiles' borders stay as they were in a round, and the next round's tiles, cut from
// the fewer faces, fall elsewhere. The whole mesh then collapses, in passes and in
// order of cost, from the tiles' result (the boundary planes already in its quadrics).
// Each coarser level goes on from the state the finer one left.
void collapse_edges_to_levels(QuadricMesh mesh, const CollapseSettings& settings,
                              const std::vector<std::uint64_t>& coarser, CollapseStats* stats,
                              const CollapseLevelSink& each, ProgressPhase* progress) {
  CollapseStats local;
  CollapseStats& st = stats ? *stats : local;
  CollapseState state(std::move(mesh), settings);
  st.non_manifold_vertices = state.non_manifold_count();
  const double tiles_to = double(settings.target_triangles) * settings.tile_share;
  while (settings.tile_faces && state.triangle_count() >= std::max(settings.tile_min_faces, 4 * settings.tile_faces) &&
         tiles_to < 0.75 * double(state.triangle_count())) {
    CollapseSettings round = settings;
    round.target_triangles = std::uint64_t(std::max(tiles_to, 0.25 * double(state.triangle_count())));
    round.tile_share = 1;
    const std::uint64_t before = state.triangle_count();
    QuadricMesh tiled = collapse_tiles(state, round, &st);
    if (progress) progress->set(2 * st.collapses);
    round.boundary_weight = 0;
    state = CollapseState(std::move(tiled), round);
    // A round that took less than a quarter of what it aimed at (the tiles' borders
    // hold most collapses, as around a hub every tile shares) would be followed by
    // others like it: the passes of the whole mesh go on instead.
    if (4 * (before - state.triangle_count()) < before - round.target_triangles) break;
  }
  CollapseSettings level = settings;
  for (std::size_t k = 0; k <= coarser.size(); ++k) {
    if (k > 0) {
      level.target_triangles = coarser[k - 1];
      st.stuck = st.stopped_by_error = st.parity = false;
      state.restore_needle_guard(level.min_compactness);
    }
    // A mesh already below an exact target (the out-of-core passes took the free
    // collapses of a flat mesh past it): edges split up to it, the surface unchanged.
    if (level.exact_count && state.triangle_count() < level.target_triangles &&
        !state.split_up_to(level.target_triangles))
      st.parity = st.stuck = state.triangle_count() + 1 == level.target_triangles;
    collapse_state(state, level, &st, progress);
    // Every collapse left would make a needle: on the generated sphere to a low target
    // the collapse jammed well short of it, every edge refused, most by the needle
    // guard. The count asked wins over the guard: the rest go without it.
    if (st.stuck && !st.stopped_by_error && !st.parity && level.exact_count &&
        state.triangle_count() > level.target_triangles && level.min_compactness > 0) {
      st.stuck = false;
      state.drop_needle_guard();
      collapse_in_order(state, level, &st, progress);
    }
    st.why_stuck = st.stuck && !st.stopped_by_error && !st.parity ? stuck_edges(state) : CollapseStats::StuckEdges{};
    each(k, state.result(nullptr, !settings.result_quadrics), st);
  }
}

QuadricMesh collapse_edges(QuadricMesh mesh, const CollapseSettings& settings, CollapseStats* stats,
                           ProgressPhase* progress) {
  QuadricMesh out;
  collapse_edges_to_levels(
      std::move(mesh), settings, {}, stats,
      [&](std::size_t, QuadricMesh level, const CollapseStats&) { out = std::move(level); }, progress);
  return out;
}

}  // namespace oocsimp
