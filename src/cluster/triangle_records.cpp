#include "cluster/triangle_records.hpp"

#include <tbb/parallel_sort.h>

namespace oocsimp {

std::size_t dedupe_kept_triangles(KeptTriangle* first, KeptTriangle* last) {
  // A total order (one triangle is decided in one place), so an unstable parallel
  // sort gives the same result.
  tbb::parallel_sort(first, last, [](const KeptTriangle& a, const KeptTriangle& b) {
    if (!a.same_clusters(b)) return std::lexicographical_compare(a.c, a.c + 3, b.c, b.c + 3);
    return a.index() < b.index();
  });
  return std::size_t(
      std::unique(first, last, [](const KeptTriangle& a, const KeptTriangle& b) { return a.same_clusters(b); }) -
      first);
}

}  // namespace oocsimp
