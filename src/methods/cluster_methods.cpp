#include "methods/cluster_methods.hpp"

#include "methods/curvature_clusterer.hpp"
#include "methods/floating_clusterer.hpp"
#include "methods/uniform_clusterer.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

void floating_levels(MeshInput& input, const SimplifyOptions& options, const std::vector<GridSpec>& grids,
                     const LevelSink& sink, const SimplifyStats& base) {
  cluster_floating_levels(input, options, grids, sink, base);
}

void curvature_levels(MeshInput& input, const SimplifyOptions& options, const std::vector<GridSpec>& grids,
                      const LevelSink& sink, const SimplifyStats& base) {
  cluster_curvature_levels(input, options, grids, sink, base);
}

}  // namespace

const std::vector<ClusterMethodEntry>& cluster_method_table() {
  static const std::vector<ClusterMethodEntry> methods = {
      {ClusterMethod::floating, cluster_floating, floating_levels},
      {ClusterMethod::uniform, cluster_uniform, nullptr},
      {ClusterMethod::curvature, cluster_curvature, curvature_levels},
      {ClusterMethod::qem, nullptr, nullptr},  // no clustering: methods/multiphase.cpp
  };
  return methods;
}

const ClusterMethodEntry& cluster_method(ClusterMethod m) {
  for (const ClusterMethodEntry& e : cluster_method_table())
    if (e.method == m) return e;
  throw UsageError("unknown clustering method");
}

std::vector<ClusterMethod> cluster_methods() {
  std::vector<ClusterMethod> methods;
  for (const ClusterMethodEntry& e : cluster_method_table()) methods.push_back(e.method);
  return methods;
}

}  // namespace oocsimp
