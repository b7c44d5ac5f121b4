// Peer benchmark: meshoptimizer's simplifiers, file to file, on the same input as
// `oocsimp simplify`. Loads with our mmap reader into the flat arrays meshoptimizer
// wants, simplifies to a target triangle count, compacts the vertices and writes a
// binary PLY.
//
//   meshopt_bench simplify|sloppy IN.ply OUT.ply TARGET_TRIANGLES [--error E] [--lock-border]
//
// simplify is meshopt_simplify, the in-core edge collapse with quadric errors (Garland
// & Heckbert 1997) that keeps the topology; sloppy is meshopt_simplifySloppy, which
// searches a vertex grid for the target and does not. --error is meshoptimizer's
// target_error, relative to the mesh's extent: by default FLT_MAX for simplify, so
// that the triangle count is its only stop, and 1 for sloppy (its grid search derives
// its finest grid from the error, so an unbounded one would not do). --lock-border
// is meshopt_SimplifyLockBorder, simplify only.
//
// Prints one line of key-value pairs: seconds (total, load, simplify, write), output
// triangles, peak RSS and peak anonymous RSS in MiB, and for simplify the relative
// error meshoptimizer reports.
#include <meshoptimizer.h>

#include <cfloat>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "oocsimp/error.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/oocsimp.hpp"
#include "runtime/memory_usage.hpp"

using namespace oocsimp;

namespace {

int usage(const char* argv0) {
  std::fprintf(stderr, "usage: %s simplify|sloppy IN OUT TARGET_TRIANGLES [--error E] [--lock-border]\n", argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) return usage(argv[0]);
  const std::string mode = argv[1];
  if (mode != "simplify" && mode != "sloppy") return usage(argv[0]);
  const bool sloppy = mode == "sloppy";
  float target_error = sloppy ? 1.0f : FLT_MAX;
  unsigned options = 0;
  for (int i = 5; i < argc; ++i) {
    if (std::strcmp(argv[i], "--error") == 0 && i + 1 < argc) {
      target_error = std::strtof(argv[++i], nullptr);
    } else if (std::strcmp(argv[i], "--lock-border") == 0 && !sloppy) {
      options |= meshopt_SimplifyLockBorder;
    } else {
      return usage(argv[0]);
    }
  }
  try {
    PeakAnonSampler anon;
    double t0 = now_seconds();
    MeshInput in = open_mesh_input(argv[2]);
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
    std::size_t target = std::size_t(std::strtoull(argv[4], nullptr, 10)) * 3;
    std::vector<unsigned> dst(idx.size());
    float result_error = 0;
    std::size_t n = sloppy ? meshopt_simplifySloppy(dst.data(), idx.data(), idx.size(), pos.data(), in.positions.count,
                                                    3 * sizeof(float), target, target_error, &result_error)
                           : meshopt_simplify(dst.data(), idx.data(), idx.size(), pos.data(), in.positions.count,
                                              3 * sizeof(float), target, target_error, options, &result_error);
    dst.resize(n);
    std::vector<unsigned> remap(in.positions.count);
    std::size_t nv = meshopt_optimizeVertexFetchRemap(remap.data(), dst.data(), dst.size(), in.positions.count);
    std::vector<float> out_pos(3 * nv);
    meshopt_remapVertexBuffer(out_pos.data(), pos.data(), in.positions.count, 3 * sizeof(float), remap.data());
    meshopt_remapIndexBuffer(dst.data(), dst.data(), dst.size(), remap.data());
    double t2 = now_seconds();
    std::vector<std::uint32_t> tri(dst.begin(), dst.end());
    write_mesh(argv[3], std::vector<double>(out_pos.begin(), out_pos.end()), tri, MeshFormat::ply_binary);
    double t3 = now_seconds();
    std::printf(
        "seconds %.3f load %.3f simplify %.3f write %.3f triangles %zu peak_rss_mib %.1f peak_anon_mib %.1f "
        "result_error %.3g\n",
        t3 - t0, t1 - t0, t2 - t1, t3 - t2, tri.size() / 3, double(peak_rss_bytes()) / 1048576.0,
        double(anon.peak()) / 1048576.0, double(result_error));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "meshopt_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
