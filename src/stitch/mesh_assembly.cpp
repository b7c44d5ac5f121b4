#include "stitch/mesh_assembly.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>

#include "cluster/fixed_point_sums.hpp"
#include "grid/cell_map.hpp"
#include "oocsimp/quadric.hpp"

namespace oocsimp {

// Cross-tile triangles: their corners' clusters were written by the tiles owning
// the corners into buckets by triangle index; a bucket fits in memory.
std::vector<KeptTriangle> stitch_kept_triangles(StreamSpill& inside, StreamSpill& corners) {
  std::vector<KeptTriangle> kept;
  // At most: every triangle decided in a tile, and one per three stitch corners.
  kept.reserve(inside.bytes_appended() / sizeof(KeptTriangle) + corners.bytes_appended() / sizeof(CornerRecord) / 3);
  for (std::uint32_t b = 0; b < inside.stream_count(); ++b) {
    std::size_t at = kept.size();
    kept.resize(at + inside.record_count(b));
    inside.read_into(b, kept.data() + at, (kept.size() - at) * sizeof(KeptTriangle));
  }
  stitch_cross_tile_corners(corners, &kept);
  return kept;
}

Vec3d representative(const ClusterRecord& s, const FloatingCellShape& cell, RepresentativeRule rule) {
  const Vec3d& c = s.centre;
  const Vec3d mean = s.mean();  // relative, in cells
  Vec3d x;
  switch (rule) {
    case RepresentativeRule::centre: return c;
    case RepresentativeRule::mean: x = mean; break;
    case RepresentativeRule::quadric: {
      // Kept inside the floating cell: the cube around the centre, then (for a
      // spherical cell) pulled back onto the sphere.
      x = minimize_quadric(s.quadric(), mean, {-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
      if (cell.shape == CellShape::sphere) {
        double r = length(x);
        if (r > 0.5) x = x * 0.5 / r;
      }
      break;
    }
  }
  return c + x * cell.size;
}

SimplifiedMesh assemble_mesh(std::vector<KeptTriangle> kept, StreamSpill& partials, const FloatingCellShape& cell,
                             RepresentativeRule rule, AssemblyCounts* counts) {
  std::vector<KeptTriangle>& tris = kept;
  dedupe_kept_triangles(tris);
  tbb::parallel_sort(tris.begin(), tris.end(), [](const KeptTriangle& a, const KeptTriangle& b) {
    return a.index() < b.index();  // input order of first occurrence
  });
  // Output vertices are the clusters in order of first use; CellMap numbers its
  // keys in insertion order, which is exactly that.
  CellMap<char> index(2 * tris.size() + 16);
  SimplifiedMesh mesh;
  mesh.triangles.reserve(3 * tris.size());
  for (const KeptTriangle& t : tris)
    for (std::uint64_t c : t.corners()) mesh.triangles.push_back(index.insert(c));
  std::vector<KeptTriangle>().swap(kept);
  // Representatives, a cluster bucket at a time: merge each centre's shares (in
  // fixed point, so in any order) and solve for the clusters some triangle uses.
  mesh.positions.assign(3 * index.size(), 0.0);
  std::uint64_t clusters = 0;
  for (std::uint32_t b = 0; b < partials.stream_count(); ++b) {
    std::vector<PartialCluster> shares;
    partials.read(b, &shares);
    // Shares of one centre in any order: they are summed in fixed point.
    tbb::parallel_sort(shares.begin(), shares.end(),
                       [](const PartialCluster& a, const PartialCluster& c) { return a.centre < c.centre; });
    std::vector<std::size_t> starts;  // first share of each centre
    for (std::size_t i = 0; i < shares.size(); ++i)
      if (i == 0 || shares[i].centre != shares[i - 1].centre) starts.push_back(i);
    clusters += starts.size();
    starts.push_back(shares.size());
    tbb::parallel_for(std::size_t(0), starts.size() - 1, [&](std::size_t k) {
      std::int64_t id = index.find(shares[starts[k]].centre);
      if (id < 0) return;  // a cluster no output triangle uses
      ClusterRecord sum = shares[starts[k]].sums;
      for (std::size_t i = starts[k] + 1; i < starts[k + 1]; ++i) sum.add(shares[i].sums);
      Vec3d p = representative(sum, cell, rule);
      mesh.positions[3 * std::size_t(id)] = p.x;
      mesh.positions[3 * std::size_t(id) + 1] = p.y;
      mesh.positions[3 * std::size_t(id) + 2] = p.z;
    });
  }
  if (counts) counts->clusters = clusters;
  return mesh;
}

}  // namespace oocsimp
