#include "stitch/kept_triangles.hpp"

#include <tbb/parallel_sort.h>

#include <cstring>
#include <stdexcept>
#include <string>

namespace oocsimp {

void stitch_cross_tile_corners(StreamSpill& corners, std::vector<KeptTriangle>* kept) {
  std::vector<KeptTriangle> bucket_kept;
  std::vector<CornerRecord> rec;
  for (std::uint32_t b = 0; b < corners.stream_count(); ++b) {
    corners.read(b, &rec);
    std::sort(rec.begin(), rec.end(),
              [](const CornerRecord& a, const CornerRecord& c) { return a.t_and_slot < c.t_and_slot; });
    for (std::size_t i = 0; i < rec.size();) {
      std::uint64_t t = rec[i].t_and_slot >> 2;
      if (i + 2 >= rec.size() || (rec[i + 2].t_and_slot >> 2) != t)
        throw std::logic_error("stitch: triangle " + std::to_string(t) + " lacks a corner");
      std::uint64_t c0 = rec[i].cluster, c1 = rec[i + 1].cluster, c2 = rec[i + 2].cluster;
      if (c0 != c1 && c1 != c2 && c0 != c2) bucket_kept.push_back(KeptTriangle::of(t, c0, c1, c2));
      i += 3;
    }
    dedupe_kept_triangles(bucket_kept);
    kept->insert(kept->end(), bucket_kept.begin(), bucket_kept.end());
    bucket_kept.clear();
  }
}

}  // namespace oocsimp
