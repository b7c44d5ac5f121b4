// The clustering methods as rows of one table: a new method is an enum value, its
// file and a row in cluster_methods.cpp.
#pragma once

#include <vector>

#include "oocsimp/simplify.hpp"

namespace oocsimp {

/// A clustering method: simplify() opens the input, chooses the grid and calls its
/// run function with the triangle stream at its start; run fills the clustering
/// fields of `stats` (counts, the method's phases).
using ClusterRun = SimplifiedMesh (*)(MeshInput& input, const SimplifyOptions& options, const GridSpec& grid,
                                      SimplifyStats* stats);
struct ClusterMethodEntry {
  ClusterMethod method;
  const char* name;  ///< as the stats (and the CLI's --method) spell it
  ClusterRun run;
};
/// Every method, the default first.
const std::vector<ClusterMethodEntry>& cluster_method_table();
/// The entry of `m`; throws UsageError for a value without one.
const ClusterMethodEntry& cluster_method(ClusterMethod m);

}  // namespace oocsimp
