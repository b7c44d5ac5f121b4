#include "methods/cluster_methods.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include "methods/curvature_clusterer.hpp"
#include "methods/floating_clusterer.hpp"
#include "methods/uniform_clusterer.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

OutputMesh single_level(ClusterLevels levels, MeshInput& input, const RunPlan& plan, const GridSpec& grid,
                        SimplifyStats* stats, std::vector<Quadric>* quadrics) {
  OutputMesh out;
  levels(
      input, plan, {grid},
      [&](std::size_t, OutputMesh& m, SimplifyStats& s) {
        out = std::move(m);
        if (stats) *stats = std::move(s);
      },
      stats ? *stats : SimplifyStats(), quadrics);
  return out;
}

const std::vector<ClusterMethodEntry>& cluster_method_table() {
  static const std::vector<ClusterMethodEntry> methods = {
      {ClusterMethod::floating, cluster_floating, cluster_floating_levels},
      {ClusterMethod::uniform, cluster_uniform, nullptr},
      {ClusterMethod::curvature, cluster_curvature, cluster_curvature_levels},
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

std::vector<std::array<double, 3>> locked_positions(const PositionArray& positions,
                                                    const std::vector<std::uint64_t>& locked) {
  std::vector<std::array<double, 3>> places;
  places.reserve(locked.size());
  for (std::uint64_t v : locked) {
    const Vec3d p = positions.get(v);
    if (is_finite(p)) places.push_back({p.x, p.y, p.z});  // a non-finite vertex takes part in nothing
  }
  std::sort(places.begin(), places.end());
  places.erase(std::unique(places.begin(), places.end()), places.end());
  return places;
}

void warn_dropped_locks(std::size_t dropped, std::size_t places, SimplifyStats* stats) {
  if (dropped == 0 || !stats) return;
  stats->warnings.push_back(std::to_string(dropped) + " of " + std::to_string(places) +
                            " locked vertices are left out (counted by position): every neighbour of theirs fell "
                            "in one other cell, so no triangle of theirs survived (a finer grid keeps them)");
}

}  // namespace oocsimp
