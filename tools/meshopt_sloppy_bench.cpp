// Peer benchmark: meshoptimizer's meshopt_simplifySloppy, file to file, on the same
// input as `oocsimp simplify`. Loads with our mmap reader into the flat arrays
// meshoptimizer wants, asks sloppy for a target triangle count (it searches its grid
// for it), compacts the vertices and writes a binary PLY.
//
//   meshopt_sloppy_bench IN.ply OUT.ply TARGET_TRIANGLES
//
// Prints one line: seconds (total, load, simplify, write), output triangles and
// peak RSS.
#include <meshoptimizer.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "oocsimp/error.hpp"
#include "oocsimp/mesh_input.hpp"
#include "oocsimp/mesh_writer.hpp"
#include "report/memory_usage.hpp"

using namespace oocsimp;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s IN OUT TARGET_TRIANGLES\n", argv[0]);
    return 2;
  }
  try {
    double t0 = now_seconds();
    MeshInput in = open_mesh_input(argv[1]);
    std::vector<float> pos(3 * in.positions.count);
    for (std::uint64_t i = 0; i < in.positions.count; ++i) {
      Vec3d p = in.positions.get(i);
      pos[3 * i] = float(p.x);
      pos[3 * i + 1] = float(p.y);
      pos[3 * i + 2] = float(p.z);
    }
    std::vector<unsigned> idx;
    idx.reserve(3 * in.info.face_count);
    std::vector<std::uint64_t> buf(3 * 65536);
    while (std::size_t n = in.triangles->read(buf.data(), 65536))
      for (std::size_t k = 0; k < 3 * n; ++k) idx.push_back(unsigned(buf[k]));
    double t1 = now_seconds();
    std::size_t target = std::size_t(std::strtoull(argv[3], nullptr, 10)) * 3;
    std::vector<unsigned> dst(idx.size());
    std::size_t n = meshopt_simplifySloppy(dst.data(), idx.data(), idx.size(), pos.data(), in.positions.count,
                                           3 * sizeof(float), target, 1.0f, nullptr);
    dst.resize(n);
    std::vector<unsigned> remap(in.positions.count);
    std::size_t nv = meshopt_optimizeVertexFetchRemap(remap.data(), dst.data(), dst.size(), in.positions.count);
    std::vector<float> out_pos(3 * nv);
    meshopt_remapVertexBuffer(out_pos.data(), pos.data(), in.positions.count, 3 * sizeof(float), remap.data());
    meshopt_remapIndexBuffer(dst.data(), dst.data(), dst.size(), remap.data());
    double t2 = now_seconds();
    std::vector<std::uint32_t> tri(dst.begin(), dst.end());
    out_pos.resize(3 * nv);
    write_mesh(argv[2], std::vector<double>(out_pos.begin(), out_pos.end()), tri, MeshFormat::ply_binary);
    double t3 = now_seconds();
    std::printf("seconds %.3f load %.3f simplify %.3f write %.3f triangles %zu peak_rss_mib %.1f\n", t3 - t0, t1 - t0,
                t2 - t1, t3 - t2, tri.size() / 3, double(peak_rss_bytes()) / 1048576.0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "meshopt_sloppy_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
