// Per-vertex normals of the output (--normals): area-weighted face normals.
#include <utility>

#include "io/output_mesh.hpp"
#include "oocsimp/formats.hpp"

namespace oocsimp {

void add_vertex_normals(SimplifiedMesh* mesh) {
  OutputMesh m = OutputMesh::of(std::move(*mesh));
  add_vertex_normals(&m, ArrayPlace());
  *mesh = m.take();
}

}  // namespace oocsimp
