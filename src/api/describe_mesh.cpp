// describe_mesh: what `oocsimp info` prints about a mesh file, gathered through the
// reader so that a program need not hold a MeshInput.
#include <algorithm>
#include <vector>

#include "io/mesh_input.hpp"
#include "runtime/progress_phase.hpp"
#include "oocsimp/formats.hpp"

namespace oocsimp {

namespace {

void add(PrimitiveTally* t, float thickness) {
  ++t->count;
  t->least = std::min(t->least, double(thickness));
  t->most = std::max(t->most, double(thickness));
  t->sum += thickness;
}

}  // namespace

MeshSummary describe_mesh(const std::string& path, const std::string& temp_dir, const ProgressCallback& progress) {
  OpenOptions open;
  open.temp_dir = temp_dir;
  open.progress = progress;
  // As the edge collapse reads the file: texture coordinates too (OBJ's split at seams).
  open.attributes.texture_coordinates = true;
  MeshInput m = open_mesh_input(path, open);
  MeshSummary s;
  // The thick edges and points come with the triangle stream: it is read through only
  // when the file has some.
  if (m.info.edge_count > 0 || m.info.point_count > 0) {
    ProgressPhase phase(progress, "read edges and points", 0, "B");
    m.triangles->set_primitive_sink([&](const LinePrimitive* p, std::size_t n) {
      for (std::size_t k = 0; k < n; ++k) add(p[k].a == p[k].b ? &s.points : &s.edges, p[k].thickness);
    });
    std::vector<std::uint64_t> chunk(3 * 65536);
    while (m.triangles->read(chunk.data(), 65536) > 0) {
    }
  }
  s.info = m.info;
  s.attributes = m.attributes.attributes;
  return s;
}

}  // namespace oocsimp
