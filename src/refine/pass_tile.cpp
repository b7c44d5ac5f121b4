#include "refine/pass_tile.hpp"

#include <algorithm>
#include <utility>

#include "common/huge_pages.hpp"
#include "common/radix_sort.hpp"

namespace oocsimp {

namespace {

// The tile's vertices, numbered in ascending id: every corner of its faces. `ids`
// gets each local vertex's id, `corners` the local vertex at each face's corners (3
// a face), from one sort of the corners by id.
void number_vertices(const TileMesh& tile, std::vector<std::uint64_t>* ids, std::vector<std::uint32_t>* corners) {
  struct Corner {
    std::uint64_t id;
    std::uint32_t slot;
  };
  std::vector<Corner> sorted;
  resize_filled(&sorted, 3 * tile.faces.size());
  for (std::size_t f = 0; f < tile.faces.size(); ++f)
    for (std::size_t c = 0; c < 3; ++c) sorted[3 * f + c] = {tile.faces[f].v[c], std::uint32_t(3 * f + c)};
  radix_sort(&sorted, [](const Corner& c) { return c.id; });
  ids->clear();
  resize_filled(corners, sorted.size());
  for (const Corner& c : sorted) {
    if (ids->empty() || ids->back() != c.id) ids->push_back(c.id);
    (*corners)[c.slot] = std::uint32_t(ids->size() - 1);
  }
}

// The tile as a mesh for the collapse: owned vertices free unless a face of theirs
// reaches another tile, every other vertex locked.
QuadricMesh local_mesh(const TileMesh& tile, const std::vector<std::uint64_t>& ids,
                       const std::vector<std::uint32_t>& corners, const std::vector<std::uint64_t>* locked_ids,
                       std::vector<std::uint8_t>* owned) {
  const std::size_t n = ids.size(), k = tile.attribute_count;
  QuadricMesh m;
  resize_filled(&m.positions, n);
  // The first pass sums the quadrics from the faces (below); the others take the owned
  // vertices' own.
  if (!tile.first_pass) resize_filled(&m.quadrics, n);
  m.attribute_count = k;
  reserve_filled(&m.attributes, n * k);
  m.attributes.assign(n * k, 0.0);
  m.locked.assign(n, 1);
  owned->assign(n, 0);
  if (!tile.hold_border) m.locked.assign(n, 0);
  // Both lists ascend by id: one walk finds each owned vertex's number (a vertex of
  // no face, were there one, takes no part).
  std::size_t l = 0;
  for (std::size_t i = 0; i < tile.owned.size(); ++i) {
    while (l < n && ids[l] < tile.owned[i].id) ++l;
    if (l == n || ids[l] != tile.owned[i].id) continue;
    (*owned)[l] = 1;
    m.locked[l] = locked_ids && std::binary_search(locked_ids->begin(), locked_ids->end(), ids[l]);
    m.positions[l] = tile.owned[i].position;
    if (!tile.first_pass) m.quadrics[l] = tile.owned[i].quadric;
    std::copy(tile.attributes.begin() + std::ptrdiff_t(i * k), tile.attributes.begin() + std::ptrdiff_t((i + 1) * k),
              m.attributes.begin() + std::ptrdiff_t(l * k));
  }
  resize_filled(&m.triangles, 3 * tile.faces.size());
  resize_filled(&m.face_normals, tile.faces.size());
  for (std::size_t f = 0; f < tile.faces.size(); ++f) {
    const PassFace& face = tile.faces[f];
    const std::uint32_t* v = &corners[3 * f];
    for (int c = 0; c < 3; ++c) {
      m.triangles[3 * f + std::size_t(c)] = v[c];
      if (!(*owned)[v[c]]) m.positions[v[c]] = face.p[c];
    }
    m.face_normals[f] = face.normal;
    // A face reaching another tile: its owned corners stay where they are.
    if (tile.hold_border && (!(*owned)[v[0]] || !(*owned)[v[1]] || !(*owned)[v[2]]))
      for (int c = 0; c < 3; ++c) m.locked[v[c]] = 1;
  }
  // The first pass sums the quadrics from the faces: every face around an owned vertex
  // is here, so its quadric is whole (the others' are partial, and never used). So are
  // the boundary edges of an owned vertex; a boundary loop through another tile's
  // vertex is not seen whole, and stays an outline (CollapseState::hole_edges).
  if (tile.first_pass) {
    m.quadrics = face_quadrics(m.positions, m.triangles);
    m.partial.resize(n);
    for (std::size_t l = 0; l < n; ++l) m.partial[l] = !(*owned)[l];
  }
  return m;
}

}  // namespace

TileOutput collapse_pass_tile(const TileMesh& tile, const CollapseSettings& settings, std::vector<double>* cost_log) {
  std::vector<std::uint64_t> ids;
  std::vector<std::uint32_t> corners;
  number_vertices(tile, &ids, &corners);
  std::vector<std::uint8_t> owned;
  CollapseSettings s = settings;
  s.exact_count = false;
  s.tile_faces = 0;
  s.work_ahead = false;  // the pass's tiles keep the threads busy
  // Boundary planes join the quadrics once, in the first pass: a boundary edge of an
  // owned vertex has all its faces here, so its count of faces is the mesh's.
  if (!tile.first_pass || !tile.hold_border) s.boundary_weight = 0;
  CollapseState state(local_mesh(tile, ids, corners, s.locked_ids, &owned), s);
  std::vector<std::uint32_t>().swap(corners);
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
