// A run spread over parts (docs/cluster.md): part I of K sums the chunks it owns into
// its part file; the merge checks that every part is there, whole and from the same
// run, and finishes the run from them: the uniform grid, floating cells, curvature
// cells (their estimate spread) and the edge collapse to a target (its first
// out-of-core pass spread).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "methods/curvature_clusterer.hpp"
#include "methods/multiphase.hpp"
#include "methods/uniform_clusterer.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"
#include "parts/part_file.hpp"

namespace oocsimp {

/// The plan's options that shape the output, as one line for the manifest (and the test of
/// a stale part): the method, welding, the attribute selection and the precision.
std::string part_options_text(const RunPlan& plan);
/// The same options back from that text into `options` (the rest untouched); false
/// when the text is malformed.
bool read_part_options(const std::string& text, SimplifyOptions* options);

/// Part manifest.part of manifest.parts of a uniform run on `input` (at its start)
/// with `grid`: the chunks it owns summed (UniformCells::sum_part) into its part file
/// in `dir`, renamed into place when complete. Fills the input counts of `stats`.
void run_uniform_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const std::string& dir,
                      SimplifyStats* stats);

/// The same for a run to a target with plan.method qem (the default with a
/// target): the part's share of the first out-of-core pass (simplify_to_target_part),
/// or nothing but its manifest when the run has no such pass.
void run_qem_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const std::string& dir,
                  SimplifyStats* stats);

/// The same for plan.method floating: the part's tiles' cluster shares
/// (cluster_floating_part), grading and sweeping with the other parts through
/// `channel` when given (parts that run at once), alone otherwise.
void run_floating_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const PartChannel& channel,
                       const std::string& dir, SimplifyStats* stats);

/// The same for plan.method curvature: the curvatures of the vertices dealt to the
/// part (estimate_curvature_part), nearly all of the method's time, with the plan.
void run_curvature_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const std::string& dir,
                        SimplifyStats* stats);

/// Part manifest.part of a clustering run (uniform, floating, curvature) on `input`,
/// at manifest.grid; with a target (plan.target), the part's share of phase 1's
/// first attempt at the grid target_clustering_grid chooses (it overrides
/// manifest.grid), or, when the run clusters nothing there, a part with no work and
/// a grid of cell 0: the merge runs that target whole.
void run_clustering_part(MeshInput& input, const RunPlan& plan, PartManifest manifest, const PartChannel& channel,
                         const std::string& dir, SimplifyStats* stats);

/// The part files of a work folder, checked to make one run: every part of the count
/// present, each whole (its checksum), all with the same manifest but for the part
/// number, and the input unchanged since. Throws InputError (exit 3) naming the
/// missing, damaged or stale part, or the changed input.
class PartSet {
 public:
  explicit PartSet(const std::string& dir);
  const PartManifest& manifest() const { return parts_[0]->manifest(); }
  /// Chunk j of each pass from the part that holds it.
  UniformChunkSource chunks() const;
  /// Whether the parts hold the first pass of an edge collapse (all or none: a part
  /// that differs is stale); then their plans, checked to agree, combined, and their
  /// tiles with `attributes` values per vertex. Throws InputError naming the part.
  bool has_first_pass() const;
  FirstPassParts first_pass(std::size_t attributes) const;
  /// The floating run's plan, checked to be every part's (throws InputError naming a
  /// part without one, or with another tiling), and every part's cluster shares.
  FloatingPartPlan floating_plan() const;
  ClusterShareSource floating_shares(const AttributeLayout& layout) const;
  /// The curvature run's plan, checked to be every part's, with the parts' counts
  /// summed (throws InputError naming a part without one or with another).
  CurvaturePartPlan curvature_plan() const;
  /// The fill of the curvatures of `vertices` input vertices from every part's values
  /// (throws InputError when the parts counted another number of vertices).
  CurvatureFill curvatures(std::uint64_t vertices) const;
  /// The clustering the parts of plan.method shared, merged at the grid it is
  /// given (the manifest's), with quadrics when asked; `input` must outlive it.
  MergedPhaseOne clustering(MeshInput& input, const RunPlan& plan) const;

 private:
  bool has_floating() const;
  std::string dir_;
  std::vector<std::unique_ptr<PartReader>> parts_;  // by part number
};

}  // namespace oocsimp
