#include "cluster/triangle_records.hpp"

#include <tbb/parallel_sort.h>

namespace oocsimp {

void dedupe_kept_triangles(std::vector<KeptTriangle>& kept) {
  // A total order (one triangle is decided in one place), so an unstable parallel
  // sort gives the same result.
  tbb::parallel_sort(kept.begin(), kept.end(), [](const KeptTriangle& a, const KeptTriangle& b) {
    if (!a.same_clusters(b)) return std::lexicographical_compare(a.c, a.c + 3, b.c, b.c + 3);
    return a.index() < b.index();
  });
  kept.erase(std::unique(kept.begin(), kept.end(),
                         [](const KeptTriangle& a, const KeptTriangle& b) { return a.same_clusters(b); }),
             kept.end());
}

}  // namespace oocsimp
