// Pass 3 of floating cells, tile by tile in parallel (Low & Tan 1997 §3.2: each vertex
// goes to the cluster of a centre whose cell holds it, and only the triangles over
// three clusters survive):
//   assign      the tile's owned vertices to the decided centres, its own and its
//               neighbours' border centres;
//   faces       the vertex quadrics from the faces (Garland & Heckbert 1997), and each
//               triangle kept, collapsed (thick edges, Low & Tan 1997 §3.3) or left
//               to the stitch when it crosses tiles;
//   clusters    the vertex quadrics summed per cluster, in fixed point;
//   hand on     the tile's shares to the spills of ClusterShares, by bucket.
#include "cluster/cluster_accumulation.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <utility>
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
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// Triangles per stitch bucket: the stitch reads a bucket whole (up to three corners
// a triangle, and the triangles they make), so a bucket's records fit in an eighth of
// the budget; within these bounds, so the buckets stay few.
constexpr std::uint64_t kLeastTrianglesPerStitchBucket = std::uint64_t(1) << 16;
constexpr std::uint64_t kMostTrianglesPerStitchBucket = std::uint64_t(1) << 22;
constexpr std::uint64_t kStitchBucketsInBudget = 8;
// A cluster bucket's shares fit in an eighth of the budget even if every vertex were
// a centre: the assembly reads a bucket whole next to the output tables.
constexpr std::uint64_t kClusterBucketsInBudget = 8;
// Records per buffer of a spill's stream: the stitch buckets are few and large, the
// cluster buckets many (one per cluster span), each with a buffer of its own.
// The stitch buckets' buffers together take at most a sixteenth of the budget.
constexpr std::size_t kMostCornerBufferRecords = 4096;
constexpr std::size_t kLeastCornerBufferRecords = 256;
constexpr std::uint64_t kStitchBuffersInBudget = 16;
constexpr std::size_t kClusterBufferRecords = 64;

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

// The stitch buckets, by triangle index: the corners of the triangles that cross
// tiles (`corners`) and the triangles decided inside a tile (`inside`).
void open_triangle_buckets(std::uint64_t triangle_count, const SpillSettings& spill, std::uint64_t memory_budget,
                           ClusterShares* out) {
  const std::uint64_t per_bucket = std::clamp<std::uint64_t>(
      memory_budget / kStitchBucketsInBudget / (3 * sizeof(CornerRecord) + sizeof(KeptTriangle)),
      kLeastTrianglesPerStitchBucket, kMostTrianglesPerStitchBucket);
  std::size_t buckets = std::max<std::size_t>(1, std::size_t(triangle_count / per_bucket) + 1);
  out->bucket_span = std::max<std::uint64_t>(1, (triangle_count + buckets - 1) / buckets);
  // Each stream has a buffer of its own: many buckets get smaller ones.
  const std::size_t corner_buffer = std::size_t(
      std::clamp<std::uint64_t>(memory_budget / kStitchBuffersInBudget / buckets / (2 * sizeof(CornerRecord)),
                                kLeastCornerBufferRecords, kMostCornerBufferRecords));
  out->corners = std::make_unique<StreamSpill>(spill.dir, "stitch", sizeof(CornerRecord), corner_buffer, spill.compress,
                                               spill.allow.buckets);
  out->inside = std::make_unique<StreamSpill>(spill.dir, "kept", sizeof(KeptTriangle), corner_buffer / 4,
                                              spill.compress, spill.allow.buckets);
  for (std::size_t b = 0; b < buckets; ++b) {
    out->corners->add_stream();
    out->inside->add_stream();
  }
}

// The cluster buckets, by centre index: the tiles' shares of each cluster
// (`partials`), with attributes their attribute shares, with thick edges their edge
// shares, which split the buckets' allowance between them.
void open_cluster_buckets(std::uint64_t vertex_count, const AccumulationSettings& settings, ClusterShares* out) {
  const SpillSettings& spill = settings.spill;
  const AttributeArray* attribute_array = settings.attributes;
  if (attribute_array && !attribute_array->empty()) out->attributes = AttributeLayout(*attribute_array);
  const AttributeLayout& layout = out->attributes;
  const std::size_t attribute_bytes = layout.empty() ? 0 : attribute_record_bytes(layout);
  const std::uint64_t sharers = 1 + std::uint64_t(!layout.empty()) + std::uint64_t(settings.thick_edges);
  const std::uint64_t cluster_allowance = spill.allow.buckets / sharers;
  out->cluster_span = std::max<std::uint64_t>(
      1, settings.memory_budget / kClusterBucketsInBudget / (sizeof(PartialCluster) + attribute_bytes));
  std::uint64_t cluster_buckets = vertex_count / out->cluster_span + 1;
  out->partials = std::make_unique<StreamSpill>(spill.dir, "clusters", sizeof(PartialCluster), kClusterBufferRecords,
                                                false, cluster_allowance);
  for (std::uint64_t b = 0; b < cluster_buckets; ++b) out->partials->add_stream();
  if (!layout.empty()) {
    out->attribute_shares = std::make_unique<StreamSpill>(
        spill.dir, "attributes", attribute_bytes, kClusterBufferRecords, false,
        settings.thick_edges ? cluster_allowance : spill.allow.buckets - cluster_allowance);
    for (std::uint64_t b = 0; b < cluster_buckets; ++b) out->attribute_shares->add_stream();
  }
  if (settings.thick_edges) {
    out->edge_shares =
        std::make_unique<StreamSpill>(spill.dir, "edges", sizeof(EdgeShare), kClusterBufferRecords, spill.compress,
                                      spill.allow.buckets - (sharers - 1) * cluster_allowance);
    for (std::uint64_t b = 0; b < cluster_buckets; ++b) out->edge_shares->add_stream();
  }
}

// Each thread's buffers, kept from tile to tile: fresh ones cost a page fault per
// page, which on virtual machines rivals the work done in them.
struct Scratch {
  std::vector<GradedVertex> owned;  // the tile's owned vertices, grouped by lookup cube
  std::vector<std::size_t> owned_at;
  std::vector<Quadric> vertex_q;  // per owned vertex
  std::vector<KeptTriangle> kept;
  std::vector<CornerRecord> corners;
  std::vector<ClusterRecord> sums;  // per centre in reach
  std::vector<PartialCluster> partial;
  std::uint64_t bytes() const {
    return owned.capacity() * sizeof(GradedVertex) + owned_at.capacity() * sizeof(std::size_t) +
           vertex_q.capacity() * sizeof(Quadric) + kept.capacity() * sizeof(KeptTriangle) +
           corners.capacity() * sizeof(CornerRecord) + sums.capacity() * sizeof(ClusterRecord) +
           partial.capacity() * sizeof(PartialCluster);
  }
};

// A tile's triangles over its local mesh, with its owned vertices (in the scratch)
// assigned to clusters: `near` holds the centres in reach (the tile's own, then its
// neighbours' border centres), and cluster_of, per owned vertex, the position in
// `near` of its cluster's centre.
struct AssignedTile {
  AssignedTile(TriangleRecords records, const PositionArray& positions)
      : tris(std::move(records)), mesh(tris, positions) {}
  TriangleRecords tris;
  TileLocalMesh mesh;
  std::vector<GradedVertex> near;
  std::vector<std::uint32_t> cluster_of;
};

// What a tile's faces leave besides the vertex quadrics, kept triangles and stitch
// corners (in the scratch).
struct FaceSums {
  std::vector<double> vertex_weight;  // with attributes: per owned vertex, a third of its faces' area, in cells squared
  EdgeShareTable edges;               // with thick edges: the triangles that collapse to an edge
  std::vector<std::uint64_t> collapsed;  // with thick edges: per centre in reach, the triangles collapsed into it
};

// The work of one tile: the steps of the file's header, each a method.
class TileAccumulation {
 public:
  TileAccumulation(const BinnedTiles& tiles, const PositionArray& positions, const BlockStore& blocks,
                   const TileBorders& borders, const AccumulationSettings& settings, ClusterShares& out)
      : tiles_(tiles), positions_(positions), blocks_(blocks), borders_(borders), settings_(settings), out_(out) {}

  void run(std::uint32_t tile, Scratch& scratch) const {
    AssignedTile a(tiles_.load(tile), positions_);
    assign_vertices(tile, scratch, &a);
    FaceSums faces;
    add_faces(a, scratch, &faces);
    sum_clusters(a, faces, scratch);
    hand_on(a, faces, scratch);
  }

 private:
  void assign_vertices(std::uint32_t tile, Scratch& s, AssignedTile* a) const;
  void add_faces(const AssignedTile& a, Scratch& s, FaceSums* f) const;
  void add_face_quadric(const AssignedTile& a, const Vec3d p[3], const std::size_t local[3], Scratch& s,
                        FaceSums* f) const;
  void decide_triangle(const AssignedTile& a, const TriangleRecord& r, const Vec3d p[3], const std::size_t local[3],
                       Scratch& s, FaceSums* f) const;
  void sum_clusters(const AssignedTile& a, const FaceSums& f, Scratch& s) const;
  void hand_on(const AssignedTile& a, FaceSums& f, Scratch& s) const;
  void hand_on_attribute_shares(const AssignedTile& a, const FaceSums& f, const Scratch& s) const;

  const BinnedTiles& tiles_;
  const PositionArray& positions_;
  const BlockStore& blocks_;
  const TileBorders& borders_;
  const AccumulationSettings& settings_;
  ClusterShares& out_;
  const double half_ = 0.5 * settings_.cell.size;
  const double inv_ = 1.0 / settings_.cell.size;
};

// Owned vertices grouped by lookup cube: consecutive assignments then probe the
// same cubes (by input index the pass is slower). Their order changes no sum: vertex
// quadrics follow the triangles, cluster sums are fixed point.
void TileAccumulation::assign_vertices(std::uint32_t tile, Scratch& s, AssignedTile* a) const {
  TileVertexBlock block(blocks_.block(tile));
  std::vector<GradedVertex>& owned = s.owned;
  owned.resize(block.size());
  for (std::size_t j = 0; j < owned.size(); ++j) owned[j] = block.vertex(block.filed(j));
  // Local vertex id -> position in `owned` (rather than a binary search per corner).
  std::vector<std::size_t>& owned_at = s.owned_at;
  owned_at.assign(a->mesh.index.size(), SIZE_MAX);
  for (std::size_t i = 0; i < owned.size(); ++i) owned_at[std::size_t(a->mesh.ids.find(owned[i].index))] = i;
  a->near = block.centres();
  std::vector<GradedVertex> ext = external_centres(tiles_.grid, tile, borders_, half_);
  a->near.insert(a->near.end(), ext.begin(), ext.end());
  a->cluster_of = assign_to_centres(owned, a->near, settings_.cell, settings_.assign);
}

// Vertex quadrics (Garland & Heckbert 1997: the sum of the incident faces' plane
// quadrics), in double, relative to the vertex's cluster centre in cell units. A
// vertex's faces all lie in its tile and are summed in input order, so Q_v is the
// same for any tiling; Q_v then goes into the cluster's fixed-point sum.
void TileAccumulation::add_faces(const AssignedTile& a, Scratch& s, FaceSums* f) const {
  s.vertex_q.assign(s.owned.size(), Quadric());
  if (!out_.attributes.empty()) f->vertex_weight.assign(s.owned.size(), 0.0);
  s.kept.clear();
  s.corners.clear();
  if (settings_.thick_edges) f->collapsed.assign(a.near.size(), 0);
  for (std::size_t t = 0; t < a.tris.size(); ++t) {
    const TriangleRecord& r = a.tris[t];
    const std::uint32_t* id = &a.mesh.corners[3 * t];
    std::size_t local[3];  // the owned corners' positions in `owned`, SIZE_MAX for the others
    int owned_count = 0;
    for (int k = 0; k < 3; ++k) {
      local[k] = r.owned(k) ? s.owned_at[id[k]] : SIZE_MAX;
      owned_count += local[k] != SIZE_MAX;
    }
    const Vec3d p[3] = {a.mesh.positions[id[0]], a.mesh.positions[id[1]], a.mesh.positions[id[2]]};
    add_face_quadric(a, p, local, s, f);
    if (owned_count == 3) {
      decide_triangle(a, r, p, local, s, f);
    } else {  // it crosses tiles: its owned corners go to the stitch
      for (int k = 0; k < 3; ++k)
        if (local[k] != SIZE_MAX)
          s.corners.push_back(
              {r.index() << 2 | std::uint64_t(k), a.near[a.cluster_of[local[k]]].index, a.mesh.index[id[k]]});
    }
  }
}

// The face's plane once, in cell units relative to its first corner; each owned
// corner adds it relative to its own cluster's centre.
void TileAccumulation::add_face_quadric(const AssignedTile& a, const Vec3d p[3], const std::size_t local[3], Scratch& s,
                                        FaceSums* f) const {
  const double inv = inv_;
  const TrianglePlane plane = triangle_plane((p[1] - p[0]) * inv, (p[2] - p[0]) * inv);
  if (plane.degenerate()) return;
  for (int k = 0; k < 3; ++k) {
    if (local[k] == SIZE_MAX) continue;
    const Vec3d& m = plane.m;
    const Vec3d r = p[0] - a.near[a.cluster_of[local[k]]].p;
    double d = m.x * r.x * inv + m.y * r.y * inv + m.z * r.z * inv;  // m.(first corner), in cells
    add_plane_quadric(&s.vertex_q[local[k]], plane, d);
    if (!f->vertex_weight.empty()) f->vertex_weight[local[k]] += plane.len / 6;
  }
}

// A triangle whose corners this tile owns: kept over three clusters; with thick
// edges, one over two clusters adds to its edge's share and one over a single
// cluster counts as collapsed into it (Low & Tan 1997 §3.3).
void TileAccumulation::decide_triangle(const AssignedTile& a, const TriangleRecord& r, const Vec3d p[3],
                                       const std::size_t local[3], Scratch& s, FaceSums* f) const {
  const std::uint64_t c[3] = {a.near[a.cluster_of[local[0]]].index, a.near[a.cluster_of[local[1]]].index,
                              a.near[a.cluster_of[local[2]]].index};
  if (c[0] != c[1] && c[1] != c[2] && c[0] != c[2]) {
    s.kept.push_back(KeptTriangle::of(r.index(), c[0], c[1], c[2]));
  } else if (settings_.thick_edges && c[0] == c[1] && c[1] == c[2]) {
    ++f->collapsed[a.cluster_of[local[0]]];
  } else if (settings_.thick_edges) {
    Vec3d offset[3];
    for (int k = 0; k < 3; ++k) offset[k] = (p[k] - a.near[a.cluster_of[local[k]]].p) * inv_;
    f->edges.add(c, offset);
  }
}

// The tile's share of each cluster in reach: its members' vertex quadrics and offsets.
void TileAccumulation::sum_clusters(const AssignedTile& a, const FaceSums& f, Scratch& s) const {
  std::vector<ClusterRecord>& sums = s.sums;
  sums.assign(a.near.size(), ClusterRecord());
  for (std::size_t i = 0; i < s.owned.size(); ++i) {
    sums[a.cluster_of[i]].add_vertex(s.vertex_q[i], (s.owned[i].p - a.near[a.cluster_of[i]].p) * inv_);
  }
  for (std::size_t i = 0; i < f.collapsed.size(); ++i) sums[i].collapsed = f.collapsed[i];
}

void TileAccumulation::hand_on(const AssignedTile& a, FaceSums& f, Scratch& s) const {
  const std::uint64_t cluster_span = out_.cluster_span, bucket_span = out_.bucket_span;
  if (settings_.thick_edges)
    append_by_bucket(*out_.edge_shares, &f.edges.shares(), [&](const EdgeShare& e) { return e.a / cluster_span; });
  // Cross-tile corners go to the stitch buckets by triangle index.
  append_by_bucket(*out_.corners, &s.corners, [&](const CornerRecord& c) { return (c.t_and_slot >> 2) / bucket_span; });
  // This tile's shares of clusters go to the cluster buckets, by centre index.
  std::vector<PartialCluster>& partial = s.partial;
  partial.clear();
  for (std::size_t i = 0; i < a.near.size(); ++i)
    if (s.sums[i].members) {
      s.sums[i].centre = a.near[i].p;
      s.sums[i].locked = is_locked(a.near[i]);
      partial.push_back({a.near[i].index, s.sums[i]});
    }
  append_by_bucket(*out_.partials, &partial, [&](const PartialCluster& c) { return c.centre / cluster_span; });
  if (!out_.attributes.empty()) hand_on_attribute_shares(a, f, s);
  // The triangles decided here go to the same buckets as the stitch's, so that
  // the output-sized list of kept triangles is built once, at its exact size,
  // instead of growing (and being copied) in the heap tile by tile.
  dedupe_kept_triangles(s.kept);
  append_by_bucket(*out_.inside, &s.kept, [&](const KeptTriangle& k) { return k.index() / bucket_span; });
}

// The tile's shares of its clusters' attribute sums (AttributeLayout), in fixed point
// like the quadric sums, so that merging shares in any order gives the same sums;
// appended by centre index, a run per cluster bucket.
void TileAccumulation::hand_on_attribute_shares(const AssignedTile& a, const FaceSums& f, const Scratch& s) const {
  const AttributeLayout& layout = out_.attributes;
  const std::vector<GradedVertex>& near = a.near;
  const std::size_t width = layout.width();
  std::vector<Fixed> sums(near.size() * width);
  const auto add_fixed = [](Fixed& sum, double term) { sum.add(Fixed::of(term)); };
  for (std::size_t i = 0; i < s.owned.size(); ++i)
    layout.add_vertex(&sums[a.cluster_of[i] * width], *settings_.attributes, s.owned[i].index, f.vertex_weight[i],
                      add_fixed);
  std::vector<std::pair<std::uint64_t, std::size_t>> order;  // (bucket, cluster in near)
  for (std::size_t c = 0; c < near.size(); ++c)
    if (sums[c * width + 1].v != 0) order.push_back({near[c].index / out_.cluster_span, c});  // it has members
  std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<std::int64_t> records;
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    records.clear();
    for (; j < order.size() && order[j].first == order[i].first; ++j) {
      const std::size_t c = order[j].second;
      records.push_back(std::int64_t(near[c].index));
      for (std::size_t k = 0; k < width; ++k) records.push_back(sums[c * width + k].v);
    }
    out_.attribute_shares->append(std::uint32_t(order[i].first), records.data(), j - i);
    i = j;
  }
}

// Every tile once, in parallel. Between tiles a thread keeps at most half its part of
// the tiles' share in its scratch (the buffers of an outsized tile are freed after
// it), and the gate lets the tiles in work take the other half, so the two stay
// within the share.
void accumulate_tiles(const TileAccumulation& accumulation, const BinnedTiles& tiles,
                      const AccumulationSettings& settings, ProgressPhase& phase) {
  const std::uint64_t work_share = settings.work_share;
  tbb::enumerable_thread_specific<Scratch> scratches;
  const std::uint64_t threads = std::uint64_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  const std::uint64_t kept_scratch = work_share / 2 / threads;
  TileMemoryGate gate(work_share - kept_scratch * threads, settings.budget, settings.release_memory);
  tbb::parallel_for(std::uint32_t(0), tiles.count(), [&](std::uint32_t tile) {
    if (settings.only && !settings.only->owns(tile)) {
      phase.advance(1);
      return;
    }
    gate.run(tiles.triangles->record_count(tile) * kTileBytesPerRecord, [&] {
      Scratch& scratch = scratches.local();
      accumulation.run(tile, scratch);
      if (scratch.bytes() > kept_scratch) scratch = Scratch();
    });
    phase.advance(1);
  });
}

}  // namespace

void flush_shares(ClusterShares* out) {
  out->corners->flush();
  out->partials->flush();
  out->inside->flush();
  if (out->attribute_shares) out->attribute_shares->flush();
  if (out->edge_shares) out->edge_shares->flush();
}

ClusterShares accumulate_clusters(const BinnedTiles& tiles, const PositionArray& positions, const BlockStore& blocks,
                                  const TileBorders& borders, std::uint64_t vertex_count,
                                  const AccumulationSettings& settings) {
  ClusterShares out;
  open_triangle_buckets(tiles.triangle_count, settings.spill, settings.memory_budget, &out);
  open_cluster_buckets(vertex_count, settings, &out);
  const ProgressCallback none;
  ProgressPhase phase(settings.progress ? *settings.progress : none, "cluster tiles", tiles.count(), "tile");
  const TileAccumulation accumulation(tiles, positions, blocks, borders, settings, out);
  accumulate_tiles(accumulation, tiles, settings, phase);
  flush_shares(&out);
  return out;
}

std::size_t share_record_bytes(ShareKind kind, const AttributeLayout& layout) {
  switch (kind) {
    case ShareKind::partial:
      return sizeof(PartialCluster);
    case ShareKind::inside:
      return sizeof(KeptTriangle);
    case ShareKind::corner:
      return sizeof(CornerRecord);
    case ShareKind::attribute:
      return attribute_record_bytes(layout);
  }
  return 0;
}

ClusterShares open_cluster_shares(std::uint64_t triangle_count, std::uint64_t vertex_count,
                                  const AccumulationSettings& settings) {
  ClusterShares out;
  AccumulationSettings s = settings;
  s.thick_edges = false;
  open_triangle_buckets(triangle_count, s.spill, s.memory_budget, &out);
  open_cluster_buckets(vertex_count, s, &out);
  return out;
}

namespace {

// The bucket of each record, as accumulate_clusters appends it.
template <class Record, class Key>
void add_by_key(StreamSpill* spill, std::uint64_t span, const void* records, std::size_t count, const Key& key,
                const std::string& where) {
  std::vector<Record> r(count);
  if (count) std::memcpy(r.data(), records, count * sizeof(Record));
  for (const Record& x : r)
    if (key(x) / span >= spill->stream_count())
      throw InputError(where + ": a cluster share names an index beyond the input");
  append_by_bucket(*spill, &r, [&](const Record& x) { return key(x) / span; });
}

}  // namespace

void add_share_records(ClusterShares* shares, ShareKind kind, const void* records, std::size_t count,
                       const std::string& where) {
  constexpr std::uint64_t kTriangleBits = (std::uint64_t(1) << KeptTriangle::kOrderShift) - 1;
  switch (kind) {
    case ShareKind::partial:
      add_by_key<PartialCluster>(
          shares->partials.get(), shares->cluster_span, records, count,
          [](const PartialCluster& p) { return p.centre; }, where);
      return;
    case ShareKind::inside:
      add_by_key<KeptTriangle>(
          shares->inside.get(), shares->bucket_span, records, count,
          [](const KeptTriangle& k) { return k.t_and_order & kTriangleBits; }, where);
      return;
    case ShareKind::corner:
      add_by_key<CornerRecord>(
          shares->corners.get(), shares->bucket_span, records, count,
          [](const CornerRecord& c) { return c.t_and_slot >> 2; }, where);
      return;
    case ShareKind::attribute: {
      if (!shares->attribute_shares) throw InputError(where + ": attribute shares for an input without attributes");
      // A record: the centre's index, then the layout's fixed-point sums. A part
      // hands them on by its own buckets, so runs of one bucket go in one append.
      const std::size_t bytes = attribute_record_bytes(shares->attributes);
      const auto* at = static_cast<const unsigned char*>(records);
      const auto bucket = [&](std::size_t i) {
        std::uint64_t centre = 0;
        std::memcpy(&centre, at + i * bytes, sizeof centre);
        const std::uint64_t b = centre / shares->cluster_span;
        if (b >= shares->attribute_shares->stream_count())
          throw InputError(where + ": a cluster share names an index beyond the input");
        return std::uint32_t(b);
      };
      for (std::size_t i = 0; i < count;) {
        const std::uint32_t b = bucket(i);
        std::size_t j = i + 1;
        while (j < count && bucket(j) == b) ++j;
        shares->attribute_shares->append(b, at + i * bytes, j - i);
        i = j;
      }
      return;
    }
  }
  throw InputError(where + ": a cluster share of an unknown kind");
}

void for_each_share_run(const ClusterShares& shares,
                        const std::function<void(ShareKind, const void*, std::size_t)>& f) {
  const std::pair<ShareKind, const StreamSpill*> spills[] = {{ShareKind::partial, shares.partials.get()},
                                                             {ShareKind::inside, shares.inside.get()},
                                                             {ShareKind::corner, shares.corners.get()},
                                                             {ShareKind::attribute, shares.attribute_shares.get()}};
  for (const auto& [kind_of, spill] : spills) {
    if (!spill) continue;
    const ShareKind kind = kind_of;  // a lambda may not capture a structured binding in C++17 (clang refuses)
    for (std::uint32_t stream = 0; stream < spill->stream_count(); ++stream)
      spill->for_each_block(stream, [&](const void* records, std::size_t n) { f(kind, records, n); });
  }
}

}  // namespace oocsimp
