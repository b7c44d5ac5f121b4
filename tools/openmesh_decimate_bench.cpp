// Peer benchmark: OpenMesh's Decimater with ModQuadricT, the in-core quadric edge
// collapse (Garland & Heckbert 1997) that exact triangle targets are measured against
// for quality, file to file, on the same input as `oocsimp simplify`. Reads with our
// mmap reader into an OpenMesh TriMesh, decimates to a triangle count, garbage-collects
// and writes a binary PLY of the vertices the triangles use.
//
//   openmesh_decimate_bench IN.ply OUT.ply TARGET_TRIANGLES [--normal-flip DEGREES] [--lock-boundary]
//
// ModQuadricT alone (unset_max_err: non-binary, so its quadric error is the priority
// and no collapse is refused for its error); --normal-flip adds ModNormalFlippingT,
// which refuses a collapse that turns a face normal by more than DEGREES.
//
// OpenMesh's collapses are halfedge collapses: v0 moves onto v1, so vertices keep
// input positions (subset placement) and the quadric error is evaluated at v1, not at
// an optimal point. ModQuadricT sums only the faces' planes, without the constraint
// planes along boundary edges (Garland & Heckbert 1997, "Preserving Boundaries"):
// sliding a boundary vertex within its faces' plane costs nothing, so flat open
// patches lose their outline. The Decimater keeps boundary vertices on the boundary,
// not in place; --lock-boundary locks them all, and they are then never removed.
//
// DecimaterT::decimate_to_faces(0, n) pops collapses until the face count it tracks
// is at most n: an interior collapse removes two faces and a boundary one a single
// face, so it ends at n or n - 1 (always n - 1 on a closed mesh when n is odd, since a
// closed mesh's count stays even); when no legal collapse is left (link condition,
// boundary rules, locked vertices, a binary module's refusal) the heap empties and it
// stops above n. Input faces that add_face rejects (complex edges or vertices) are
// left out and counted.
//
// Prints one line of key-value pairs: seconds (total, load, simplify, write), output
// triangles, peak RSS and peak anonymous RSS in MiB, then the target, the collapses
// done and the rejected input faces. "load" includes building the TriMesh; "simplify"
// includes the Decimater's initialisation (the quadrics) and the garbage collection.
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include "oocsimp/error.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/oocsimp.hpp"
#include "runtime/memory_usage.hpp"

using namespace oocsimp;

namespace {

using Mesh = OpenMesh::TriMesh_ArrayKernelT<>;
using Decimater = OpenMesh::Decimater::DecimaterT<Mesh>;
using ModQuadric = OpenMesh::Decimater::ModQuadricT<Mesh>::Handle;
using ModNormalFlipping = OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle;

int usage(const char* argv0) {
  std::fprintf(stderr, "usage: %s IN OUT TARGET_TRIANGLES [--normal-flip DEGREES] [--lock-boundary]\n", argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) return usage(argv[0]);
  double flip_degrees = 0;
  bool lock_boundary = false;
  for (int i = 4; i < argc; ++i) {
    if (std::strcmp(argv[i], "--normal-flip") == 0 && i + 1 < argc) {
      flip_degrees = std::strtod(argv[++i], nullptr);
    } else if (std::strcmp(argv[i], "--lock-boundary") == 0) {
      lock_boundary = true;
    } else {
      return usage(argv[0]);
    }
  }
  const std::size_t target = std::size_t(std::strtoull(argv[3], nullptr, 10));
  // add_face reports every complex edge on omerr; they are counted below instead, and a
  // scan with many of them would otherwise print a line each.
  omerr().disable();
  try {
    PeakAnonSampler anon;
    double t0 = now_seconds();
    MeshInput in = open_mesh_input(argv[1]);
    Mesh mesh;
    // Edges (about 1.5 per triangle) and faces are reserved so that their arrays do
    // not regrow, copying the largest arrays, on big inputs.
    mesh.reserve(in.positions.count, in.info.face_count * 3 / 2 + 16, in.info.face_count);
    std::vector<Mesh::VertexHandle> vh(in.positions.count);
    for (std::uint64_t i = 0; i < in.positions.count; ++i) {
      Vec3d p = in.positions.get(i);
      vh[i] = mesh.add_vertex(Mesh::Point(float(p.x), float(p.y), float(p.z)));
    }
    std::uint64_t rejected = 0;
    std::vector<std::uint64_t> buf(3 * 65536);
    while (std::size_t n = in.triangles->read(buf.data(), 65536))
      for (std::size_t k = 0; k < n; ++k)
        if (!mesh.add_face(vh[buf[3 * k]], vh[buf[3 * k + 1]], vh[buf[3 * k + 2]]).is_valid()) ++rejected;
    std::vector<Mesh::VertexHandle>().swap(vh);
    double t1 = now_seconds();

    std::size_t collapses = 0;
    {
      // The Decimater holds the status flags that garbage_collection reads, and
      // releases them when it goes.
      Decimater decimater(mesh);
      ModQuadric quadric;
      decimater.add(quadric);
      decimater.module(quadric).unset_max_err();
      ModNormalFlipping flipping;
      if (flip_degrees > 0) {
        decimater.add(flipping);
        decimater.module(flipping).set_max_normal_deviation(flip_degrees);
      }
      if (lock_boundary)
        for (Mesh::VertexHandle v : mesh.vertices())
          if (mesh.is_boundary(v)) mesh.status(v).set_locked(true);
      if (!decimater.initialize()) throw std::runtime_error("the OpenMesh Decimater did not initialise");
      collapses = decimater.decimate_to_faces(0, target);
      mesh.garbage_collection();
    }
    double t2 = now_seconds();

    // Vertices no triangle uses (isolated in the input) are left out, as meshopt_bench
    // and oocsimp do.
    constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> index(mesh.n_vertices(), kUnused);
    std::vector<double> out_pos;
    std::vector<std::uint32_t> tri;
    tri.reserve(3 * mesh.n_faces());
    for (Mesh::FaceHandle f : mesh.faces()) {
      for (Mesh::VertexHandle v : mesh.fv_range(f)) {
        std::uint32_t& id = index[v.idx()];
        if (id == kUnused) {
          id = std::uint32_t(out_pos.size() / 3);
          const Mesh::Point& p = mesh.point(v);
          out_pos.insert(out_pos.end(), {double(p[0]), double(p[1]), double(p[2])});
        }
        tri.push_back(id);
      }
    }
    write_mesh(argv[2], out_pos, tri, MeshFormat::ply_binary);
    double t3 = now_seconds();
    std::printf(
        "seconds %.3f load %.3f simplify %.3f write %.3f triangles %zu peak_rss_mib %.1f peak_anon_mib %.1f "
        "target %zu collapses %zu rejected_faces %" PRIu64 "\n",
        t3 - t0, t1 - t0, t2 - t1, t3 - t2, tri.size() / 3, double(peak_rss_bytes()) / 1048576.0,
        double(anon.peak()) / 1048576.0, target, collapses, rejected);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "openmesh_decimate_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
