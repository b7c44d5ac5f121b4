#include "curvature/tiled_curvatures.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "common/vec3_math.hpp"
#include "grid/tile_grid.hpp"
#include "oocsimp/error.hpp"
#include "runtime/progress_phase.hpp"
#include "spill/stream_spill.hpp"

namespace oocsimp {

namespace {

constexpr std::size_t kChunkTriangles = 65536;

// A triangle as a tile holds it: its index in the input and its corners.
struct TileTriangle {
  std::uint64_t index;
  std::uint64_t v[3];
};

bool finite(const Vec3d& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// How far beyond its tile a vertex's estimate reads: the faces whose bounding spheres
// meet the height field's ball (each within its reach plus a face's size of the
// vertex), and the faces around their corners (another face's size), for the
// outline test.
double halo_of(const TiledCurvatureSettings& s) {
  return LocalHeightField::kHeightFieldReach * s.vertex.radius + 2 * s.longest_edge;
}

// Bytes of the spill's bookkeeping per occupied tile while the faces are binned: the
// stream's buffer (at least 16 records of 32 bytes), its state and the tile's entry.
constexpr std::uint64_t kSpillBytesPerTile = 768;

// At side `side`: the most vertices any tile and its halo hold (bounded by the tiles
// within the halo's reach around it; 0 when there are none), and the occupied tiles.
struct TileFill {
  std::uint64_t fullest = 0;
  std::uint64_t tiles = 0;
};
TileFill tile_fill(const MeshInput& input, double side, double halo) {
  std::unordered_map<GridCoord, std::uint64_t, GridCoordHash> count;
  for (std::uint64_t v = 0; v < input.positions.count; ++v) {
    const Vec3d p = input.positions.get(v);
    if (finite(p)) ++count[GridCoord::of(p, side)];
  }
  const std::int64_t reach = std::int64_t(std::ceil(halo / side));
  TileFill fill;
  fill.tiles = count.size();
  for (const auto& [c, own] : count) {
    std::uint64_t sum = 0;
    for (std::int64_t dz = -reach; dz <= reach; ++dz)
      for (std::int64_t dy = -reach; dy <= reach; ++dy)
        for (std::int64_t dx = -reach; dx <= reach; ++dx) {
          auto it = count.find(GridCoord{c.x + dx, c.y + dy, c.z + dz});
          if (it != count.end()) sum += it->second;
        }
    fill.fullest = std::max(fill.fullest, sum);
  }
  return fill;
}

std::string mib(std::uint64_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MiB"; }

}  // namespace

MeshSurvey survey_mesh(MeshInput& input, const ProgressCallback& progress) {
  ProgressPhase phase(progress, "survey", input.file_size, "B");
  MeshSurvey s;
  double sum = 0;
  std::uint64_t sides = 0;
  std::vector<std::uint64_t> buffer(3 * kChunkTriangles);
  while (const std::size_t n = input.triangles->read(buffer.data(), kChunkTriangles)) {
    for (std::size_t t = 0; t < n; ++t) {
      const Vec3d p[3] = {input.positions.get(buffer[3 * t]), input.positions.get(buffer[3 * t + 1]),
                          input.positions.get(buffer[3 * t + 2])};
      for (int k = 0; k < 3; ++k) {
        const double l = distance(p[k], p[(k + 1) % 3]);
        if (!std::isfinite(l)) continue;
        sum += l;
        ++sides;
        s.longest_edge = std::max(s.longest_edge, l);
      }
    }
    s.triangles += n;
    phase.set(input.triangles->bytes_consumed());
  }
  input.restart_triangles();
  s.mean_edge_length = sides ? sum / double(sides) : 0;
  return s;
}

std::uint64_t tile_bytes_per_vertex(unsigned threads) {
  // At two faces a vertex: the records (2 x 32) and, while they are sorted into
  // the tile's vertices, their corners' global indices (2 x 3 x 8); the position 24,
  // the own list 4, the corners (2 x 12), the faces' shapes (2 x 56), the faces
  // around each vertex (start 4, 6 faces x 4), the outline flag 1, the results 8; and
  // each thread's marks and slots of vertices and marks of faces (4 + 4 + 2 x 4).
  return 2 * 32 + 2 * 3 * 8 + 24 + 4 + 2 * 12 + 2 * 56 + (4 + 6 * 4) + 1 + 8 + std::uint64_t(threads) * 16;
}

double curvature_tile_side(const MeshInput& input, const TiledCurvatureSettings& settings, unsigned threads) {
  if (settings.tile_side > 0) return settings.tile_side;
  const double halo = halo_of(settings);
  const Box3d& b = input.info.bounds;
  const double extent = b.empty() ? 0 : std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z});
  // Half the budget for the tile in work; a quarter for the spill, of which half for
  // the tiles' buffers while binning.
  const std::uint64_t share = settings.memory_budget / 2, bookkeeping = settings.memory_budget / 8;
  double side = std::max(extent, halo);
  if (!(side > 0)) return 1;
  for (;;) {
    const TileFill fill = tile_fill(input, side, halo);
    const std::uint64_t bytes = fill.fullest * tile_bytes_per_vertex(threads);
    const std::uint64_t tile_bytes = fill.tiles * kSpillBytesPerTile;
    if (bytes <= share && tile_bytes <= bookkeeping) return side;
    // Tiles smaller than their halo hold mostly halo, and ever more tiles cost more
    // bookkeeping than they save: the budget is too small. This side would do with
    // the budget named.
    if (side / 2 < halo || tile_bytes > bookkeeping)
      throw UsageError("options.memory_budget",
                       "options.memory_budget " + mib(settings.memory_budget) +
                           " cannot hold a tile of the curvature estimate and its halo (radius " +
                           std::to_string(settings.vertex.radius) + ") next to the " + std::to_string(fill.tiles) +
                           " tiles' bookkeeping: give at least " + mib(std::max(2 * bytes, 8 * tile_bytes)));
    side /= 2;
  }
}

VertexCurvatureCounts tiled_vertex_curvatures(MeshInput& input, const TiledCurvatureSettings& settings, double side,
                                              float* k) {
  const VertexCurvatureCounts counts = tiled_vertex_curvatures(
      input, settings, side, nullptr,
      [k](const std::vector<std::uint64_t>& vertices, const std::vector<float>& k1, const std::vector<float>& k2) {
        for (std::size_t i = 0; i < vertices.size(); ++i) {
          k[2 * vertices[i]] = k1[i];
          k[2 * vertices[i] + 1] = k2[i];
        }
      });
  // Vertices in no face, or at non-finite positions, were in no tile's estimate.
  VertexCurvatureCounts total = counts;
  total.none = input.positions.count - total.invariant - total.fitted;
  return total;
}

VertexCurvatureCounts tiled_vertex_curvatures(MeshInput& input, const TiledCurvatureSettings& settings, double side,
                                              const VertexFilter& wanted, const TileValuesSink& sink) {
  const double halo = halo_of(settings);
  // The tiles: those holding a vertex, numbered in vertex order; only those holding a
  // wanted vertex are estimated.
  TileGrid grid;
  grid.side = side;
  std::vector<char> estimated;
  for (std::uint64_t v = 0; v < input.positions.count; ++v) {
    const Vec3d p = input.positions.get(v);
    if (!finite(p)) continue;
    std::int64_t tile = grid.find(grid.of(p));
    if (tile < 0) {
      tile = std::int64_t(grid.count());
      grid.add(grid.of(p));
      estimated.push_back(0);
    }
    if (!wanted || wanted(p)) estimated[std::size_t(tile)] = 1;
  }
  // Each triangle into every tile its box, widened by the halo, meets.
  const std::uint64_t spill_memory = settings.memory_budget / 4;
  const std::size_t buffer_records = std::clamp<std::size_t>(
      std::size_t(spill_memory / 2 / std::max<std::uint64_t>(1, grid.count()) / sizeof(TileTriangle)), 16, 4096);
  StreamSpill spill(settings.temp_dir, "curvature", sizeof(TileTriangle), buffer_records, true, spill_memory / 2);
  for (std::uint32_t t = 0; t < grid.count(); ++t) spill.add_stream();
  std::vector<std::uint64_t> buffer(3 * kChunkTriangles);
  std::uint64_t index = 0;
  {
    ProgressPhase bin_phase(settings.progress, "bin tiles", input.file_size, "B");
    while (const std::size_t n = input.triangles->read(buffer.data(), kChunkTriangles)) {
      bin_phase.set(input.triangles->bytes_consumed());
      for (std::size_t t = 0; t < n; ++t, ++index) {
        const TileTriangle record{index, {buffer[3 * t], buffer[3 * t + 1], buffer[3 * t + 2]}};
        Box3d box;
        for (std::uint64_t v : record.v) {
          const Vec3d p = input.positions.get(v);
          if (finite(p)) box.add(p);
        }
        if (box.empty()) continue;
        const GridCoord lo = grid.of(box.min - Vec3d{halo, halo, halo}),
                        hi = grid.of(box.max + Vec3d{halo, halo, halo});
        const double cells = double(hi.x - lo.x + 1) * double(hi.y - lo.y + 1) * double(hi.z - lo.z + 1);
        if (cells > double(grid.count())) {  // a face far larger than the tiles: look at every tile
          for (std::uint32_t id = 0; id < grid.count(); ++id) {
            const GridCoord& c = grid.coord(id);
            if (estimated[id] && c.x >= lo.x && c.x <= hi.x && c.y >= lo.y && c.y <= hi.y && c.z >= lo.z && c.z <= hi.z)
              spill.append(id, &record, 1);
          }
          continue;
        }
        for (std::int64_t z = lo.z; z <= hi.z; ++z)
          for (std::int64_t y = lo.y; y <= hi.y; ++y)
            for (std::int64_t x = lo.x; x <= hi.x; ++x) {
              const std::int64_t id = grid.find(GridCoord{x, y, z});
              if (id >= 0 && estimated[std::size_t(id)]) spill.append(std::uint32_t(id), &record, 1);
            }
      }
    }
  }
  input.restart_triangles();
  spill.flush();  // the streams' buffers go before the tiles' work comes
  // Each tile: its faces as a mesh of their own, its own vertices estimated.
  ProgressPhase phase(settings.progress, "curvatures", settings.estimated_vertices, "vtx");
  VertexCurvatureSettings vertex = settings.vertex;
  vertex.progress = &phase;
  VertexCurvatureCounts total;
  std::vector<TileTriangle> records;
  std::vector<std::uint64_t> own_vertices;
  for (std::uint32_t tile = 0; tile < grid.count(); ++tile) {
    if (!estimated[tile]) continue;
    spill.read(tile, &records);
    std::vector<std::uint64_t> global;
    global.reserve(3 * records.size());
    for (const TileTriangle& r : records) global.insert(global.end(), r.v, r.v + 3);
    std::sort(global.begin(), global.end());
    global.erase(std::unique(global.begin(), global.end()), global.end());
    std::vector<Vec3d> positions(global.size());
    std::vector<std::uint32_t> own;
    for (std::size_t i = 0; i < global.size(); ++i) {
      positions[i] = input.positions.get(global[i]);
      if (finite(positions[i]) && grid.of(positions[i]) == grid.coord(tile) && (!wanted || wanted(positions[i])))
        own.push_back(std::uint32_t(i));
    }
    std::vector<std::uint32_t> triangles;
    triangles.reserve(3 * records.size());
    for (const TileTriangle& r : records)
      for (std::uint64_t v : r.v)
        triangles.push_back(std::uint32_t(std::lower_bound(global.begin(), global.end(), v) - global.begin()));
    std::vector<TileTriangle>().swap(records);
    std::vector<float> k1, k2;
    const VertexCurvatureCounts c = vertex_curvatures_of(positions, triangles, vertex, own, &k1, &k2);
    own_vertices.resize(own.size());
    for (std::size_t i = 0; i < own.size(); ++i) own_vertices[i] = global[own[i]];
    sink(own_vertices, k1, k2);
    total.invariant += c.invariant;
    total.fitted += c.fitted;
    total.none += c.none;
  }
  return total;
}

}  // namespace oocsimp
