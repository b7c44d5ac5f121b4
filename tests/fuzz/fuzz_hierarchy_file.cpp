// libFuzzer target: the .4k hierarchy file reader, and extraction from what it reads.
//
// The input is a .4k file without its checksums: the 64-byte header, then the body.
// The target sets the header's body size to what follows the header, makes the
// header's and every MiB's checksums right and appends the latter, so that mutations
// reach the reader's checks of the structure instead of stopping at a checksum (a
// shorter input goes to the reader as it is). A file read must keep what
// parse_hierarchy_file promises: indices in range, attribute values for every vertex,
// levels in order; the finest level, the last level, a triangle count and a region
// must then extract to meshes whose faces name three distinct vertices in range, each
// with its attribute values, and finite positions where the finest are (extraction
// places vertices at their quadrics' minima). InputError is the clean outcome of the reader, and
// UsageError of a query the hierarchy cannot answer; anything else is a finding.
#include <algorithm>
#include <cmath>
#include <string>

#include "fuzz_common.hpp"
#include "hierarchy/hierarchy_file.hpp"
#include "io/content_hash.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/hierarchy.hpp"

namespace {

using oocsimp_fuzz::finding;

constexpr std::size_t kHeaderBytes = 64, kHashedHeaderBytes = 56, kBlockBytes = std::size_t(1) << 20;

std::string with_checksums(const std::uint8_t* data, std::size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size < kHeaderBytes) return bytes;
  const std::uint64_t body = size - kHeaderBytes;
  std::memcpy(&bytes[48], &body, 8);
  const std::uint64_t header_hash = oocsimp::content_hash(bytes.data(), kHashedHeaderBytes);
  std::memcpy(&bytes[kHashedHeaderBytes], &header_hash, 8);
  for (std::size_t at = 0; at < body; at += kBlockBytes) {
    const std::uint64_t h =
        oocsimp::content_hash(bytes.data() + kHeaderBytes + at, std::min<std::size_t>(kBlockBytes, body - at));
    bytes.append(reinterpret_cast<const char*>(&h), 8);
  }
  return bytes;
}

// Whether the finest positions are all finite: then so must every extracted one be,
// the vertices placed at their quadrics' minima included.
bool g_finite_input = true;

void check_mesh(const oocsimp::SimplifiedMesh& m, std::size_t attributes, const char* what) {
  const std::size_t vertices = m.positions.size() / 3;
  if (g_finite_input)
    for (const double x : m.positions)
      if (!std::isfinite(x)) finding(std::string(what) + ": a position that is not finite");
  if (m.positions.size() % 3 != 0 || m.triangles.size() % 3 != 0) finding(std::string(what) + ": ragged arrays");
  if (m.attributes.attributes.size() != attributes || m.attributes.values.size() != vertices * attributes)
    finding(std::string(what) + ": attribute values not one set per vertex");
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const std::uint32_t a = m.triangles[t], b = m.triangles[t + 1], c = m.triangles[t + 2];
    if (a >= vertices || b >= vertices || c >= vertices) finding(std::string(what) + ": an index out of range");
    if (a == b || b == c || a == c) finding(std::string(what) + ": a face naming a vertex twice");
  }
}

template <class F>
void answer(const char* what, std::size_t attributes, F&& extract) {
  try {
    check_mesh(extract(), attributes, what);
  } catch (const oocsimp::UsageError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  oocsimp_fuzz::init_process();
  oocsimp::MeshHierarchy h;
  try {
    h = oocsimp::parse_hierarchy_file(with_checksums(data, size), "fuzz.4k");
  } catch (const oocsimp::InputError&) {
    return 0;
  }
  const std::size_t vertices = h.positions.size() / 3, k = h.attributes.attributes.size();
  g_finite_input = std::all_of(h.positions.begin(), h.positions.end(), [](double x) { return std::isfinite(x); });
  if (h.positions.size() % 3 != 0 || h.triangles.size() % 3 != 0) finding("ragged arrays read");
  for (const std::uint32_t v : h.triangles)
    if (v >= vertices) finding("a finest face names a vertex out of range");
  if (h.attributes.values.size() != vertices * k) finding("attribute values not one set per vertex");
  if (h.levels.empty() || h.levels[0].end_record != 0 || h.levels.back().end_record != h.records.size())
    finding("levels that do not run from no record to the last");
  for (std::size_t j = 1; j < h.levels.size(); ++j)
    if (h.levels[j].end_record < h.levels[j - 1].end_record) finding("levels out of order");
  if (h.first_new_face.size() != h.records.size()) finding("a record without its first new face");

  answer("the finest level", k, [&] {
    oocsimp::HierarchyQuery q;
    q.level = 0;
    return oocsimp::extract_mesh(h, q);
  });
  answer("the last level", k, [&] {
    oocsimp::HierarchyQuery q;
    q.level = std::uint32_t(h.levels.size() - 1);
    return oocsimp::extract_mesh(h, q);
  });
  answer("a triangle count", k, [&] {
    oocsimp::HierarchyQuery q;
    q.triangles = h.triangles.size() / 6 + 1;
    return oocsimp::extract_mesh(h, q);
  });
  if (vertices > 0)
    answer("a region", k, [&] {
      oocsimp::HierarchyQuery q;
      q.level = std::uint32_t(h.levels.size() - 1);
      q.region = oocsimp::HierarchyQuery::Region::sphere;
      q.centre = {h.positions[0], h.positions[1], h.positions[2]};
      q.radius = 0.25;
      return oocsimp::extract_mesh(h, q);
    });
  return 0;
}
