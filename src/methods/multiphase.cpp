// Exact targets: phase 1 clusters out of core to an intermediate of about k times the
// target, carrying each cluster's summed quadric; phase 2 collapses edges in core
// from those quadrics down to the target, so that no error information is lost
// between the phases (Garland & Shaffer 2002). --method qem is phase 2 alone on the
// whole input.
#include "methods/multiphase.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cluster/attribute_sums.hpp"
#include "common/huge_pages.hpp"
#include "common/memory_budget.hpp"
#include "common/phase_timer.hpp"
#include "common/vec3_math.hpp"
#include "methods/cluster_methods.hpp"
#include "oocsimp/error.hpp"
#include "refine/edge_collapse.hpp"
#include "report/memory_usage.hpp"
#include "report/progress_phase.hpp"

namespace oocsimp {

namespace {

// What holding a whole mesh for the collapse takes: per vertex its position, quadric,
// flags and face list (3 entries per face); per face its corners, input normal and a
// few queue entries.
constexpr std::uint64_t kCollapseBytesPerVertex = sizeof(Vec3d) + sizeof(Quadric) + 16;
constexpr std::uint64_t kCollapseBytesPerTriangle = 12 + sizeof(Vec3d) + 3 * 4 * 3 + 4 * 16;

std::uint64_t collapse_bytes(std::uint64_t vertices, std::uint64_t triangles, std::size_t attributes) {
  return vertices * (kCollapseBytesPerVertex + 8 * attributes) + triangles * kCollapseBytesPerTriangle;
}

std::uint64_t resolve_target(const TargetOptions& t, std::uint64_t input_triangles) {
  if (t.triangles) return t.triangles;
  if (t.ratio) return std::max<std::uint64_t>(4, std::uint64_t(std::llround(t.ratio * double(input_triangles))));
  return 4;  // max_error alone: as far as the error allows
}

// Whether the whole input fits in the budget for the collapse, next to what the run holds.
bool whole_fits(const MeshInput& input, const MemoryBudget& budget) {
  return budget.fits(budget.held(),
                     collapse_bytes(input.positions.count, input.info.face_count, input.attributes.size()));
}

// The whole input, relative to `origin`, with its carried attributes, after a check
// that it fits in the budget next to what the run holds.
QuadricMesh load_whole(MeshInput& input, const SimplifyOptions& options, const Vec3d& origin, const char* why,
                       SimplifyStats* stats) {
  const std::size_t k = input.attributes.size();
  const MemoryBudget budget(options);
  const std::uint64_t v = input.positions.count, f = input.info.face_count;
  budget.check(budget.held(), collapse_bytes(v, f, k),
               "the whole mesh of " + input.info.path + " (" + std::to_string(v) + " vertices, " + std::to_string(f) +
                   " faces) " + why,
               "give options.memory_budget " + whole_mib(budget.held() + collapse_bytes(v, f, k)) +
                   " MiB or more, or a clustering method with the target");
  ProgressPhase phase(options.progress, "load mesh", input.file_size, "B");
  QuadricMesh m;
  reserve_huge(&m.positions, v);
  m.positions.resize(v);
  for (std::uint64_t i = 0; i < v; ++i) m.positions[i] = input.positions.get(i) - origin;
  m.attribute_count = k;
  m.attributes.resize(v * k);
  for (std::uint64_t i = 0; i < v; ++i)
    for (std::size_t j = 0; j < k; ++j) m.attributes[i * k + j] = input.attributes.get(i, j);
  input.restart_triangles();
  std::vector<std::uint64_t> chunk(3 * 65536);
  reserve_huge(&m.triangles, 3 * f);
  while (std::size_t n = input.triangles->read(chunk.data(), 65536)) {
    for (std::size_t i = 0; i < 3 * n; ++i) m.triangles.push_back(std::uint32_t(chunk[i]));
    phase.set(input.triangles->bytes_consumed());
  }
  if (stats) {
    stats->input_triangles = m.triangles.size() / 3;
    stats->skipped = input.triangles->skipped();
  }
  return m;
}

// The collapse's result in model units, attributes as their types hold them.
SimplifiedMesh to_output(const QuadricMesh& m, const Vec3d& origin, const std::vector<VertexAttribute>& attributes) {
  SimplifiedMesh out;
  out.positions.reserve(3 * m.positions.size());
  for (const Vec3d& p : m.positions) {
    const Vec3d x = p + origin;
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

// Phase 2 on `m` down to the target; fills the collapse's stats and, when `last` (no
// finer phase 1 to try) or a finer one could not help, the warning of a missed target.
// *finer_may_help says whether a finer phase 1 could meet a missed target: not when
// the surface is closed and one triangle is left over, as it would be there too.
SimplifiedMesh refine(QuadricMesh m, const Vec3d& origin, const std::vector<VertexAttribute>& attributes,
                      std::uint64_t target, const SimplifyOptions& options, SimplifyStats* stats, bool last = true,
                      bool* finer_may_help = nullptr) {
  PhaseTimer clock;
  const PeakAnonSampler memory;
  stats->intermediate_triangles = m.triangles.size() / 3;
  if (m.quadrics.size() != m.positions.size()) m.quadrics = face_quadrics(m.positions, m.triangles);
  CollapseSettings settings;
  settings.target_triangles = target;
  if (options.target.max_error > 0) settings.max_error = options.target.max_error;
  CollapseStats cs;
  QuadricMesh done;
  {
    ProgressPhase phase(options.progress, "collapse",
                        stats->intermediate_triangles - std::min(stats->intermediate_triangles, target), "tri");
    done = collapse_edges(std::move(m), settings, &cs, &phase);
  }
  stats->collapses = cs.collapses;
  stats->largest_collapse_cost = cs.largest_cost;
  stats->largest_collapse_error = cs.largest_error;
  const std::uint64_t left = done.triangles.size() / 3;
  // max_error alone asks for no count: stopping at it is the aim, not a miss.
  const bool count_asked =
      options.target.triangles != 0 || options.target.ratio != 0 || options.method == ClusterMethod::qem;
  stats->target_missed = left != target && (count_asked || !cs.stopped_by_error);
  if (finer_may_help) *finer_may_help = stats->target_missed && !cs.parity;
  if (stats->target_missed && count_asked && (last || cs.parity)) {
    std::string why = cs.parity ? "the surface is closed, so its triangle count is even"
                      : cs.stopped_by_error
                          ? "the next collapse's error was above the maximum error"
                          : "no valid collapse was left (each would break the surface or flip a face)";
    stats->warnings.push_back("the target of " + std::to_string(target) +
                              " triangles was not met: " + std::to_string(left) + " triangles (" + why + ")");
  }
  SimplifiedMesh out = to_output(done, origin, attributes);
  stats->output_vertices = out.positions.size() / 3;
  stats->output_triangles = out.triangles.size() / 3;
  clock.end("refine");
  clock.move_to(&stats->phases);
  stats->phase2_peak_anon_bytes = memory.peak();
  return out;
}

// The input as it is, for a target at or above its triangle count.
SimplifiedMesh input_as_is(MeshInput& input, const SimplifyOptions& options, std::uint64_t target,
                           SimplifyStats* stats) {
  const Vec3d origin;  // no shift: the positions come back exactly
  QuadricMesh m = load_whole(input, options, origin, "to give back", stats);
  // Only the vertices a triangle uses, numbered by first use, as the collapse does.
  CollapseSettings keep_all;
  keep_all.target_triangles = m.triangles.size() / 3;
  QuadricMesh used = collapse_edges(std::move(m), keep_all, nullptr);
  stats->intermediate_triangles = stats->input_triangles;
  stats->warnings.push_back(input.info.path + ": the target of " + std::to_string(target) +
                            " triangles is at or above the input's " + std::to_string(stats->input_triangles) +
                            ": its own triangles are given back");
  SimplifiedMesh out = to_output(used, origin, input.attributes.attributes);
  stats->output_vertices = out.positions.size() / 3;
  stats->output_triangles = out.triangles.size() / 3;
  return out;
}

// Phase 2 alone, on the whole input: --method qem, and a target so near the input's
// count that phase 1 would keep nearly everything.
SimplifiedMesh collapse_whole(MeshInput& input, const SimplifyOptions& o, const Vec3d& origin, SimplifyStats* stats) {
  PhaseTimer clock;
  stats->cell_size = 0;  // no grid
  for (std::uint32_t& d : stats->grid_dims) d = 0;
  QuadricMesh whole = load_whole(input, o, origin, "for quadric edge collapse", stats);
  clock.end("load");
  clock.move_to(&stats->phases);
  const std::uint64_t target = resolve_target(o.target, stats->input_triangles);
  whole.quadrics = face_quadrics(whole.positions, whole.triangles);
  return refine(std::move(whole), origin, input.attributes.attributes, target, o, stats);
}

}  // namespace

void check_target_options(const SimplifyOptions& o) {
  const TargetOptions& t = o.target;
  if (t.triangles != 0 && t.ratio != 0)
    throw UsageError("give at most one of options.target.triangles and options.target.ratio");
  const CellSizing& s = o.sizing;
  if (t.given() && (s.cell != 0 || s.grid != 0 || s.ratio != 0))
    throw UsageError(
        "a target (options.target.triangles, options.target.ratio, options.target.max_error) sets the cell itself: "
        "give no options.sizing.cell, options.sizing.grid or options.sizing.ratio with it");
  if (o.method == ClusterMethod::qem && (s.cell != 0 || s.grid != 0 || s.ratio != 0))
    throw UsageError(
        "options.sizing.cell, options.sizing.grid and options.sizing.ratio apply to the clustering methods; the qem "
        "method takes options.target.triangles, options.target.ratio or options.target.max_error");
  if (t.triangles != 0 && t.triangles < 4) throw UsageError("options.target.triangles must be at least 4");
  if (t.ratio != 0 && !(t.ratio > 0 && t.ratio <= 1)) throw UsageError("options.target.ratio must be in (0, 1]");
  if (t.max_error != 0 && !(t.max_error > 0 && std::isfinite(t.max_error)))
    throw UsageError("options.target.max_error must be a positive number");
  if (!(t.intermediate_factor >= 1 && std::isfinite(t.intermediate_factor)))
    throw UsageError("options.target.intermediate_factor must be at least 1");
}

SimplifiedMesh simplify_to_target(MeshInput& input, const SimplifyOptions& options, SimplifyStats* stats) {
  check_target_options(options);
  SimplifyOptions o = options;
  // --method qem alone keeps the default share, now exactly.
  if (!o.target.given()) o.target.ratio = kDefaultRatio;
  const std::uint64_t faces = input.info.face_count;
  const Vec3d origin = input.info.bounds.empty() ? Vec3d{} : input.info.bounds.min;
  const std::uint64_t estimate = resolve_target(o.target, faces);
  if (o.target.max_error == 0 && estimate >= faces) return input_as_is(input, o, estimate, stats);

  const double k = o.target.intermediate_factor;
  if (o.method == ClusterMethod::qem) return collapse_whole(input, o, origin, stats);

  // Phase 1 at the cell the vertex sample gives for k times the target (or the target
  // itself without refinement), and for no fewer than kLeastIntermediate triangles:
  // coarser, clustering folds the sheets of steep or thin parts over one another
  // (a fifth of the edges of the 200k terrain clustered to 5k are non-manifold), and
  // the collapse gets stuck in the tangles. When it falls short of the target or gets
  // stuck all the same, phase 1 runs again four times finer, twice at most, and then
  // the whole input collapses if it fits the budget (not for a closed surface one
  // triangle short: its count is even at any cell).
  constexpr double kLeastIntermediate = 65536;
  // --mem bounds phase 1; phase 2 holds the intermediate whole, on top (about 180
  // bytes a triangle, measured). Phase 1's output with its quadrics takes about 90
  // bytes per triangle it hands on, and floating hands on up to 1.6x the triangles
  // asked for: kPhase1BytesPerIntermediateTriangle per triangle asked keeps it inside,
  // so a smaller budget gets a smaller k, down to the target itself.
  constexpr double kPhase1BytesPerIntermediateTriangle = 192;
  const MemoryBudget budget(o);
  const double budget_intermediate = budget.bytes() ? double(budget.bytes()) / kPhase1BytesPerIntermediateTriangle
                                                    : std::numeric_limits<double>::infinity();
  const ClusterMethodEntry& method = cluster_method(o.method);
  const std::size_t phases_before = stats->phases.size();
  const std::size_t warnings_before = stats->warnings.size();
  const bool whole_possible = whole_fits(input, budget);
  for (int attempt = 0;; ++attempt) {
    const bool refining = o.target.refine == RefineMethod::qem;
    const double finer = std::pow(4.0, attempt);
    const double want =
        refining
            ? std::max({std::min(k * double(estimate), budget_intermediate), double(estimate), kLeastIntermediate}) *
                  finer
            : double(estimate);
    stats->phases.resize(phases_before);  // only the last attempt's phases
    stats->warnings.resize(warnings_before);
    // A phase 1 that would keep three quarters of the input or more saves phase 2
    // little and costs a pass of its own; and when the finest phase 1 missed the
    // target, the whole input is the last resort: it collapses whole, when it fits
    // the budget.
    if (refining && (want >= double(faces) || (4 * want >= 3 * double(faces) && whole_possible) || attempt == 3)) {
      stats->phase1_peak_anon_bytes = 0;
      return collapse_whole(input, o, origin, stats);
    }
    o.sizing = CellSizing();
    o.sizing.ratio = want / double(std::max<std::uint64_t>(faces, 1));
    const bool finest = attempt == 2 && !whole_possible;
    const GridSpec grid = choose_grid(input, o.sizing, o.threads);
    stats->cell_size = grid.cell;
    for (int a = 0; a < 3; ++a) stats->grid_dims[a] = grid.dims[a];
    input.restart_triangles();
    std::vector<Quadric> quadrics;
    const PeakAnonSampler phase1_memory;
    SimplifiedMesh m = method.run(input, o, grid, stats, refining ? &quadrics : nullptr);
    stats->phase1_peak_anon_bytes = phase1_memory.peak();
    if (!refining) return m;
    const std::uint64_t target = resolve_target(o.target, stats->input_triangles);
    if (o.target.max_error == 0 && target >= stats->input_triangles) return input_as_is(input, o, target, stats);
    const std::uint64_t got = m.triangles.size() / 3;
    if (got < target && !finest) continue;
    QuadricMesh q;
    q.positions.resize(got ? m.positions.size() / 3 : 0);
    for (std::size_t i = 0; i < q.positions.size(); ++i)
      q.positions[i] = Vec3d{m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]} - grid.origin;
    std::vector<double>().swap(m.positions);  // copied: not held through phase 2
    q.triangles = std::move(m.triangles);
    q.quadrics = std::move(quadrics);
    q.attribute_count = m.attributes.attributes.size();
    q.attributes = std::move(m.attributes.values);
    bool finer_may_help = false;
    SimplifiedMesh out =
        refine(std::move(q), grid.origin, m.attributes.attributes, target, o, stats, finest, &finer_may_help);
    if (!finer_may_help || finest) return out;
  }
}

}  // namespace oocsimp
