#include "methods/cluster_methods.hpp"

#include "methods/curvature_clusterer.hpp"
#include "methods/floating_clusterer.hpp"
#include "methods/uniform_clusterer.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

const std::vector<ClusterMethodEntry>& cluster_method_table() {
  static const std::vector<ClusterMethodEntry> methods = {
      {ClusterMethod::floating, cluster_floating},
      {ClusterMethod::uniform, cluster_uniform},
      {ClusterMethod::curvature, cluster_curvature},
      {ClusterMethod::qem, nullptr},  // no clustering: methods/multiphase.cpp
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
