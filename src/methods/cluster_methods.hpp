// The clustering methods as rows of one table: a new method is an enum value, its
// file and a row in cluster_methods.cpp.
#pragma once

#include <vector>

#include "cluster/quadric.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// A clustering method: simplify() opens the input, chooses the grid and calls its
/// run function with the triangle stream at its start; run fills the clustering
/// fields of `stats` (counts, the method's phases). With `quadrics`, it also gives
/// each output vertex its cluster's summed quadric, in model units relative to
/// grid.origin (multiphase simplification's phase 1, Garland & Shaffer 2002).
using ClusterRun = SimplifiedMesh (*)(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                                      SimplifyStats* stats, std::vector<Quadric>* quadrics);
struct ClusterMethodEntry {
  ClusterMethod method;  ///< spelled by cluster_method_names() (oocsimp/simplify.hpp)
  ClusterRun run;        ///< null for qem, which clusters nothing (simplify_to_target)
};
/// Every method, the default first.
const std::vector<ClusterMethodEntry>& cluster_method_table();
/// The entry of `m`; throws UsageError for a value without one.
const ClusterMethodEntry& cluster_method(ClusterMethod m);

}  // namespace oocsimp
