// libFuzzer target: the whole simplify path on small inputs (at most 64 KiB).
//
// The first byte selects the variant, the rest is the mesh file:
//   bits 0-1  input: 0 .ply, 1 .obj, 2 .stl, 3 .ply.zst (the rest compressed)
//   bit 2     floating cells: tiles two cells wide (several tiles) instead of one tile
//   bit 3     floating cells: sphere instead of cube
//   bit 4     floating cells: assign to the heaviest instead of the nearest centre
//   bits 5-6  floating cells: representative 0/3 quadric, 1 centre, 2 mean
//   bit 7     output as ascii instead of binary PLY
// The mesh is opened and simplified with uniform cells (--grid 8), with floating
// cells of 1/8 of the bounding-box diagonal (skipped when the box is empty or a
// point), and to a target by the edge collapse (half the triangles, then three levels
// of detail from a quarter), one thread; each result is checked (indices in range and
// pairwise distinct, each unordered triple once, finite positions), written with
// write_mesh and read back; the levels' counts may not grow. InputError, IoError and
// UsageError are the clean outcomes.
#include <algorithm>
#include <array>
#include <set>

#include "fuzz_common.hpp"
#include "oocsimp/oocsimp.hpp"
#include "api/simplify.hpp"

namespace {

using oocsimp_fuzz::finding;

// How many of the input's triangles repeat an earlier one's three vertices: the edge
// collapse keeps what it is given (it makes no such repeat), clustering drops them.
std::uint64_t repeated_triangles(oocsimp::MeshInput& in) {
  in.restart_triangles();
  std::set<std::array<std::uint64_t, 3>> seen;
  std::uint64_t repeated = 0, buf[3 * 64];
  for (std::size_t n; (n = in.triangles->read(buf, 64)) != 0;)
    for (std::size_t t = 0; t < n; ++t) {
      std::array<std::uint64_t, 3> k = {buf[3 * t], buf[3 * t + 1], buf[3 * t + 2]};
      std::sort(k.begin(), k.end());
      repeated += !seen.insert(k).second;
    }
  in.restart_triangles();
  return repeated;
}

void check_result(const oocsimp::SimplifiedMesh& m, const char* method, std::uint64_t repeats_allowed = 0) {
  const std::string what = std::string(method) + ": ";
  if (m.positions.size() % 3 != 0) finding(what + "positions not a multiple of 3");
  if (m.triangles.size() % 3 != 0) finding(what + "triangles not a multiple of 3");
  std::size_t nv = m.positions.size() / 3;
  for (double f : m.positions)
    if (!std::isfinite(f)) finding(what + "output position is not finite");
  std::set<std::array<std::uint32_t, 3>> seen;
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    std::array<std::uint32_t, 3> k = {m.triangles[t], m.triangles[t + 1], m.triangles[t + 2]};
    for (std::uint32_t i : k)
      if (i >= nv) finding(what + "output index " + std::to_string(i) + " >= " + std::to_string(nv) + " vertices");
    if (k[0] == k[1] || k[1] == k[2] || k[0] == k[2]) finding(what + "degenerate output triangle");
    std::sort(k.begin(), k.end());
    if (!seen.insert(k).second && repeats_allowed-- == 0)
      finding(what + "the same three vertices in two output triangles");
  }
}

void simplify_write_reread(oocsimp::MeshInput& in, const oocsimp::SimplifyOptions& o, bool ascii, const char* method,
                           std::uint64_t repeats_allowed = 0) {
  oocsimp::SimplifyStats stats;
  oocsimp::SimplifiedMesh m = oocsimp::simplify(in, o, &stats);
  check_result(m, method, repeats_allowed);
  if (stats.output_triangles != m.triangles.size() / 3 || stats.output_vertices != m.positions.size() / 3)
    finding(std::string(method) + ": stats disagree with the result");
  const std::string out = oocsimp_fuzz::Scratch::path() + "/output.ply";
  oocsimp::write_mesh(out, m.positions, m.triangles,
                      ascii ? oocsimp::MeshFormat::ply_ascii : oocsimp::MeshFormat::ply_binary, m.precision);
  // What we wrote must read back as the same mesh size.
  try {
    oocsimp::OpenOptions oo;
    oo.temp_dir = oocsimp_fuzz::Scratch::path();
    oocsimp::MeshInput back = oocsimp::open_mesh_input(out, oo);
    oocsimp_fuzz::check_positions(back);
    auto tris = oocsimp_fuzz::drain_triangles(back);
    if (back.positions.count != m.positions.size() / 3 || tris.first != m.triangles.size() / 3)
      finding(std::string(method) + ": the written mesh reads back with other counts");
    // In the output's precision: a double output (double input, such as an OBJ whose
    // coordinates need it) reads back exactly, a float one as its floats.
    const bool as_float = m.precision == oocsimp::ScalarType::f32;
    const auto same = [&](double read, double written) { return as_float ? float(read) == written : read == written; };
    for (std::uint64_t i = 0; i < back.positions.count; ++i) {
      oocsimp::Vec3d p = back.positions.get(i);
      if (!same(p.x, m.positions[3 * i]) || !same(p.y, m.positions[3 * i + 1]) || !same(p.z, m.positions[3 * i + 2]))
        finding(std::string(method) + ": the written mesh reads back with other positions");
    }
  } catch (const std::exception& e) {
    finding(std::string(method) + ": the written mesh does not read back: " + e.what());
  }
  ::unlink(out.c_str());
}

void run(std::uint8_t sel, const std::string& path) {
  oocsimp::OpenOptions oo;
  oo.temp_dir = oocsimp_fuzz::Scratch::path();
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, oo);
  const bool ascii = sel & 0x80;

  oocsimp::SimplifyOptions uniform;
  uniform.sizing.grid = 8;
  uniform.method = oocsimp::ClusterMethod::uniform;
  uniform.threads = 1;
  uniform.temp_dir = oocsimp_fuzz::Scratch::path();
  simplify_write_reread(in, uniform, ascii, "uniform");

  // The edge collapse to a target (the default with one), and levels going on from it.
  const std::uint64_t faces = in.info.face_count;
  if (faces >= 8) {
    const std::uint64_t repeated = repeated_triangles(in);
    oocsimp::SimplifyOptions target;
    target.target.triangles = faces / 2;
    target.threads = 1;
    target.temp_dir = oocsimp_fuzz::Scratch::path();
    simplify_write_reread(in, target, ascii, "target", repeated);
    if (faces >= 64) {
      target.target.triangles = faces / 4;
      oocsimp::LodOptions lods;
      lods.levels = 3;
      std::uint64_t finer = ~std::uint64_t(0);
      oocsimp::simplify_lods(in, target, lods,
                             [&](std::uint32_t, oocsimp::SimplifiedMesh& m, const oocsimp::SimplifyStats& stats) {
                               check_result(m, "levels", repeated);
                               const std::uint64_t count = m.triangles.size() / 3;
                               if (stats.output_triangles != count) finding("levels: stats disagree with the result");
                               if (count > finer) finding("levels: a coarser level has more triangles");
                               finer = count;
                             });
    }
  }

  const oocsimp::Box3d& b = in.info.bounds;
  double diag = b.diagonal();
  if (b.empty() || !(diag > 0) || !std::isfinite(diag)) return;
  oocsimp::SimplifyOptions floating;
  floating.method = oocsimp::ClusterMethod::floating;
  floating.sizing.cell = diag / 8;
  if (sel & 0x04) floating.floating.tile_side = 2 * floating.sizing.cell;
  floating.floating.cell_shape = sel & 0x08 ? oocsimp::CellShape::sphere : oocsimp::CellShape::cube;
  floating.floating.assign = sel & 0x10 ? oocsimp::AssignRule::heaviest : oocsimp::AssignRule::nearest;
  switch ((sel >> 5) & 3) {
    case 1:
      floating.floating.representative = oocsimp::RepresentativeRule::centre;
      break;
    case 2:
      floating.floating.representative = oocsimp::RepresentativeRule::mean;
      break;
    default:
      floating.floating.representative = oocsimp::RepresentativeRule::quadric;
      break;
  }
  floating.memory_budget = 64u << 20;
  floating.threads = 1;
  floating.temp_dir = oocsimp_fuzz::Scratch::path();
  simplify_write_reread(in, floating, ascii, "floating");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > (64u << 10)) return 0;
  oocsimp_fuzz::init_process();
  const std::uint8_t sel = data[0];
  static const char* const kNames[4] = {"input.ply", "input.obj", "input.stl", "input.ply.zst"};
  const std::string name = kNames[sel & 3];
  const std::string path = oocsimp_fuzz::Scratch::path() + "/" + name;
  if ((sel & 3) == 3) {
    std::string packed = oocsimp_fuzz::zstd_compress(data + 1, size - 1);
    oocsimp_fuzz::write_bytes(path, packed.data(), packed.size());
  } else {
    oocsimp_fuzz::write_bytes(path, data + 1, size - 1);
  }
  oocsimp_fuzz::expect_clean([&] { run(sel, path); }, true);
  ::unlink(path.c_str());
  oocsimp_fuzz::check_no_leftovers({});
  return 0;
}
