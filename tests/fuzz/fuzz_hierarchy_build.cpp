// libFuzzer target: building a 4-k hierarchy from a small mesh file, and extracting
// from it.
//
// The first byte selects the variant, the rest (at most 64 KiB) is the mesh file:
//   bit 0     input: 0 .ply, 1 .obj
//   bits 1-2  sets of removals a level: 1, 2, 3 (the default), or one sequential set
// The hierarchy is built on one thread and on two (an arena of two, so that the
// builder's walk works plans out ahead and applies its removals in parallel batches);
// the two .4k files must hold the same bytes. What the file holds must then keep
// what the hierarchy promises at every level and for a region: faces naming three
// distinct vertices in range, each edge of at most two faces wound oppositely (the
// builder makes non-manifold input manifold first or refuses it), the finest level's
// Euler characteristic, and finite positions where the finest are (the vertices are
// placed at their quadrics' minima). InputError (a file that does not read, an edge
// of three faces), IoError and UsageError are the clean outcomes.
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "fuzz_common.hpp"
#include "oocsimp/hierarchy.hpp"

namespace {

using oocsimp_fuzz::finding;

// V - E + F of the faces of `m` (only the vertices they use), after checking each
// face and each edge.
long euler_characteristic(const oocsimp::SimplifiedMesh& m, const std::string& what) {
  const std::size_t vertices = m.positions.size() / 3;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  std::set<std::uint32_t> used;
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const std::uint32_t* c = &m.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (c[k] >= vertices) finding(what + ": a corner out of range");
      used.insert(c[k]);
    }
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) finding(what + ": a face naming a vertex twice");
    for (int k = 0; k < 3; ++k) ++directed[{c[k], c[(k + 1) % 3]}];
  }
  long edges = 0;
  for (const auto& [edge, count] : directed) {
    if (count > 1) finding(what + ": two faces wind an edge the same way");
    const auto reverse = directed.find({edge.second, edge.first});
    if (reverse == directed.end() || edge.first < edge.second) ++edges;
  }
  return long(used.size()) - edges + long(m.triangles.size() / 3);
}

void check_positions(const oocsimp::SimplifiedMesh& m, bool finite_input, const std::string& what) {
  if (m.positions.size() % 3 != 0 || m.triangles.size() % 3 != 0) finding(what + ": ragged arrays");
  if (finite_input)
    for (const double x : m.positions)
      if (!std::isfinite(x)) finding(what + ": a position that is not finite");
}

// A file of the scratch folder, removed however the run ends.
struct ScratchFile {
  std::string path;
  ~ScratchFile() { ::unlink(path.c_str()); }
};

std::string read_all(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) finding("cannot read " + path);
  std::string bytes;
  char buffer[65536];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, f)) bytes.append(buffer, n);
  std::fclose(f);
  return bytes;
}

void run(std::uint8_t sel, const std::string& path) {
  oocsimp::HierarchyOptions options;
  options.temp_dir = oocsimp_fuzz::Scratch::path();
  const int sets = (sel >> 1) & 3;
  if (sets == 3) {
    options.independent = false;
  } else {
    options.sets_per_level = std::uint32_t(sets + 1);
  }
  const ScratchFile one{oocsimp_fuzz::Scratch::path() + "/one.4k"}, two{oocsimp_fuzz::Scratch::path() + "/two.4k"};
  // A clean refusal of the input ends the run here; past it, every step must succeed.
  options.threads = 1;
  oocsimp::build_hierarchy_file(path, one.path, options);
  options.threads = 2;
  oocsimp::MeshHierarchy h;
  try {
    tbb::task_arena arena(2);
    arena.execute([&] { oocsimp::build_hierarchy_file(path, two.path, options); });
    if (read_all(one.path) != read_all(two.path)) finding("the .4k bytes differ between one thread and two");
    h = oocsimp::read_hierarchy(one.path);
  } catch (const std::exception& e) {
    finding(std::string("built on one thread, then: ") + e.what());
  }
  bool finite_input = true;
  for (const double x : h.positions) finite_input = finite_input && std::isfinite(x);
  oocsimp::HierarchyQuery finest;
  finest.level = 0;
  const oocsimp::SimplifiedMesh level0 = oocsimp::extract_mesh(h, finest);
  check_positions(level0, finite_input, "level 0");
  const long chi = euler_characteristic(level0, "level 0");
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t i = 0; i < level0.positions.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], level0.positions[i]);
    hi[i % 3] = std::max(hi[i % 3], level0.positions[i]);
  }
  for (std::uint32_t j = 1; j < h.levels.size(); ++j) {
    oocsimp::HierarchyQuery q;
    q.level = j;
    const std::string what = "level " + std::to_string(j);
    const oocsimp::SimplifiedMesh m = oocsimp::extract_mesh(h, q);
    check_positions(m, finite_input, what);
    if (m.triangles.size() / 3 != h.levels[j].triangles) finding(what + ": not the level's triangle count");
    if (euler_characteristic(m, what) != chi) finding(what + ": another Euler characteristic than the finest");
    // The coarsest level with the middle of the bounding box kept at the finest.
    if (j + 1 == h.levels.size() && finite_input && !level0.positions.empty()) {
      q.region = oocsimp::HierarchyQuery::Region::box;
      auto quarter_in = [&](int k, double side) { return 0.5 * (lo[k] + hi[k]) + side * 0.25 * (hi[k] - lo[k]); };
      q.box.add(oocsimp::Vec3d{quarter_in(0, -1), quarter_in(1, -1), quarter_in(2, -1)});
      q.box.add(oocsimp::Vec3d{quarter_in(0, 1), quarter_in(1, 1), quarter_in(2, 1)});
      try {
        const oocsimp::SimplifiedMesh r = oocsimp::extract_mesh(h, q);
        check_positions(r, finite_input, what + " with a region");
        if (euler_characteristic(r, what + " with a region") != chi)
          finding(what + " with a region: another Euler characteristic than the finest");
      } catch (const oocsimp::UsageError&) {  // a region that meets no face
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > (64u << 10)) return 0;
  oocsimp_fuzz::init_process(2);
  const std::uint8_t sel = data[0];
  const std::string name = sel & 1 ? "input.obj" : "input.ply";
  const std::string path = oocsimp_fuzz::Scratch::path() + "/" + name;
  oocsimp_fuzz::write_bytes(path, data + 1, size - 1);
  try {
    run(sel, path);
  } catch (const oocsimp::InputError&) {
  } catch (const oocsimp::IoError&) {
  } catch (const oocsimp::UsageError&) {
  } catch (const std::exception& e) {
    finding(std::string("unexpected exception: ") + e.what());
  }
  oocsimp_fuzz::check_no_leftovers({name});
  ::unlink(path.c_str());
  return 0;
}
