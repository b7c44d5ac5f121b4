// The plan of one run: the user's SimplifyOptions with every default settled, made
// once by api/ (plan_run) after the input is opened. The methods and the parts read
// this and nothing else, and never change it; a phase that runs another method (a
// target's phase 1) gets a plan of its own, derived from the run's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/options.hpp"

namespace oocsimp {

struct RunPlan {
  // --- Settled from the options, the input and the machine ---
  ClusterMethod method = ClusterMethod::floating;  ///< never automatic
  std::uint64_t budget_bytes = 0;                  ///< the working set's bytes, never 0
  bool budget_counts_process = false;              ///< as SimplifyOptions::budget_counts_process
  std::string temp_dir;                            ///< never empty
  unsigned threads = 0;                            ///< as given (0: all cores); api/ has limited the run to it
  /// The target, for a run that has one (target.given(): a count, a ratio or a
  /// maximum error, or the qem method alone, which keeps the default share):
  /// max_error in model units (a fraction of the diagonal settled), and the default
  /// ratio where qem names none. Empty for a clustering without a target.
  TargetOptions target;
  std::vector<std::uint64_t> locked_vertices;  ///< sorted, each once

  // --- As the user gave them ---
  CellSizing sizing;
  FloatingOptions floating;
  CurvatureClusterOptions curvature;
  Precision precision = Precision::automatic;
  AttributeSelection attributes;
  bool weld = false;
  bool thick_edges = false;
  bool lock_boundary = false;
  ProgressCallback progress;
  void (*release_memory)() = nullptr;
};

/// Whether the plan's target asks for a count (triangles, or a ratio: the qem method's
/// default share included), not a maximum error alone.
inline bool asks_count(const RunPlan& plan) { return plan.target.triangles != 0 || plan.target.ratio != 0; }

}  // namespace oocsimp
