// A mesh in the caller's memory as a MeshInput: the position and attribute views
// point into the caller's arrays, and the triangle stream reads its index array.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "api/simplify.hpp"
#include "io/attribute_array.hpp"
#include "io/position_array.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/simplify.hpp"

namespace oocsimp {

namespace {

constexpr const char* kMemoryName = "mesh in memory";

class MemoryTriangleStream : public TriangleStream {
 public:
  MemoryTriangleStream(const std::uint32_t* indices, std::uint64_t triangles, std::uint64_t vertices)
      : indices_(indices), triangles_(triangles), vertices_(vertices) {}

  std::size_t read(std::uint64_t* out, std::size_t max_triangles) override {
    const std::size_t n = std::size_t(std::min<std::uint64_t>(max_triangles, triangles_ - next_));
    for (std::size_t t = 0; t < n; ++t)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = indices_[3 * (next_ + t) + std::uint64_t(k)];
        if (v >= vertices_)
          throw InputError(std::string(kMemoryName) + ": triangle " + std::to_string(next_ + t) + " names vertex " +
                           std::to_string(v) + " of " + std::to_string(vertices_));
        out[3 * t + std::size_t(k)] = v;
      }
    next_ += n;
    return n;
  }
  std::uint64_t bytes_consumed() const override { return next_ * 3 * sizeof(std::uint32_t); }

 private:
  const std::uint32_t* indices_;
  std::uint64_t triangles_, vertices_, next_ = 0;
};

}  // namespace

MeshInput open_mesh_view(const MeshView& mesh, const AttributeSelection& selection) {
  if (mesh.vertex_count > 0 && !mesh.positions)
    throw UsageError(std::string(kMemoryName) + ": " + std::to_string(mesh.vertex_count) +
                     " vertices but no positions");
  if (mesh.triangle_count > 0 && !mesh.indices)
    throw UsageError(std::string(kMemoryName) + ": " + std::to_string(mesh.triangle_count) +
                     " triangles but no indices");
  MeshInput in;
  in.info.path = kMemoryName;
  in.info.format = "memory";
  in.info.vertex_count = mesh.vertex_count;
  in.info.face_count = mesh.triangle_count;
  in.info.positions_in_place = true;
  const std::size_t scalar = mesh.position_type == ScalarType::f64 ? sizeof(double) : sizeof(float);
  PositionArray& pa = in.positions;
  pa.base = static_cast<const unsigned char*>(mesh.positions);
  pa.count = mesh.vertex_count;
  pa.stride = mesh.position_stride ? mesh.position_stride : 3 * scalar;
  for (int k = 0; k < 3; ++k) pa.offset[k] = std::size_t(k) * scalar;
  pa.type = mesh.position_type;
  pa.swap = false;
  scan_positions(in);
  if (in.info.non_finite_vertices > 0)
    in.info.first_non_finite_position = "vertex " + std::to_string(in.info.first_non_finite_vertex);
  in.info.double_precision = mesh.position_type == ScalarType::f64;
  std::vector<AttributeCandidate> offered;
  for (const VertexAttribute& a : mesh.attributes.attributes) offered.push_back({a.name, a.type});
  for (std::size_t k : carried_attributes(offered, selection, kMemoryName, &in.info.not_carried))
    in.attributes.add(mesh.attributes.attributes[k], mesh.attributes.base[k], mesh.attributes.stride[k]);
  in.attributes.count = mesh.vertex_count;
  in.attributes.swap = false;
  scan_attribute_ranges(in.attributes);
  in.file_size = mesh.triangle_count * 3 * sizeof(std::uint32_t);
  const std::uint32_t* indices = mesh.indices;
  const std::uint64_t triangles = mesh.triangle_count, vertices = mesh.vertex_count;
  reader_state(in).make_triangles = [indices, triangles, vertices]() -> std::unique_ptr<TriangleStream> {
    return std::make_unique<MemoryTriangleStream>(indices, triangles, vertices);
  };
  in.restart_triangles();
  return in;
}

SimplifiedMesh simplify_mesh(const MeshView& mesh, const SimplifyOptions& options, SimplifyStats* stats) {
  AttributeSelection selection = options.attributes;
  selection.texture_coordinates = resolved_method(options) == ClusterMethod::qem;
  MeshInput in = open_mesh_view(mesh, selection);
  if (!mesh.vertex_lock) return simplify(in, options, stats);
  SimplifyOptions locked = options;
  for (std::uint64_t v = 0; v < mesh.vertex_count; ++v)
    if (mesh.vertex_lock[v]) locked.locked_vertices.push_back(v);
  return simplify(in, locked, stats);
}

}  // namespace oocsimp
