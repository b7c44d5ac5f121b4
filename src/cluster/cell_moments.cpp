// Per-cell patch moments and the cell-scale curvature; see cell_moments.hpp.
#include "cluster/cell_moments.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <vector>

#include "cluster/plane_quadric.hpp"
#include "oocsimp/error.hpp"
#include "runtime/ordered_pipeline.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

constexpr std::size_t kFaceChunk = 1 << 15;
constexpr std::size_t kChunkSlots = 1 << 10;  // a chunk's table, at first
constexpr std::size_t kTableSlots = 1 << 12;  // a pass's table, at first

struct MomentChunk {
  std::vector<std::uint64_t> tris = std::vector<std::uint64_t>(3 * kFaceChunk);
  std::size_t count = 0;
  CellMap<PatchMoments> cells{kChunkSlots};
};

std::size_t pipeline_tokens() { return 2 * std::max<std::size_t>(1, tbb::this_task_arena::max_concurrency()); }

// Each face of the chunk to its centroid's cell, with the last cell remembered: the
// faces of a stream come in runs through one cell.
void sum_chunk(const PositionArray& positions, const MomentLattice& lattice, const MomentFilter& keep, MomentChunk& c) {
  c.cells.clear();
  std::uint64_t last_key = ~std::uint64_t(0);
  std::uint32_t last_index = 0;
  bool last_kept = false;
  for (std::size_t t = 0; t < c.count; ++t) {
    const std::uint64_t* v = &c.tris[3 * t];
    const Vec3d a = positions.get(v[0]) - lattice.origin, b = positions.get(v[1]) - lattice.origin,
                d = positions.get(v[2]) - lattice.origin;
    if (!is_finite(a) || !is_finite(b) || !is_finite(d)) continue;
    const Vec3d centroid = (a + b + d) / 3.0;
    const std::uint64_t key = lattice.key_relative(centroid);
    if (key != last_key) {
      last_key = key;
      last_kept = !keep || keep(key);
      if (last_kept) last_index = c.cells.insert(key);
    }
    if (!last_kept) continue;
    const Vec3d corner = lattice.corner(key);
    c.cells.value(last_index).add_face(centroid - corner, triangle_plane(b - a, d - a).m * 0.5);
  }
}

}  // namespace

std::uint64_t estimated_moment_cells(const OccupancyGrowth& occupancy, const Box3d& bounds,
                                     const MomentLattice& lattice, std::uint64_t faces) {
  // The occupancy's resolution counts cells along the bounding box's longest side.
  const Vec3d e = bounds.max - bounds.min;
  const double resolution = std::max({e.x, e.y, e.z}) / lattice.side;
  // A face's centroid keys its cell: the faces are the points that fill the cells.
  double cells = 1.25 * occupancy.occupied_by(std::max(resolution, 1.0), faces);
  cells = std::min({cells, double(faces), double(lattice.dims[0]) * double(lattice.dims[1]) * double(lattice.dims[2])});
  return std::uint64_t(std::ceil(std::max(cells, 1.0)));
}

std::uint64_t moment_table_bytes(std::uint64_t cells) {
  return CellMap<PatchMoments>(kTableSlots).bytes_with(std::size_t(cells));
}

std::uint64_t moment_pass_bytes(std::uint64_t cells, bool worst) {
  const std::uint64_t chunk_cells = worst ? std::min<std::uint64_t>(cells, kFaceChunk) : 1;
  const std::uint64_t chunk =
      3 * kFaceChunk * sizeof(std::uint64_t) + CellMap<PatchMoments>(kChunkSlots).bytes_with(std::size_t(chunk_cells));
  return moment_table_bytes(cells) + pipeline_tokens() * chunk;
}

std::uint64_t sum_cell_moments(MeshInput& input, const MomentLattice& lattice, const MomentFilter& keep,
                               CellMap<PatchMoments>* cells, const MomentCheck& check, const ProgressCallback& progress,
                               const char* phase_name) {
  TriangleStream& stream = *input.triangles;
  std::uint64_t read = 0;
  std::uint64_t largest_chunk = 0;
  const std::size_t tokens = pipeline_tokens();
  ProgressPhase phase(progress, phase_name, input.file_size, "B");
  run_ordered_pipeline<MomentChunk>(
      tokens,
      [&](MomentChunk& c) {
        c.count = stream.read(c.tris.data(), kFaceChunk);
        phase.set(stream.bytes_consumed());
        return c.count > 0;
      },
      [&](MomentChunk& c) { sum_chunk(input.positions, lattice, keep, c); },
      [&](MomentChunk& c) {
        read += c.count;
        for (std::size_t i = 0; i < c.cells.size(); ++i) {
          const std::uint32_t g = cells->insert(c.cells.key(i));
          cells->value(g).add(c.cells.value(i), Vec3d{});
        }
        largest_chunk = std::max<std::uint64_t>(largest_chunk, c.cells.bytes() + c.tris.capacity() * 8);
        if (check) check(cells->bytes() + tokens * largest_chunk, read);
      });
  input.restart_triangles();
  return read;
}

PatchCurvature neighbourhood_curvature(const CellMap<PatchMoments>& cells, const MomentLattice& lattice,
                                       std::uint64_t key) {
  const std::int64_t at[3] = {std::int64_t(key & MomentLattice::kAxisMask),
                              std::int64_t((key >> 21) & MomentLattice::kAxisMask),
                              std::int64_t((key >> 42) & MomentLattice::kAxisMask)};
  PatchMoments sum;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const std::int64_t x = at[0] + dx, y = at[1] + dy, z = at[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x >= std::int64_t(lattice.dims[0]) || y >= std::int64_t(lattice.dims[1]) ||
            z >= std::int64_t(lattice.dims[2]))
          continue;
        const std::int64_t i = cells.find(std::uint64_t(x) | (std::uint64_t(y) << 21) | (std::uint64_t(z) << 42));
        if (i < 0) continue;
        sum.add(cells.value(std::size_t(i)), Vec3d{dx * lattice.side, dy * lattice.side, dz * lattice.side});
      }
  return patch_curvature(sum);
}

ScaleCurvatureCounts estimate_at_scale(MeshInput& input, double side, const MemoryBudget& budget,
                                       const ProgressCallback& progress, float* k) {
  const PositionArray& positions = input.positions;
  ScaleCurvatureCounts counts;
  std::fill(k, k + 2 * positions.count, 0.f);
  const Box3d& box = input.info.bounds;
  if (!(side > 0) || !std::isfinite(side)) throw UsageError("options.at_scale", "options.at_scale must be positive");
  if (box.empty()) return counts;
  MomentLattice lattice;
  lattice.origin = box.min;
  lattice.side = side;
  const Vec3d extent = box.max - box.min;
  const double e[3] = {extent.x, extent.y, extent.z};
  for (int a = 0; a < 3; ++a) {
    const double n = std::floor(e[a] / side) + 1;
    if (!(n < double(MomentLattice::kAxisMask)))
      throw UsageError("options.at_scale", "options.at_scale " + std::to_string(side) +
                                               " would cut the bounding box into " + std::to_string(n) +
                                               " cells along an axis; at most " +
                                               std::to_string(MomentLattice::kAxisMask) + " fit");
    lattice.dims[a] = std::uint64_t(n);
  }
  const std::uint64_t held = budget.held();
  const std::uint64_t triangles = std::max<std::uint64_t>(input.info.face_count, 1);
  // Up front: the table and the pass's chunks, then the table and each cell's
  // estimate, for the cells the vertices' occupancy says the faces will fill. Refused
  // when even the least of it does not fit; the advice holds the most.
  const std::uint64_t expected =
      estimated_moment_cells(sampled_occupancy_growth(positions, box), box, lattice, triangles);
  const std::uint64_t after = moment_table_bytes(expected) + expected * sizeof(PatchCurvature);
  const std::uint64_t least = std::max(moment_pass_bytes(expected, false), after);
  const std::uint64_t most = std::max(moment_pass_bytes(expected, true), after);
  budget.check(held, least, "about " + std::to_string(expected) + " cells of curvature moments, estimated",
               "give at least " + whole_mib(held + most) + " MiB, or a larger options.at_scale");
  CellMap<PatchMoments> cells(kTableSlots);
  counts.triangles = sum_cell_moments(
      input, lattice, nullptr, &cells,
      [&](std::uint64_t bytes, std::uint64_t read) {
        if (budget.fits(held, bytes)) return;
        // The table grows with the faces read: what the whole input would take.
        const double whole = double(bytes) * double(triangles) / double(std::max<std::uint64_t>(read, 1));
        budget.check(
            held, bytes,
            std::to_string(cells.size()) + " cells of curvature moments after " + std::to_string(read) + " triangles",
            "give at least " + whole_mib(held + std::uint64_t(whole)) + " MiB, or a larger options.at_scale");
      },
      progress, "cell moments");
  counts.cells = cells.size();
  budget.check(held, cells.bytes() + cells.size() * sizeof(PatchCurvature),
               std::to_string(cells.size()) + " cells of curvature moments and their estimates",
               "give at least " + whole_mib(held + cells.bytes() + cells.size() * sizeof(PatchCurvature)) +
                   " MiB, or a larger options.at_scale");
  // Each cell's estimate, in the table's order.
  std::vector<PatchCurvature> estimate(cells.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i < r.end(); ++i)
                        estimate[i] = neighbourhood_curvature(cells, lattice, cells.key(i));
                    });
  for (const PatchCurvature& c : estimate) {
    if (c.fit == PatchFit::slope)
      ++counts.slope;
    else if (c.fit == PatchFit::folded)
      ++counts.folded;
    else
      ++counts.empty;
  }
  // Each vertex from the (up to) 8 cells whose centres surround it, weighted
  // trilinearly over those with an estimate.
  std::atomic<std::uint64_t> interpolated{0};
  ProgressPhase phase(progress, "curvatures at scale", positions.count, "vtx");
  tbb::parallel_for(
      tbb::blocked_range<std::uint64_t>(0, positions.count, 1 << 14), [&](const tbb::blocked_range<std::uint64_t>& r) {
        std::uint64_t found = 0;
        for (std::uint64_t v = r.begin(); v < r.end(); ++v) {
          const Vec3d p = positions.get(v) - lattice.origin;
          if (!is_finite(p)) continue;
          const double u[3] = {p.x / side - 0.5, p.y / side - 0.5, p.z / side - 0.5};
          std::int64_t base[3];
          double f[3];
          for (int a = 0; a < 3; ++a) {
            base[a] = std::int64_t(std::floor(u[a]));
            f[a] = u[a] - double(base[a]);
          }
          double w_sum = 0, s1 = 0, s2 = 0;
          for (int corner = 0; corner < 8; ++corner) {
            std::int64_t c[3];
            double w = 1;
            bool inside = true;
            for (int a = 0; a < 3; ++a) {
              const int o = (corner >> a) & 1;
              c[a] = base[a] + o;
              w *= o ? f[a] : 1 - f[a];
              inside = inside && c[a] >= 0 && c[a] < std::int64_t(lattice.dims[a]);
            }
            if (!inside || !(w > 0)) continue;
            const std::int64_t i =
                cells.find(std::uint64_t(c[0]) | (std::uint64_t(c[1]) << 21) | (std::uint64_t(c[2]) << 42));
            if (i < 0 || estimate[std::size_t(i)].fit != PatchFit::slope) continue;
            w_sum += w;
            s1 += w * estimate[std::size_t(i)].k1;
            s2 += w * estimate[std::size_t(i)].k2;
          }
          if (!(w_sum > 0)) {
            // On a cell's centre plane every weight but its own side's is 0:
            // the vertex's own cell, if it has one.
            const std::int64_t i = cells.find(lattice.key_relative(p));
            if (i < 0 || estimate[std::size_t(i)].fit != PatchFit::slope) continue;
            w_sum = 1;
            s1 = estimate[std::size_t(i)].k1;
            s2 = estimate[std::size_t(i)].k2;
          }
          k[2 * v] = float(s1 / w_sum);
          k[2 * v + 1] = float(s2 / w_sum);
          ++found;
        }
        interpolated += found;
        phase.advance(r.size());
      });
  counts.interpolated = interpolated;
  counts.none = positions.count - counts.interpolated;
  return counts;
}

}  // namespace oocsimp
