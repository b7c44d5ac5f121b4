// The parallel first step of quadric edge collapse on large meshes: tiles of the mesh
// collapse on their own, their borders locked, then the whole mesh (collapse_edges).
//
// A collapse changes only the faces around its edge, so collapses whose faces lie in
// different tiles do not meet: each tile runs the same collapse on its own faces,
// with every vertex that has a face in another tile locked (it neither moves nor goes),
// so each tile sees all the faces around every edge it may collapse. The tiles come
// from the mesh alone (faces in Morton order of their centroids, cut every
// tile_faces), never from the thread count, and are joined in tile order: the result
// is the same for any number of threads.
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/vec3_math.hpp"
#include "refine/edge_collapse.hpp"

namespace oocsimp {

namespace {

constexpr std::uint32_t kNoTile = ~std::uint32_t(0);
constexpr std::uint32_t kBorder = kNoTile - 1;

// Spreads the low 10 bits of x to every third bit.
std::uint64_t spread(std::uint64_t x) {
  x &= 0x3FF;
  x = (x | (x << 16)) & 0x30000FF;
  x = (x | (x << 8)) & 0x300F00F;
  x = (x | (x << 4)) & 0x30C30C3;
  x = (x | (x << 2)) & 0x9249249;
  return x;
}

// Each face's tile: the faces' centroids fall in the cells of a 64^3 grid over the
// bounding box; the cells, in Morton order, are cut into runs of about `per_tile`
// faces. Returns the tile count.
std::uint32_t assign_tiles(const QuadricMesh& m, const CollapseState& state, std::uint64_t per_tile,
                           std::vector<std::uint32_t>* tile_of_face) {
  constexpr int kBits = 6;
  constexpr std::uint32_t kSide = 1u << kBits;
  const std::size_t faces = m.triangles.size() / 3;
  Box3d box;
  for (std::size_t f = 0; f < faces; ++f)
    if (state.face_alive(std::uint32_t(f))) box.add(m.positions[m.triangles[3 * f]]);
  const Vec3d size = box.max - box.min;
  const double extent = std::max({size.x, size.y, size.z, 1e-300});
  auto cell = [&](std::size_t f) {
    const std::uint32_t* t = &m.triangles[3 * f];
    const Vec3d c = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.0;
    auto axis = [&](double x, double lo) {
      const double u = (x - lo) / extent * kSide;
      return std::uint64_t(std::clamp(u, 0.0, double(kSide - 1)));
    };
    return spread(axis(c.x, box.min.x)) | spread(axis(c.y, box.min.y)) << 1 | spread(axis(c.z, box.min.z)) << 2;
  };
  std::vector<std::uint32_t> cell_of(faces);
  std::vector<std::uint64_t> count(std::size_t(kSide) * kSide * kSide, 0);
  for (std::size_t f = 0; f < faces; ++f) {
    if (!state.face_alive(std::uint32_t(f))) continue;
    cell_of[f] = std::uint32_t(cell(f));
    ++count[cell_of[f]];
  }
  std::vector<std::uint32_t> tile_of_cell(count.size());
  std::uint32_t tile = 0;
  std::uint64_t filled = 0;
  for (std::size_t c = 0; c < count.size(); ++c) {
    tile_of_cell[c] = tile;
    filled += count[c];
    if (filled >= per_tile) tile++, filled = 0;
  }
  tile_of_face->assign(faces, kNoTile);
  for (std::size_t f = 0; f < faces; ++f)
    if (state.face_alive(std::uint32_t(f))) (*tile_of_face)[f] = tile_of_cell[cell_of[f]];
  return tile + (filled > 0);
}

// What one tile hands back: its faces after its collapses, in global vertex numbers,
// and its surviving vertices' new positions, quadrics and attributes.
struct TileResult {
  QuadricMesh mesh;                   // local numbering
  std::vector<std::uint32_t> global;  // per local vertex, its global index
  CollapseStats stats;
};

TileResult collapse_tile(const CollapseState& state, const std::vector<std::uint32_t>& faces,
                         const std::vector<std::uint32_t>& vertex_tile, const CollapseSettings& settings,
                         std::vector<std::uint32_t>* local_of) {
  const QuadricMesh& m = state.mesh();
  const std::size_t k = m.attribute_count;
  TileResult r;
  QuadricMesh sub;
  sub.attribute_count = k;
  std::vector<std::uint32_t>& global = r.global;
  global.reserve(3 * faces.size());
  for (std::uint32_t f : faces)
    for (int j = 0; j < 3; ++j) global.push_back(m.triangles[3 * std::size_t(f) + std::size_t(j)]);
  std::sort(global.begin(), global.end());
  global.erase(std::unique(global.begin(), global.end()), global.end());
  // Each vertex's local number, in the thread's array over all vertices: only this
  // tile's entries are written and read.
  if (local_of->size() < m.positions.size()) local_of->resize(m.positions.size());
  const std::size_t n = global.size();
  sub.positions.resize(n);
  sub.quadrics.resize(n);
  sub.attributes.resize(n * k);
  sub.locked.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t v = global[i];
    (*local_of)[v] = std::uint32_t(i);
    sub.positions[i] = m.positions[v];
    sub.quadrics[i] = m.quadrics[v];
    std::copy(m.attributes.begin() + std::ptrdiff_t(v * k), m.attributes.begin() + std::ptrdiff_t((v + 1) * k),
              sub.attributes.begin() + std::ptrdiff_t(i * k));
    // A seam's vertex collapses only with its mirror: held unless both are this tile's.
    const std::uint32_t mirror = state.mirror(v);
    sub.locked[i] = vertex_tile[v] == kBorder || state.locked(v) ||
                    (mirror != CollapseState::kNoMirror && vertex_tile[mirror] != vertex_tile[v]);
  }
  sub.triangles.resize(3 * faces.size());
  sub.face_normals.resize(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const std::size_t f = faces[i];
    for (std::size_t j = 0; j < 3; ++j) sub.triangles[3 * i + j] = (*local_of)[m.triangles[3 * f + j]];
    sub.face_normals[i] = state.first_normals()[f];
  }
  CollapseState tile(std::move(sub), settings);
  collapse_state(tile, settings, &r.stats, nullptr);
  std::vector<std::uint32_t> sources;
  r.mesh = tile.result(&sources);
  for (std::uint32_t& s : sources) s = global[s];
  global = std::move(sources);
  return r;
}

}  // namespace

QuadricMesh collapse_tiles(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats) {
  const QuadricMesh& m = state.mesh();
  const std::size_t face_count = m.triangles.size() / 3;
  std::vector<std::uint32_t> tile_of_face;
  const std::uint32_t tiles = assign_tiles(m, state, settings.tile_faces, &tile_of_face);
  // A vertex with faces in two tiles is on a border.
  std::vector<std::uint32_t> vertex_tile(m.positions.size(), kNoTile);
  std::vector<std::vector<std::uint32_t>> faces_of(tiles);
  for (std::uint32_t f = 0; f < face_count; ++f) {
    const std::uint32_t t = tile_of_face[f];
    if (t == kNoTile) continue;
    faces_of[t].push_back(f);
    for (int j = 0; j < 3; ++j) {
      std::uint32_t& vt = vertex_tile[m.triangles[3 * std::size_t(f) + std::size_t(j)]];
      vt = vt == kNoTile || vt == t ? t : kBorder;
    }
  }
  CollapseSettings per_tile = settings;
  per_tile.exact_count = false;
  per_tile.boundary_weight = 0;  // in the quadrics already
  per_tile.tile_faces = 0;
  per_tile.pass_share = 1;      // a tile needs no strict order at its end: its count is approximate
  per_tile.work_ahead = false;  // the tiles keep the threads busy

  const double share = std::min(1.0, settings.tile_share * double(settings.target_triangles) / double(face_count));
  std::vector<TileResult> results(tiles);
  tbb::enumerable_thread_specific<std::vector<std::uint32_t>> local_of;
  tbb::parallel_for(std::uint32_t(0), tiles, [&](std::uint32_t t) {
    CollapseSettings s = per_tile;
    s.target_triangles = std::uint64_t(std::ceil(share * double(faces_of[t].size())));
    results[t] = collapse_tile(state, faces_of[t], vertex_tile, s, &local_of.local());
    std::vector<std::uint32_t>().swap(faces_of[t]);
  });
  // The tiles' faces, in tile order, over the whole mesh's vertices.
  QuadricMesh out = state.release_vertices();
  const std::size_t k = out.attribute_count;
  for (const TileResult& r : results) {
    for (std::size_t i = 0; i < r.global.size(); ++i) {
      const std::uint32_t g = r.global[i];
      out.positions[g] = r.mesh.positions[i];
      out.quadrics[g] = r.mesh.quadrics[i];
      std::copy(r.mesh.attributes.begin() + std::ptrdiff_t(i * k),
                r.mesh.attributes.begin() + std::ptrdiff_t((i + 1) * k),
                out.attributes.begin() + std::ptrdiff_t(g * k));
    }
    for (std::uint32_t v : r.mesh.triangles) out.triangles.push_back(r.global[v]);
    out.face_normals.insert(out.face_normals.end(), r.mesh.face_normals.begin(), r.mesh.face_normals.end());
    stats->collapses += r.stats.collapses;
    stats->largest_cost = std::max(stats->largest_cost, r.stats.largest_cost);
    stats->largest_error = std::max(stats->largest_error, r.stats.largest_error);
  }
  return out;
}

}  // namespace oocsimp
