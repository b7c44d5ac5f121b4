// Exact targets: phase 1 clusters out of core to an intermediate of about k times the
// target, carrying each cluster's summed quadric; phase 2 collapses edges in core
// from those quadrics down to the target, so that no error information is lost
// between the phases (Garland & Shaffer 2002). --method qem is phase 2 alone on the
// whole input.
#include "methods/multiphase.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cluster/attribute_sums.hpp"
#include "common/huge_pages.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/phase_timer.hpp"
#include "common/vec3_math.hpp"
#include "grid/grid_choice.hpp"
#include "io/attribute_array.hpp"
#include "methods/cluster_methods.hpp"
#include "methods/qem_passes.hpp"
#include "oocsimp/error.hpp"
#include "refine/edge_collapse.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

// Garland & Shaffer 2002 §3 size phase 1's intermediate at a few times the target;
// these bound it from below and by the budget, and say when to retry it finer.
//
// Phase 1 hands on no fewer triangles than this: coarser, clustering folds the sheets
// of steep or thin parts over one another, and the collapse gets stuck in the tangles.
constexpr double kLeastIntermediate = 65536;
// --mem bounds phase 1; phase 2 holds the intermediate whole, on top. Phase 1's output
// with its quadrics takes about 90 bytes per triangle it hands on, and floating hands
// on up to 1.6x the triangles asked for: this many bytes per triangle asked keeps it
// inside, so a smaller budget gets a smaller k, down to the target itself.
constexpr double kPhase1BytesPerIntermediateTriangle = 192;
// A phase 1 that falls short of the target, or whose collapse gets stuck, runs again
// this many times finer (a grid twice as fine leaves about four times the triangles
// on a surface)...
constexpr double kFinerStep = 4;
// ... this many times at most; after that the whole input collapses if it fits.
constexpr int kFinerRetries = 2;
// A phase 1 that would keep this share of the input or more saves phase 2 little and
// costs a pass of its own: the whole input collapses instead, when it fits the budget.
constexpr double kWholeInsteadShare = 0.75;

// Triangles per read of the input when it is loaded whole.
constexpr std::size_t kLoadChunkTriangles = 65536;

}  // namespace

std::uint64_t resolve_target(const TargetOptions& t, std::uint64_t input_triangles) {
  if (t.triangles) return t.triangles;
  if (t.ratio)
    return std::max<std::uint64_t>(kLeastTarget, std::uint64_t(std::llround(t.ratio * double(input_triangles))));
  return kLeastTarget;  // max_error alone: as far as the error allows
}

namespace {

// Whether the whole input fits in the budget for the collapse, next to what the run holds.
bool whole_fits(const MeshInput& input, const MemoryBudget& budget) {
  return budget.fits(budget.held(),
                     collapse_memory_bytes(input.positions.count, input.info.face_count, input.attributes.size()));
}

// The whole input, relative to `origin`, with its carried attributes, after a check
// that it fits in the budget next to what the run holds.
QuadricMesh load_whole(MeshInput& input, const RunPlan& plan, const Vec3d& origin, const char* why,
                       SimplifyStats* stats) {
  const std::size_t k = input.attributes.size();
  const MemoryBudget budget(plan.budget_bytes, plan.budget_counts_process);
  const std::uint64_t v = input.positions.count, f = input.info.face_count;
  budget.check(budget.held(), collapse_memory_bytes(v, f, k),
               "the whole mesh of " + input.info.path + " (" + std::to_string(v) + " vertices, " + std::to_string(f) +
                   " faces) " + why,
               "give options.memory_budget " + whole_mib(budget.held() + collapse_memory_bytes(v, f, k)) +
                   " MiB or more, or a clustering method with the target");
  ProgressPhase phase(plan.progress, "load mesh", input.file_size, "B");
  QuadricMesh m;
  resize_filled(&m.positions, v);
  for (std::uint64_t i = 0; i < v; ++i) m.positions[i] = input.positions.get(i) - origin;
  if (!plan.locked_vertices.empty()) {
    m.locked.assign(v, 0);
    for (std::uint64_t i : plan.locked_vertices) m.locked[i] = 1;  // below v: checked at the start
  }
  m.attribute_count = k;
  resize_filled(&m.attributes, v * k);
  for (std::uint64_t i = 0; i < v; ++i)
    for (std::size_t j = 0; j < k; ++j) m.attributes[i * k + j] = attribute_value(input.attributes, i, j);
  input.restart_triangles();
  std::vector<std::uint64_t> chunk;
  resize_filled(&chunk, 3 * kLoadChunkTriangles);
  reserve_filled(&m.triangles, 3 * f);  // every face but those the stream skips
  while (std::size_t n = input.triangles->read(chunk.data(), kLoadChunkTriangles)) {
    for (std::size_t i = 0; i < 3 * n; ++i) m.triangles.push_back(std::uint32_t(chunk[i]));
    phase.set(input.triangles->bytes_consumed());
  }
  if (stats) {
    stats->input_triangles = m.triangles.size() / 3;
    stats->skipped = input.triangles->skipped();
  }
  return m;
}

// Where the input has each locked place (`locked`, sorted), found by its position
// relative to `origin` as the collapse holds it: p - origin + origin can differ from p
// in the last bit of a double, and a locked vertex stays where the input has it.
class LockedPlaces {
 public:
  LockedPlaces(const std::vector<std::array<double, 3>>& locked, const Vec3d& origin) {
    for (const std::array<double, 3>& a : locked) {
      const Vec3d r = Vec3d{a[0], a[1], a[2]} - origin;
      relative_.push_back({{r.x, r.y, r.z}, a});
    }
    std::sort(relative_.begin(), relative_.end());
  }
  /// The model position of `p`, relative to the origin: the input's where p is locked.
  Vec3d model(const Vec3d& p, const Vec3d& origin) const {
    if (!relative_.empty()) {
      const std::array<double, 3> key{p.x, p.y, p.z};
      const auto at = std::lower_bound(relative_.begin(), relative_.end(), key,
                                       [](const auto& e, const std::array<double, 3>& k) { return e.first < k; });
      if (at != relative_.end() && at->first == key) return {at->second[0], at->second[1], at->second[2]};
    }
    return p + origin;
  }

 private:
  std::vector<std::pair<std::array<double, 3>, std::array<double, 3>>> relative_;
};

// The collapse's result in model units, attributes as their types hold them; the
// locked places (sorted) where the input has them.
SimplifiedMesh to_output(const QuadricMesh& m, const Vec3d& origin, const std::vector<VertexAttribute>& attributes,
                         const std::vector<std::array<double, 3>>& locked) {
  SimplifiedMesh out;
  out.positions.reserve(3 * m.positions.size());
  const LockedPlaces places(locked, origin);
  for (const Vec3d& p : m.positions) {
    const Vec3d x = places.model(p, origin);
    out.positions.insert(out.positions.end(), {x.x, x.y, x.z});
  }
  out.triangles = m.triangles;
  out.attributes.attributes = attributes;
  out.attributes.values = m.attributes;
  if (!attributes.empty()) {
    AttributeArray described;
    described.attributes = attributes;
    const AttributeLayout layout(described);
    for (std::size_t i = 0; i < m.positions.size(); ++i) layout.settle(&out.attributes.values[i * attributes.size()]);
  }
  out.precision = ScalarType::f64;
  return out;
}

// A mesh for phase 2: positions relative to `origin`, and the attributes its vertices
// carry (their values in the mesh).
struct CollapseInput {
  QuadricMesh mesh;
  Vec3d origin;
  const std::vector<VertexAttribute>* attributes = nullptr;
  /// The quadrics hold the boundary planes already (the out-of-core passes added them).
  bool boundary_planes_in_quadrics = false;
  /// The input's positions of the locked vertices, sorted (locked_positions).
  std::vector<std::array<double, 3>> locked;
};

// What phase 2 is asked for.
struct CollapseGoal {
  std::uint64_t target = 0;
  bool last = true;  // no finer phase 1 follows: a missed count is warned of
  /// When set, the output vertices' quadrics go there, in model units.
  std::vector<Quadric>* quadrics = nullptr;
  /// When set, the collapse goes on to each of these levels' targets in turn.
  std::vector<CoarserLevel>* coarser = nullptr;
};

struct CollapseResult {
  SimplifiedMesh mesh;
  // A finer phase 1 could meet a missed target: not when the surface is closed and
  // one triangle is left over, as it would be there too.
  bool finer_may_help = false;
};

// Why a stuck collapse took no more: what its edges left would do (CollapseStats::
// why_stuck), the commonest first, and the boundary loops it kept open.
std::string stuck_reason(const CollapseStats::StuckEdges& w) {
  std::vector<std::pair<std::uint64_t, std::string>> parts = {
      {w.folds, "would flip a face or leave a needle"},
      {w.topology, "would break the link condition (the surface would stop being manifold, or pinch)"},
      {w.locked, "have a locked end"},
      {w.overshoot, "would take it below the target by more than edge splits make up"}};
  std::stable_sort(parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string why = "no valid collapse was left: ";
  bool first = true;
  for (const auto& p : parts) {
    if (p.first == 0) continue;
    if (first)
      why += p.first == w.edges
                 ? "all " + std::to_string(w.edges) + " edges left " + p.second
                 : "of the " + std::to_string(w.edges) + " edges left, " + std::to_string(p.first) + " " + p.second;
    else
      why += ", " + std::to_string(p.first) + " " + p.second;
    first = false;
  }
  if (first) why += "no edge is left";
  if (w.loops_of_three)
    why += "; " + std::to_string(w.loops_of_three) + " of the " + std::to_string(w.loops) +
           " boundary loops left are down to three edges and stay open (closing one would fold a disc shut, leave "
           "the surface non-manifold or move a locked vertex)";
  else if (w.loops)
    why += "; " + std::to_string(w.loops) + (w.loops == 1 ? " boundary loop is left" : " boundary loops are left");
  return why;
}

// The collapse's figures in `stats`, and whether it missed the target; the warning
// of a missed count when no finer phase 1 follows or none could help. Returns
// CollapseResult::finer_may_help.
bool note_collapse(const CollapseStats& cs, std::uint64_t left, const CollapseGoal& goal, const RunPlan& plan,
                   SimplifyStats* stats) {
  stats->refine.collapses = cs.collapses;
  stats->refine.largest_collapse_cost = cs.largest_cost;
  stats->refine.largest_collapse_error = cs.largest_error;
  // max_error alone asks for no count: stopping at it is the aim, not a miss.
  const bool count_asked = asks_count(plan);
  stats->refine.target_missed = left != goal.target && (count_asked || !cs.stopped_by_error);
  if (stats->refine.target_missed && count_asked && (goal.last || cs.parity)) {
    std::string why = cs.parity             ? "the surface is closed, so its triangle count is even"
                      : cs.stopped_by_error ? "the next collapse's error was above the maximum error"
                                            : stuck_reason(cs.why_stuck);
    stats->warnings.push_back("the target of " + std::to_string(goal.target) +
                              " triangles was not met: " + std::to_string(left) + " triangles (" + why + ")");
  }
  return stats->refine.target_missed && !cs.parity;
}

// Phase 2 (Garland & Shaffer 2002 §3): quadric edge collapse of `in`, held whole, down
// to the target; fills the collapse's stats and the phase "refine". With
// goal.coarser, the collapse then goes on to each coarser level, whose stats are
// `stats` as they were before phase 2 with that level's collapse and output, and as
// its only phase "refine", the time since the finer level.
CollapseResult refine(CollapseInput in, const CollapseGoal& goal, const RunPlan& plan, SimplifyStats* stats) {
  PhaseTimer clock;
  const PeakAnonSampler memory;
  QuadricMesh& m = in.mesh;
  stats->refine.intermediate_triangles = m.triangles.size() / 3;
  const SimplifyStats before = *stats;
  if (m.quadrics.size() != m.positions.size()) m.quadrics = face_quadrics(m.positions, m.triangles);
  CollapseSettings settings;
  settings.target_triangles = goal.target;
  if (plan.target.max_error > 0) settings.max_error = plan.target.max_error;
  if (in.boundary_planes_in_quadrics) settings.boundary_weight = 0;
  // --max-error alone asks for no count: its target (the least) says nothing of which
  // holes the output can show.
  settings.soften_holes = asks_count(plan);
  settings.result_quadrics = goal.quadrics != nullptr;  // the output's
  settings.lock_boundary = plan.lock_boundary;
  settings.lock_coincident = carries_texture_coordinates(*in.attributes);
  // Each coarser level's count, from the input's triangles as the run's own (never
  // above the finer level's).
  std::vector<std::uint64_t> coarser;
  if (goal.coarser)
    for (const CoarserLevel& level : *goal.coarser)
      coarser.push_back(std::min(resolve_target(level.target, stats->input_triangles),
                                 coarser.empty() ? goal.target : coarser.back()));
  const std::uint64_t last_target = coarser.empty() ? goal.target : coarser.back();
  CollapseResult out;
  CollapseStats cs;
  ProgressPhase phase(
      plan.progress, "collapse",
      stats->refine.intermediate_triangles - std::min(stats->refine.intermediate_triangles, last_target), "tri");
  // A coarser level that missed its count where a finer phase 1 could meet it is left
  // to a run of its own, and so are the levels after it.
  bool going_on = true;
  collapse_edges_to_levels(
      std::move(m), settings, coarser, &cs,
      [&](std::size_t k, QuadricMesh done, const CollapseStats& so_far) {
        SimplifyStats* st = stats;
        if (k > 0) {
          CoarserLevel& level = (*goal.coarser)[k - 1];
          level.done = false;
          if (!going_on) return;
          level.stats = before;
          level.stats.phases.clear();  // the finer level's: this one adds its collapse only
          st = &level.stats;
        }
        const std::uint64_t target = k > 0 ? coarser[k - 1] : goal.target;
        const bool missed = note_collapse(so_far, done.triangles.size() / 3, {target, goal.last}, plan, st);
        if (k > 0 && missed && !goal.last) {
          going_on = false;
          return;
        }
        if (k > 0) (*goal.coarser)[k - 1].done = true;
        SimplifiedMesh mesh = to_output(done, in.origin, *in.attributes, in.locked);
        if (k == 0) {
          out.finer_may_help = missed;
          if (goal.quadrics) {
            *goal.quadrics = std::move(done.quadrics);
            for (Quadric& q : *goal.quadrics) q = q.translated(in.origin);
          }
        }
        st->output_vertices = mesh.positions.size() / 3;
        st->output_triangles = mesh.triangles.size() / 3;
        clock.end("refine");
        clock.move_to(&st->phases);
        st->refine.phase2_peak_anon_bytes = memory.peak();
        (k > 0 ? (*goal.coarser)[k - 1].mesh : out.mesh) = std::move(mesh);
      },
      &phase);
  return out;
}

// The input as it is, for a target at or above its triangle count.
SimplifiedMesh input_as_is(MeshInput& input, const RunPlan& plan, std::uint64_t target, SimplifyStats* stats) {
  const Vec3d origin;  // no shift: the positions come back exactly
  QuadricMesh m = load_whole(input, plan, origin, "to give back", stats);
  // Only the vertices a triangle uses, numbered by first use, as the collapse does.
  CollapseSettings keep_all;
  keep_all.target_triangles = m.triangles.size() / 3;
  QuadricMesh used = collapse_edges(std::move(m), keep_all, nullptr);
  stats->refine.intermediate_triangles = stats->input_triangles;
  stats->warnings.push_back(input.info.path + ": the target of " + std::to_string(target) +
                            " triangles is at or above the input's " + std::to_string(stats->input_triangles) +
                            ": its own triangles are given back");
  SimplifiedMesh out = to_output(used, origin, input.attributes.attributes, {});
  stats->output_vertices = out.positions.size() / 3;
  stats->output_triangles = out.triangles.size() / 3;
  return out;
}

// Phase 2 alone, on the whole input: --method qem, and a target so near the input's
// count that phase 1 would keep nearly everything.
SimplifiedMesh collapse_whole(MeshInput& input, const RunPlan& plan, const Vec3d& origin, SimplifyStats* stats,
                              std::vector<Quadric>* quadrics, std::vector<CoarserLevel>* coarser) {
  PhaseTimer clock;
  stats->cell_size = 0;  // no grid
  for (std::uint32_t& d : stats->grid_dims) d = 0;
  QuadricMesh whole = load_whole(input, plan, origin, "for quadric edge collapse", stats);
  clock.end("load");
  clock.move_to(&stats->phases);
  const std::uint64_t target = resolve_target(plan.target, stats->input_triangles);
  {
    ProgressPhase phase(plan.progress, "face quadrics", 0, "tri");
    whole.quadrics = face_quadrics(whole.positions, whole.triangles);
  }
  return refine({std::move(whole), origin, &input.attributes.attributes, false,
                 locked_positions(input.positions, plan.locked_vertices)},
                {target, true, quadrics, coarser}, plan, stats)
      .mesh;
}

// --method qem: the collapse whole, or out of core in passes (methods/qem_passes)
// down to a few times the target, then whole.
// With `parts`, the parts of a distributed run did the passes' first.
SimplifiedMesh collapse_qem(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t estimate,
                            SimplifyStats* stats, const FirstPassParts* parts = nullptr,
                            std::vector<Quadric>* quadrics = nullptr, std::vector<CoarserLevel>* coarser = nullptr) {
  if (!collapses_in_passes(input.info.face_count, estimate))
    return collapse_whole(input, plan, origin, stats, quadrics, coarser);
  stats->cell_size = 0;  // no grid
  for (std::uint32_t& d : stats->grid_dims) d = 0;
  CollapseInput rest;
  {
    const PeakAnonSampler memory;
    rest.mesh = parts ? reduce_after_first_pass(input, plan, origin, estimate, parts->plan, parts->tiles, stats)
                      : reduce_in_passes(input, plan, origin, estimate, stats);
    stats->refine.phase1_peak_anon_bytes = memory.peak();
  }
  const std::uint64_t pass_collapses = stats->refine.collapses;
  const double pass_error = stats->refine.largest_collapse_error;
  rest.origin = origin;
  rest.attributes = &input.attributes.attributes;
  rest.boundary_planes_in_quadrics = true;
  rest.locked = locked_positions(input.positions, plan.locked_vertices);
  const std::uint64_t target = resolve_target(plan.target, stats->input_triangles);
  SimplifiedMesh out = refine(std::move(rest), {target, true, quadrics, coarser}, plan, stats).mesh;
  stats->refine.collapses += pass_collapses;
  stats->refine.largest_collapse_error = std::max(stats->refine.largest_collapse_error, pass_error);
  if (coarser)
    for (CoarserLevel& level : *coarser) {
      level.stats.refine.collapses += pass_collapses;
      level.stats.refine.largest_collapse_error = std::max(level.stats.refine.largest_collapse_error, pass_error);
    }
  return out;
}

// How large phase 1's intermediate is on each attempt, and when the whole input
// collapses instead.
class IntermediatePlan {
 public:
  IntermediatePlan(const MeshInput& input, const RunPlan& plan, std::uint64_t estimate)
      : k_(plan.target.intermediate_factor), estimate_(double(estimate)), faces_(double(input.info.face_count)) {
    const MemoryBudget budget(plan.budget_bytes, plan.budget_counts_process);
    budget_intermediate_ = budget.bytes() ? double(budget.bytes()) / kPhase1BytesPerIntermediateTriangle
                                          : std::numeric_limits<double>::infinity();
    whole_possible_ = whole_fits(input, budget);
  }
  /// The triangles phase 1 aims at on attempt `attempt` (0 first): k times the target
  /// as far as the budget allows, at least the target and kLeastIntermediate, and
  /// kFinerStep times more on each retry.
  double intermediate(int attempt) const {
    const double finer = std::pow(kFinerStep, attempt);
    return std::max({std::min(k_ * estimate_, budget_intermediate_), estimate_, kLeastIntermediate}) * finer;
  }
  /// Whether the whole input collapses instead of a phase 1 of `want` triangles: it
  /// would keep the input, or most of it where the whole fits, or the finest phase 1
  /// has missed the target.
  bool whole_instead(double want, int attempt) const {
    return want >= faces_ || (want >= kWholeInsteadShare * faces_ && whole_possible_) || attempt > kFinerRetries;
  }
  /// Whether attempt `attempt` is the last phase 1: its collapse is taken as it is.
  bool finest(int attempt) const { return attempt == kFinerRetries && !whole_possible_; }

 private:
  double k_, estimate_, faces_;
  double budget_intermediate_ = 0;
  bool whole_possible_ = false;
};

// Phase 1's result: the clustered mesh at `grid` and, for phase 2, each output
// vertex's summed cluster quadric, relative to grid.origin.
struct Intermediate {
  GridSpec grid;
  SimplifiedMesh mesh;
  std::vector<Quadric> quadrics;
};

// The grid phase 1 clusters at for about `want` triangles: the cell the vertex sample
// gives for that share of the input's.
GridSpec phase_grid(MeshInput& input, const RunPlan& plan, double want) {
  CellSizing sizing;
  sizing.ratio = want / double(std::max<std::uint64_t>(input.info.face_count, 1));
  return choose_grid(input, sizing, plan.threads);
}

// Where phase 1's first attempt comes from in a merge: the parts' clustering at their
// grid.
struct PartsPhaseOne {
  const GridSpec* grid = nullptr;
  const MergedPhaseOne* merged = nullptr;
  bool any_grid = false;  ///< the parts' work serves every attempt, at any grid
};

bool same_grid(const GridSpec& a, const GridSpec& b) {
  return a.origin.x == b.origin.x && a.origin.y == b.origin.y && a.origin.z == b.origin.z && a.cell == b.cell &&
         a.dims[0] == b.dims[0] && a.dims[1] == b.dims[1] && a.dims[2] == b.dims[2];
}

// Phase 1 (Garland & Shaffer 2002 §3): the clustering method at the cell the vertex
// sample gives for about `want` triangles; with `with_quadrics`, handing on each
// cluster's quadric.
Intermediate cluster_phase(MeshInput& input, const RunPlan& plan, double want, bool with_quadrics, SimplifyStats* stats,
                           const PartsPhaseOne* parts = nullptr) {
  const ClusterMethodEntry& method = cluster_method(plan.method);
  Intermediate out;
  out.grid = phase_grid(input, plan, want);
  stats->cell_size = out.grid.cell;
  for (int a = 0; a < 3; ++a) stats->grid_dims[a] = out.grid.dims[a];
  input.restart_triangles();
  const PeakAnonSampler phase1_memory;
  std::vector<Quadric>* quadrics = with_quadrics ? &out.quadrics : nullptr;
  if (parts && (parts->any_grid || same_grid(*parts->grid, out.grid))) {
    out.mesh = (*parts->merged)(out.grid, stats, quadrics).take();
  } else {
    if (parts)
      stats->warnings.push_back(
          "the parts clustered phase 1 at another cell than this merge chooses (another --mem?): phase 1 ran again "
          "in the merge");
    out.mesh = method.run(input, plan, out.grid, stats, quadrics).take();
  }
  stats->refine.phase1_peak_anon_bytes = phase1_memory.peak();
  return out;
}

// Phase 1's output as phase 2's input, relative to the grid's origin, with the
// clusters' summed quadrics, so that no error information is lost between the phases
// (Garland & Shaffer 2002 §3). The positions are copied (and freed), the rest moves;
// the attributes' description stays in `p1`. The vertices at one of `locked`
// (sorted) are locked in the collapse: phase 1 kept each locked vertex where the
// input has it, to the last bit.
CollapseInput collapse_input(Intermediate* p1, const std::vector<std::array<double, 3>>& locked) {
  SimplifiedMesh& m = p1->mesh;
  CollapseInput in;
  QuadricMesh& q = in.mesh;
  const std::uint64_t got = m.triangles.size() / 3;
  q.positions.resize(got ? m.positions.size() / 3 : 0);
  for (std::size_t i = 0; i < q.positions.size(); ++i)
    q.positions[i] = Vec3d{m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]} - p1->grid.origin;
  if (!locked.empty()) {
    q.locked.assign(q.positions.size(), 0);
    for (std::size_t i = 0; i < q.positions.size(); ++i)
      q.locked[i] =
          std::binary_search(locked.begin(), locked.end(),
                             std::array<double, 3>{m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]});
  }
  std::vector<double>().swap(m.positions);  // copied: not held through phase 2
  q.triangles = std::move(m.triangles);
  q.quadrics = std::move(p1->quadrics);
  q.attribute_count = m.attributes.attributes.size();
  q.attributes = std::move(m.attributes.values);
  in.origin = p1->grid.origin;
  in.attributes = &m.attributes.attributes;
  in.locked = locked;
  return in;
}

// Garland & Shaffer 2002 §3: phase 1 clusters out of core to an intermediate of about
// k times the target, phase 2 collapses it in core to the target. When phase 1 falls
// short of the target or the collapse gets stuck, phase 1 runs again finer (not for a
// closed surface one triangle short: its count is even at any cell); only the last
// attempt's phases and warnings stay in the stats.
// With `parts`, the first attempt's phase 1 comes from the parts of a distributed run.
SimplifiedMesh multiphase(MeshInput& input, const RunPlan& plan, const Vec3d& origin, std::uint64_t estimate,
                          SimplifyStats* stats, const PartsPhaseOne* parts = nullptr,
                          std::vector<Quadric>* quadrics = nullptr, std::vector<CoarserLevel>* coarser = nullptr) {
  const IntermediatePlan intermediates(input, plan, estimate);
  const std::vector<std::array<double, 3>> locked = locked_positions(input.positions, plan.locked_vertices);
  const std::size_t phases_before = stats->phases.size(), warnings_before = stats->warnings.size();
  for (int attempt = 0;; ++attempt) {
    const double want = intermediates.intermediate(attempt);
    stats->phases.resize(phases_before);
    stats->warnings.resize(warnings_before);
    if (coarser)
      for (CoarserLevel& level : *coarser) level.done = false;  // an earlier attempt's go

    if (intermediates.whole_instead(want, attempt)) {
      stats->refine.phase1_peak_anon_bytes = 0;
      // The method asked for did not run: say so, and why.
      stats->warnings.push_back(std::string("options.method ") + method_name(plan.method) +
                                ": no clustering ran; the whole input (" + std::to_string(input.info.face_count) +
                                " triangles) was collapsed instead, since " +
                                (attempt > 0 ? "clustering finer still missed the target"
                                             : "clustering to the " + std::to_string(std::uint64_t(want)) +
                                                   " triangles phase 1 aims at would keep most of it"));
      return collapse_whole(input, plan, origin, stats, quadrics, coarser);
    }
    const bool finest = intermediates.finest(attempt);
    const bool from_parts = parts && (attempt == 0 || parts->any_grid);
    Intermediate p1 = cluster_phase(input, plan, want, true, stats, from_parts ? parts : nullptr);
    const std::uint64_t target = resolve_target(plan.target, stats->input_triangles);
    if (plan.target.max_error == 0 && target >= stats->input_triangles) return input_as_is(input, plan, target, stats);
    if (p1.mesh.triangles.size() / 3 < target && !finest) continue;  // too coarse: finer
    CollapseResult out = refine(collapse_input(&p1, locked), {target, finest, quadrics, coarser}, plan, stats);
    if (!out.finer_may_help || finest) return std::move(out.mesh);
  }
}

}  // namespace

namespace {

// What a run to a target settles first: its frame and its count.
struct TargetRun {
  Vec3d origin;
  std::uint64_t estimate = 0;
  /// The input is given back as it is.
  bool as_is = false;
};

TargetRun prepare_target(const MeshInput& input, const RunPlan& plan) {
  TargetRun run;
  const std::uint64_t faces = input.info.face_count;
  run.origin = input.info.bounds.empty() ? Vec3d{} : input.info.bounds.min;
  run.estimate = resolve_target(plan.target, faces);
  run.as_is = plan.target.max_error == 0 && run.estimate >= faces;
  return run;
}

}  // namespace

SimplifiedMesh simplify_to_target(MeshInput& input, const RunPlan& plan, SimplifyStats* stats,
                                  std::vector<Quadric>* quadrics, std::vector<CoarserLevel>* coarser) {
  if (quadrics) quadrics->clear();
  if (coarser)
    for (CoarserLevel& level : *coarser) level.done = false;
  const TargetRun run = prepare_target(input, plan);
  if (run.as_is) return input_as_is(input, plan, run.estimate, stats);
  if (plan.method == ClusterMethod::qem)
    return collapse_qem(input, plan, run.origin, run.estimate, stats, nullptr, quadrics, coarser);
  // --refine none: phase 1 alone, at the cell for about the target itself.
  if (plan.target.refine != RefineMethod::qem)
    return cluster_phase(input, plan, double(run.estimate), false, stats).mesh;
  return multiphase(input, plan, run.origin, run.estimate, stats, nullptr, quadrics, coarser);
}

bool target_clustering_grid(MeshInput& input, const RunPlan& plan, GridSpec* grid) {
  const TargetRun run = prepare_target(input, plan);
  if (run.as_is || plan.method == ClusterMethod::qem) return false;
  double want = double(run.estimate);  // --refine none: phase 1 alone, at about the target
  if (plan.target.refine == RefineMethod::qem) {
    const IntermediatePlan intermediates(input, plan, run.estimate);
    want = intermediates.intermediate(0);
    if (intermediates.whole_instead(want, 0)) return false;
  }
  *grid = phase_grid(input, plan, want);
  return true;
}

SimplifiedMesh simplify_to_target_after_clustering(MeshInput& input, const RunPlan& plan, const GridSpec& parts_grid,
                                                   const MergedPhaseOne& merged, bool any_grid, SimplifyStats* stats) {
  const TargetRun run = prepare_target(input, plan);
  if (run.as_is) return input_as_is(input, plan, run.estimate, stats);
  const PartsPhaseOne parts{&parts_grid, &merged, any_grid};
  if (plan.target.refine != RefineMethod::qem)
    return cluster_phase(input, plan, double(run.estimate), false, stats, &parts).mesh;
  return multiphase(input, plan, run.origin, run.estimate, stats, &parts);
}

bool simplify_to_target_part(MeshInput& input, const RunPlan& plan, std::uint32_t part, std::uint32_t parts,
                             const TileOutputSink& out, FirstPassPlan* first_pass) {
  const TargetRun run = prepare_target(input, plan);
  if (run.as_is || plan.method != ClusterMethod::qem || !collapses_in_passes(input.info.face_count, run.estimate))
    return false;
  *first_pass = first_pass_part(input, plan, run.origin, run.estimate, part, parts, out);
  return true;
}

SimplifiedMesh simplify_to_target_after_parts(MeshInput& input, const RunPlan& plan, const FirstPassParts& parts,
                                              SimplifyStats* stats) {
  const TargetRun run = prepare_target(input, plan);
  if (run.as_is || plan.method != ClusterMethod::qem || !collapses_in_passes(input.info.face_count, run.estimate))
    throw std::logic_error("simplify_to_target_after_parts: the run has no passes");
  return collapse_qem(input, plan, run.origin, run.estimate, stats, &parts);
}

}  // namespace oocsimp
