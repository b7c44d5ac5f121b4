#include "refine/pass_tile.hpp"

#include <algorithm>
#include <utility>

namespace oocsimp {

namespace {

// The tile's vertices, numbered in ascending id: every corner of its faces.
std::vector<std::uint64_t> tile_vertex_ids(const TileMesh& tile) {
  std::vector<std::uint64_t> ids;
  ids.reserve(3 * tile.faces.size());
  for (const PassFace& f : tile.faces) ids.insert(ids.end(), f.v, f.v + 3);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

std::uint32_t local_of(const std::vector<std::uint64_t>& ids, std::uint64_t id) {
  return std::uint32_t(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin());
}

// The tile as a mesh for the collapse: owned vertices free unless a face of theirs
// reaches another tile, every other vertex locked.
QuadricMesh local_mesh(const TileMesh& tile, const std::vector<std::uint64_t>& ids, std::vector<std::uint8_t>* owned) {
  const std::size_t n = ids.size(), k = tile.attribute_count;
  QuadricMesh m;
  m.positions.resize(n);
  m.quadrics.resize(n);
  m.attribute_count = k;
  m.attributes.assign(n * k, 0.0);
  m.locked.assign(n, 1);
  owned->assign(n, 0);
  if (!tile.hold_border) m.locked.assign(n, 0);
  for (std::size_t i = 0; i < tile.owned.size(); ++i) {
    const std::uint32_t l = local_of(ids, tile.owned[i].id);
    (*owned)[l] = 1;
    m.locked[l] = 0;
    m.positions[l] = tile.owned[i].position;
    m.quadrics[l] = tile.owned[i].quadric;
    std::copy(tile.attributes.begin() + std::ptrdiff_t(i * k), tile.attributes.begin() + std::ptrdiff_t((i + 1) * k),
              m.attributes.begin() + std::ptrdiff_t(l * k));
  }
  m.triangles.resize(3 * tile.faces.size());
  m.face_normals.resize(tile.faces.size());
  for (std::size_t f = 0; f < tile.faces.size(); ++f) {
    const PassFace& face = tile.faces[f];
    std::uint32_t l[3];
    for (int c = 0; c < 3; ++c) {
      l[c] = local_of(ids, face.v[c]);
      m.triangles[3 * f + std::size_t(c)] = l[c];
      if (!(*owned)[l[c]]) m.positions[l[c]] = face.p[c];
    }
    m.face_normals[f] = face.normal;
    // A face reaching another tile: its owned corners stay where they are.
    if (tile.hold_border && (!(*owned)[l[0]] || !(*owned)[l[1]] || !(*owned)[l[2]]))
      for (std::uint32_t c : l) m.locked[c] = 1;
  }
  // The first pass sums the quadrics from the faces: every face around an owned vertex
  // is here, so its quadric is whole (the others' are partial, and never used).
  if (tile.first_pass) m.quadrics = face_quadrics(m.positions, m.triangles);
  return m;
}

}  // namespace

TileOutput collapse_pass_tile(const TileMesh& tile, const CollapseSettings& settings, std::vector<double>* cost_log) {
  const std::vector<std::uint64_t> ids = tile_vertex_ids(tile);
  std::vector<std::uint8_t> owned;
  CollapseSettings s = settings;
  s.exact_count = false;
  s.tile_faces = 0;
  // Boundary planes join the quadrics once, in the first pass: a boundary edge of an
  // owned vertex has all its faces here, so its count of faces is the mesh's.
  if (!tile.first_pass || !tile.hold_border) s.boundary_weight = 0;
  CollapseState state(local_mesh(tile, ids, &owned), s);
  TileOutput out;
  out.stats.cost_log = cost_log;
  collapse_state(state, s, &out.stats, nullptr);
  out.stats.cost_log = nullptr;

  const QuadricMesh& m = state.mesh();
  for (std::size_t f = 0; f < tile.faces.size(); ++f) {
    if (!state.face_alive(std::uint32_t(f))) continue;
    const std::uint32_t* t = &m.triangles[3 * f];
    if (!owned[t[0]]) continue;  // another tile's to give out
    PassFace face = tile.faces[f];
    for (int c = 0; c < 3; ++c) {
      face.v[c] = ids[t[c]];
      face.p[c] = m.positions[t[c]];
    }
    out.faces.push_back(face);
  }
  const std::size_t k = tile.attribute_count;
  for (std::size_t l = 0; l < ids.size(); ++l) {
    if (!owned[l] || !state.alive(std::uint32_t(l))) continue;
    out.owned.push_back({ids[l], m.positions[l], m.quadrics[l]});
    out.attributes.insert(out.attributes.end(), m.attributes.begin() + std::ptrdiff_t(l * k),
                          m.attributes.begin() + std::ptrdiff_t((l + 1) * k));
  }
  return out;
}

}  // namespace oocsimp
