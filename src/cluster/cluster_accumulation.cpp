#include "cluster/cluster_accumulation.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

#include "cluster/fixed_point_sums.hpp"
#include "cluster/plane_quadric.hpp"
#include "cluster/thick_primitives.hpp"
#include "cluster/tile_grading.hpp"
#include "common/vec3_math.hpp"
#include "runtime/progress_phase.hpp"
#include "cluster/quadric.hpp"
#include "cluster/triangle_records.hpp"
#include "grid/tile_memory_gate.hpp"

namespace oocsimp {

namespace {

// Appends `records` to `spill`, a run per bucket(record), after sorting them by
// it (stably: within a bucket the records keep their order).
template <class Record, class Bucket>
void append_by_bucket(StreamSpill& spill, std::vector<Record>* records, Bucket bucket) {
  std::vector<Record>& r = *records;
  std::stable_sort(r.begin(), r.end(), [&](const Record& a, const Record& b) { return bucket(a) < bucket(b); });
  for (std::size_t i = 0; i < r.size();) {
    std::uint64_t k = bucket(r[i]);
    std::size_t j = i;
    while (j < r.size() && bucket(r[j]) == k) ++j;
    spill.append(std::uint32_t(k), &r[i], j - i);
    i = j;
  }
}

// A tile's shares of its clusters' attribute sums (AttributeLayout), in fixed point
// like the quadric sums, so that merging shares in any order gives the same sums;
// appended to `spill` by centre index, a run per cluster bucket.
void append_attribute_shares(StreamSpill& spill, const AttributeLayout& layout, const AttributeArray& attributes,
                             const std::vector<GradedVertex>& owned, const std::vector<std::uint32_t>& cluster_of,
                             const std::vector<double>& vertex_weight, const std::vector<GradedVertex>& near,
                             std::uint64_t cluster_span) {
  const std::size_t width = layout.width();
  std::vector<Fixed> sums(near.size() * width);
  const auto add_fixed = [](Fixed& sum, double term) { sum.add(Fixed::of(term)); };
  for (std::size_t i = 0; i < owned.size(); ++i)
    layout.add_vertex(&sums[cluster_of[i] * width], attributes, owned[i].index, vertex_weight[i], add_fixed);
  std::vector<std::pair<std::uint64_t, std::size_t>> order;  // (bucket, cluster in near)
  for (std::size_t c = 0; c < near.size(); ++c)
    if (sums[c * width + 1].v != 0) order.push_back({near[c].index / cluster_span, c});  // it has members
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::int64_t> records;
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    records.clear();
    for (; j < order.size() && order[j].first == order[i].first; ++j) {
      const std::size_t c = order[j].second;
      records.push_back(std::int64_t(near[c].index));
      for (std::size_t k = 0; k < width; ++k) records.push_back(sums[c * width + k].v);
    }
    spill.append(std::uint32_t(order[i].first), records.data(), j - i);
    i = j;
  }
}

}  // namespace

ClusterShares accumulate_clusters(const BinnedTiles& tiles, const PositionArray& positions, const BlockStore& blocks,
                                  const TileBorders& borders, std::uint64_t vertex_count,
                                  const AccumulationSettings& settings) {
  const FloatingCellShape& cell = settings.cell;
  const double half = 0.5 * cell.size;
  const SpillSettings& spill = settings.spill;
  ClusterShares out;
  std::uint32_t n = tiles.count();
  std::size_t buckets = std::max<std::size_t>(1, std::size_t(tiles.triangle_count / (1 << 22)) + 1);
  out.bucket_span = std::max<std::uint64_t>(1, (tiles.triangle_count + buckets - 1) / buckets);
  const std::uint64_t bucket_span = out.bucket_span;
  out.corners = std::make_unique<StreamSpill>(spill.dir, "stitch", sizeof(CornerRecord), 4096, spill.compress,
                                              spill.allow.buckets);
  out.inside =
      std::make_unique<StreamSpill>(spill.dir, "kept", sizeof(KeptTriangle), 1024, spill.compress, spill.allow.buckets);
  for (std::size_t b = 0; b < buckets; ++b) {
    out.corners->add_stream();
    out.inside->add_stream();
  }
  // Cluster buckets by centre index: a bucket's shares must fit in an eighth of
  // the budget even if every vertex were a centre.
  // With attributes (and with thick edges), a bucket's attribute shares (edge shares)
  // come on top of its cluster shares, and the buckets' allowance is split between
  // the spills.
  const AttributeArray* attribute_array = settings.attributes;
  if (attribute_array && !attribute_array->empty()) out.attributes = AttributeLayout(*attribute_array);
  const AttributeLayout& layout = out.attributes;
  const std::size_t attribute_bytes = layout.empty() ? 0 : attribute_record_bytes(layout);
  const std::uint64_t sharers = 1 + std::uint64_t(!layout.empty()) + std::uint64_t(settings.thick_edges);
  const std::uint64_t cluster_allowance = spill.allow.buckets / sharers;
  out.cluster_span =
      std::max<std::uint64_t>(1, settings.memory_budget / 8 / (sizeof(PartialCluster) + attribute_bytes));
  const std::uint64_t cluster_span = out.cluster_span;
  std::uint64_t cluster_buckets = vertex_count / cluster_span + 1;
  out.partials =
      std::make_unique<StreamSpill>(spill.dir, "clusters", sizeof(PartialCluster), 64, false, cluster_allowance);
  for (std::uint64_t b = 0; b < cluster_buckets; ++b) out.partials->add_stream();
  if (!layout.empty()) {
    out.attribute_shares = std::make_unique<StreamSpill>(
        spill.dir, "attributes", attribute_bytes, 64, false,
        settings.thick_edges ? cluster_allowance : spill.allow.buckets - cluster_allowance);
    for (std::uint64_t b = 0; b < cluster_buckets; ++b) out.attribute_shares->add_stream();
  }
  if (settings.thick_edges) {
    out.edge_shares = std::make_unique<StreamSpill>(spill.dir, "edges", sizeof(EdgeShare), 64, spill.compress,
                                                    spill.allow.buckets - (sharers - 1) * cluster_allowance);
    for (std::uint64_t b = 0; b < cluster_buckets; ++b) out.edge_shares->add_stream();
  }
  const ProgressCallback none;
  ProgressPhase phase(settings.progress ? *settings.progress : none, "cluster tiles", n, "tile");
  // Each thread's buffers, kept from tile to tile: fresh ones cost a page fault per
  // page, which on virtual machines rivals the work done in them. Between tiles a
  // thread keeps at most half its part of the tiles' share (the buffers of an outsized
  // tile are freed after it; a planned tile's take a few MB), and the gate lets the
  // tiles in work take the other half, so the two stay within the share.
  struct Scratch {
    std::vector<GradedVertex> owned;
    std::vector<std::size_t> owned_at;
    std::vector<Quadric> vertex_q;
    std::vector<KeptTriangle> kept;
    std::vector<CornerRecord> corners;
    std::vector<ClusterRecord> sums;
    std::vector<PartialCluster> partial;
    std::uint64_t bytes() const {
      return owned.capacity() * sizeof(GradedVertex) + owned_at.capacity() * sizeof(std::size_t) +
             vertex_q.capacity() * sizeof(Quadric) + kept.capacity() * sizeof(KeptTriangle) +
             corners.capacity() * sizeof(CornerRecord) + sums.capacity() * sizeof(ClusterRecord) +
             partial.capacity() * sizeof(PartialCluster);
    }
  };
  tbb::enumerable_thread_specific<Scratch> scratches;
  const std::uint64_t threads = std::uint64_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  const std::uint64_t kept_scratch = settings.work_share / 2 / threads;
  // One tile: its vertices assigned, its sums and its kept triangles.
  const auto accumulate_tile = [&](std::uint32_t tile) {
    std::vector<TriangleRecord> tris = tiles.load(tile);
    // Owned vertices grouped by lookup cube: consecutive assignments then probe the
    // same cubes (by input index, the cluster pass was slower). Their order
    // changes no sum: vertex quadrics follow the triangles, cluster sums are fixed point.
    TileVertexBlock block(blocks.block(tile));
    Scratch& scratch = scratches.local();
    std::vector<GradedVertex>& owned = scratch.owned;
    owned.resize(block.size());
    for (std::size_t j = 0; j < owned.size(); ++j) owned[j] = block.vertex(block.filed(j));
    // Local vertex id -> position in `owned` (a binary search per corner took a large
    // share of this pass).
    TileLocalMesh mesh(tris, positions);
    std::vector<std::size_t>& owned_at = scratch.owned_at;
    owned_at.assign(mesh.index.size(), SIZE_MAX);
    for (std::size_t i = 0; i < owned.size(); ++i) owned_at[std::size_t(mesh.ids.find(owned[i].index))] = i;
    std::vector<GradedVertex> near = block.centres();
    std::vector<GradedVertex> ext = external_centres(tiles.grid, tile, borders, half);
    near.insert(near.end(), ext.begin(), ext.end());
    // Per owned vertex: the position in `near` of its cluster's centre.
    std::vector<std::uint32_t> cluster_of = assign_to_centres(owned, near, cell, settings.assign);

    // Vertex quadrics (Garland & Heckbert: the sum of the incident faces' plane
    // quadrics), in double, relative to the vertex's cluster centre in cell
    // units. A vertex's faces all lie in its tile and are summed in input order,
    // so Q_v is the same for any tiling; Q_v then goes into the cluster's
    // fixed-point sum.
    std::vector<Quadric>& vertex_q = scratch.vertex_q;
    vertex_q.assign(owned.size(), Quadric());
    // With attributes, a vertex's weight: a third of its faces' area, in cells squared.
    std::vector<double> vertex_weight(layout.empty() ? 0 : owned.size());
    std::vector<KeptTriangle>& kept = scratch.kept;
    std::vector<CornerRecord>& corners = scratch.corners;
    kept.clear();
    corners.clear();
    EdgeShareTable edges;                                                          // with thick edges
    std::vector<std::uint64_t> collapsed(settings.thick_edges ? near.size() : 0);  // triangles, per cluster
    const double inv = 1.0 / cell.size;
    for (std::size_t t = 0; t < tris.size(); ++t) {
      const TriangleRecord& r = tris[t];
      const std::uint32_t* id = &mesh.corners[3 * t];
      std::size_t local[3];
      int owned_count = 0;
      for (int k = 0; k < 3; ++k) {
        local[k] = r.owned(k) ? owned_at[id[k]] : SIZE_MAX;
        owned_count += local[k] != SIZE_MAX;
      }
      const Vec3d p[3] = {mesh.positions[id[0]], mesh.positions[id[1]], mesh.positions[id[2]]};
      // The face's plane once, in cell units relative to its first corner; each
      // owned corner adds it relative to its own cluster's centre.
      const TrianglePlane plane = triangle_plane((p[1] - p[0]) * inv, (p[2] - p[0]) * inv);
      if (!plane.degenerate())
        for (int k = 0; k < 3; ++k) {
          if (local[k] == SIZE_MAX) continue;
          const Vec3d& m = plane.m;
          const Vec3d r = p[0] - near[cluster_of[local[k]]].p;
          double d = m.x * r.x * inv + m.y * r.y * inv + m.z * r.z * inv;  // m.(first corner), in cells
          add_plane_quadric(&vertex_q[local[k]], plane, d);
          if (!vertex_weight.empty()) vertex_weight[local[k]] += plane.len / 6;
        }
      if (owned_count == 3) {
        const std::uint64_t c[3] = {near[cluster_of[local[0]]].index, near[cluster_of[local[1]]].index,
                                    near[cluster_of[local[2]]].index};
        if (c[0] != c[1] && c[1] != c[2] && c[0] != c[2]) {
          kept.push_back(KeptTriangle::of(r.index(), c[0], c[1], c[2]));
        } else if (settings.thick_edges && c[0] == c[1] && c[1] == c[2]) {
          ++collapsed[cluster_of[local[0]]];
        } else if (settings.thick_edges) {
          Vec3d offset[3];
          for (int k = 0; k < 3; ++k) offset[k] = (p[k] - near[cluster_of[local[k]]].p) * inv;
          edges.add(c, offset);
        }
      } else {
        for (int k = 0; k < 3; ++k)
          if (local[k] != SIZE_MAX)
            corners.push_back({r.index() << 2 | std::uint64_t(k), near[cluster_of[local[k]]].index, mesh.index[id[k]]});
      }
    }
    std::vector<ClusterRecord>& sums = scratch.sums;
    sums.assign(near.size(), ClusterRecord());
    for (std::size_t i = 0; i < owned.size(); ++i) {
      sums[cluster_of[i]].add_vertex(vertex_q[i], (owned[i].p - near[cluster_of[i]].p) * inv);
    }
    for (std::size_t i = 0; i < collapsed.size(); ++i) sums[i].collapsed = collapsed[i];
    if (settings.thick_edges)
      append_by_bucket(*out.edge_shares, &edges.shares(), [&](const EdgeShare& e) { return e.a / cluster_span; });
    // Cross-tile corners go to the stitch buckets by triangle index.
    append_by_bucket(*out.corners, &corners, [&](const CornerRecord& c) { return (c.t_and_slot >> 2) / bucket_span; });
    // This tile's shares of clusters go to the cluster buckets, by centre index.
    std::vector<PartialCluster>& partial = scratch.partial;
    partial.clear();
    for (std::size_t i = 0; i < near.size(); ++i)
      if (sums[i].members) {
        sums[i].centre = near[i].p;
        partial.push_back({near[i].index, sums[i]});
      }
    append_by_bucket(*out.partials, &partial, [&](const PartialCluster& c) { return c.centre / cluster_span; });
    if (!layout.empty())
      append_attribute_shares(*out.attribute_shares, layout, *attribute_array, owned, cluster_of, vertex_weight, near,
                              cluster_span);
    // The triangles decided here go to the same buckets as the stitch's, so that
    // the output-sized list of kept triangles is built once, at its exact size,
    // instead of growing (and being copied) in the heap tile by tile.
    dedupe_kept_triangles(kept);
    append_by_bucket(*out.inside, &kept, [&](const KeptTriangle& k) { return k.index() / bucket_span; });
  };
  TileMemoryGate gate(settings.work_share - kept_scratch * threads);
  tbb::parallel_for(std::uint32_t(0), n, [&](std::uint32_t tile) {
    gate.run(tiles.triangles->record_count(tile) * kTileBytesPerRecord, [&] {
      accumulate_tile(tile);
      Scratch& scratch = scratches.local();
      if (scratch.bytes() > kept_scratch) scratch = Scratch();
    });
    phase.advance(1);
  });
  out.corners->flush();
  out.partials->flush();
  out.inside->flush();
  if (out.attribute_shares) out.attribute_shares->flush();
  if (out.edge_shares) out.edge_shares->flush();
  return out;
}

}  // namespace oocsimp
