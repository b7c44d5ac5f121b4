#include "stitch/kept_triangles.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cstring>

#include "cluster/thick_primitives.hpp"
#include "common/vec3_math.hpp"
#include <stdexcept>
#include <string>

namespace oocsimp {

void stitch_cross_tile_corners(StreamSpill& corners, const KeptTriangleSink& keep, const CrossTileEdges* edges) {
  std::vector<KeptTriangle> bucket_kept;
  std::vector<CornerRecord> rec;
  EdgeShareTable shares;
  for (std::uint32_t b = 0; b < corners.stream_count(); ++b) {
    corners.read(b, &rec);
    std::sort(rec.begin(), rec.end(),
              [](const CornerRecord& a, const CornerRecord& c) { return a.t_and_slot < c.t_and_slot; });
    for (std::size_t i = 0; i < rec.size();) {
      std::uint64_t t = rec[i].t_and_slot >> 2;
      if (i + 2 >= rec.size() || (rec[i + 2].t_and_slot >> 2) != t)
        throw std::logic_error("stitch: triangle " + std::to_string(t) + " lacks a corner");
      const std::uint64_t c[3] = {rec[i].cluster, rec[i + 1].cluster, rec[i + 2].cluster};
      if (c[0] != c[1] && c[1] != c[2] && c[0] != c[2]) {
        bucket_kept.push_back(KeptTriangle::of(t, c[0], c[1], c[2]));
      } else if (edges) {
        // The same offsets as a tile computes: (position - centre) / cell.
        const double inv = 1.0 / edges->cell;
        Vec3d offset[3];
        for (int k = 0; k < 3; ++k)
          offset[k] = (edges->positions->get(rec[i + k].vertex) - edges->positions->get(c[k])) * inv;
        shares.add(c, offset);
      }
      i += 3;
    }
    if (edges) {
      std::vector<EdgeShare>& s = shares.shares();
      std::stable_sort(s.begin(), s.end(), [&](const EdgeShare& a, const EdgeShare& b) {
        return a.a / edges->cluster_span < b.a / edges->cluster_span;
      });
      for (std::size_t j = 0; j < s.size();) {
        std::size_t k = j;
        while (k < s.size() && s[k].a / edges->cluster_span == s[j].a / edges->cluster_span) ++k;
        edges->shares->append(std::uint32_t(s[j].a / edges->cluster_span), &s[j], k - j);
        j = k;
      }
      shares.clear();
    }
    dedupe_kept_triangles(bucket_kept);
    keep(bucket_kept.data(), bucket_kept.size());
    bucket_kept.clear();
  }
}

}  // namespace oocsimp
