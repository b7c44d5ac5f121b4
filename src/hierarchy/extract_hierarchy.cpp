// Extraction from a 4-k hierarchy (Velho 1999 §3): a set of records that holds the
// records that made every face it replaces gives a conforming mesh. The records are
// walked in the order they were made; one is applied when the query wants it and
// every record it depends on was applied, which gives the largest such set within
// the query (and, for a region, leaves every record that would replace a face
// meeting the region, and all that depend on it, unapplied).
#include <algorithm>
#include <cmath>
#include <string>

#include "common/triangle_geometry.hpp"
#include "common/vec3_math.hpp"
#include "hierarchy/hierarchy_steps.hpp"
#include "hierarchy/record_faces.hpp"
#include "hierarchy/vertex_placement.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

constexpr std::uint32_t kFinest = 0xffffffffu;

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

class Region {
 public:
  Region(const MeshHierarchy& h, const HierarchyQuery& q) : h_(h), q_(q) {}
  bool none() const { return q_.region == HierarchyQuery::Region::none; }
  bool meets(std::uint32_t face) const {
    const std::uint32_t* t = &h_.face_corners[3 * std::size_t(face)];
    const Vec3d a = at(t[0]), b = at(t[1]), c = at(t[2]);
    if (q_.region == HierarchyQuery::Region::box) {
      const Box3d box = metrics::triangle_box(a, b, c);
      return metrics::box_box_distance2(box, q_.box) <= 0;
    }
    return squared_distance(q_.centre, metrics::closest_point_on_triangle(q_.centre, a, b, c)) <= q_.radius * q_.radius;
  }

 private:
  Vec3d at(std::uint32_t v) const {
    return {h_.positions[3 * std::size_t(v)], h_.positions[3 * std::size_t(v) + 1],
            h_.positions[3 * std::size_t(v) + 2]};
  }
  const MeshHierarchy& h_;
  const HierarchyQuery& q_;
};

void check_query(const MeshHierarchy& h, const HierarchyQuery& q) {
  const int asked = int(q.level != HierarchyQuery::kNoLevel) + int(q.triangles > 0) + int(q.error >= 0);
  if (asked != 1) throw UsageError("query", "query: give exactly one of a level, a triangle count and an error bound");
  const std::size_t last = h.levels.size() - 1;
  if (q.level != HierarchyQuery::kNoLevel && q.level > last)
    throw UsageError("query.level", "query.level " + std::to_string(q.level) +
                                        " is beyond the last: the hierarchy has levels 0 to " + std::to_string(last));
  if (q.triangles > 0 && q.triangles < h.levels.back().triangles)
    throw UsageError("query.triangles",
                     "query.triangles " + std::to_string(q.triangles) + " is below the coarsest level's " +
                         std::to_string(h.levels.back().triangles) + " triangles (level " + std::to_string(last) + ")");
  if (!(q.error >= 0) && q.error != -1)
    throw UsageError("query.error", "query.error " + number(q.error) + " must be 0 or more");
  if (q.region == HierarchyQuery::Region::sphere && !(q.radius > 0 && std::isfinite(q.radius)))
    throw UsageError("query.radius", "query.radius " + number(q.radius) + " must be positive and finite");
  if (q.region == HierarchyQuery::Region::box && q.box.empty())
    throw UsageError("query.box", "query.box is empty (a minimum above its maximum)");
  if (!name_of(hierarchy_placement_names(), q.placement))
    throw UsageError("query.placement",
                     "query.placement " + std::to_string(int(q.placement)) + " is none of HierarchyPlacement's values");
}

// Which record made each face (kFinest: the finest mesh's).
std::vector<std::uint32_t> records_making_faces(const MeshHierarchy& h) {
  std::vector<std::uint32_t> made_by(h.face_corners.size() / 3, kFinest);
  for (std::size_t r = 0; r < h.records.size(); ++r)
    for (int i = 0; i < record_new_face_count(h.records[r]); ++i)
      made_by[h.first_new_face[r] + std::size_t(i)] = std::uint32_t(r);
  return made_by;
}

}  // namespace

std::uint64_t dependency_height(const MeshHierarchy& h) {
  const std::vector<std::uint32_t> made_by = records_making_faces(h);
  std::vector<std::uint32_t> depth(h.records.size(), 0);
  std::uint64_t height = 0;
  for (std::size_t r = 0; r < h.records.size(); ++r) {
    const HierarchyRecord& record = h.records[r];
    std::uint32_t d = 1;
    for (int i = 0; i < record.face_count; ++i)
      if (made_by[record.faces[i]] != kFinest) d = std::max(d, depth[made_by[record.faces[i]]] + 1);
    depth[r] = d;
    height = std::max<std::uint64_t>(height, d);
  }
  return height;
}

SimplifiedMesh extract_from_hierarchy(const MeshHierarchy& h, const HierarchyQuery& q) {
  check_query(h, q);
  const std::size_t finest = h.triangles.size() / 3, records = h.records.size();
  const std::size_t faces = h.face_corners.size() / 3;
  const Region region(h, q);
  if (!region.none()) {
    bool any = false;
    for (std::uint32_t f = 0; f < finest && !any; ++f) any = region.meets(f);
    if (!any) {
      Box3d bounds;
      for (std::size_t v = 0; v < h.positions.size(); v += 3)
        bounds.add(Vec3d{h.positions[v], h.positions[v + 1], h.positions[v + 2]});
      throw UsageError("query.region", "query.region meets no face of the mesh, whose bounds are " +
                                           number(bounds.min.x) + "," + number(bounds.min.y) + "," +
                                           number(bounds.min.z) + " to " + number(bounds.max.x) + "," +
                                           number(bounds.max.y) + "," + number(bounds.max.z));
    }
  }

  const std::vector<std::uint32_t> made_by = records_making_faces(h);
  const std::size_t end = q.level != HierarchyQuery::kNoLevel ? h.levels[q.level].end_record : records;
  std::vector<std::uint8_t> applied(records, 0), replaced(faces, 0);
  // A removal takes its vertex away with the faces it replaces, which were all the
  // vertex's faces when it was made. Out of the records' order (a region, an error
  // bound) a vertex on the boundary can still have others: the records that took
  // them were held back. Such a removal would cut the surface there (a boundary
  // ear's face would go and leave the vertex's other faces hanging), so it waits
  // too: it applies only where the vertex's live faces are those it replaces.
  std::vector<std::uint32_t> live_around(h.positions.size() / 3, 0);
  for (std::size_t c = 0; c < 3 * finest; ++c) ++live_around[h.face_corners[c]];
  std::uint64_t triangles = finest;
  for (std::size_t r = 0; r < end; ++r) {
    if (q.triangles > 0 && triangles <= q.triangles) break;
    const HierarchyRecord& record = h.records[r];
    if (q.error >= 0 && !(record.error <= q.error)) continue;
    bool take = record.swap || live_around[record.vertex] == record.face_count;
    for (int i = 0; i < record.face_count && take; ++i) {
      const std::uint32_t f = record.faces[i];
      take = (made_by[f] == kFinest || applied[made_by[f]]) && (region.none() || !region.meets(f));
    }
    if (!take) continue;
    applied[r] = 1;
    const int count = record_new_face_count(record);
    for (int i = 0; i < record.face_count; ++i) {
      replaced[record.faces[i]] = 1;
      for (int k = 0; k < 3; ++k) --live_around[h.face_corners[3 * std::size_t(record.faces[i]) + std::size_t(k)]];
    }
    for (int i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k)
        ++live_around[h.face_corners[3 * std::size_t(h.first_new_face[r] + i) + std::size_t(k)]];
    triangles = triangles + std::uint64_t(count) - record.face_count;
  }
  if (q.triangles > 0 && triangles > q.triangles)
    throw UsageError("query.triangles", "query.triangles " + std::to_string(q.triangles) +
                                            ": with the region kept at the finest level the fewest is " +
                                            std::to_string(triangles));

  // The live faces: the finest not replaced, and those the applied records made and
  // no applied record replaced; vertices in their order in the finest mesh.
  SimplifiedMesh out;
  out.precision = h.precision;
  out.attributes.attributes = h.attributes.attributes;
  const std::size_t k_values = h.attributes.attributes.size();
  if (h.attributes.values.size() != k_values * (h.positions.size() / 3))
    throw UsageError("hierarchy.attributes", "hierarchy.attributes holds " +
                                                 std::to_string(h.attributes.values.size()) +
                                                 " values, not one per attribute and vertex");
  std::vector<std::uint32_t> number_of(h.positions.size() / 3, kFinest);
  auto live = [&](std::uint32_t f) { return !replaced[f] && (made_by[f] == kFinest || applied[made_by[f]]); };
  for (std::uint32_t f = 0; f < faces; ++f)
    if (live(f))
      for (int k = 0; k < 3; ++k) number_of[h.face_corners[3 * std::size_t(f) + std::size_t(k)]] = 0;
  std::uint32_t next = 0;
  for (std::size_t v = 0; v < number_of.size(); ++v) {
    if (number_of[v] == kFinest) continue;
    number_of[v] = next++;
    out.positions.insert(out.positions.end(), {h.positions[3 * v], h.positions[3 * v + 1], h.positions[3 * v + 2]});
    const auto first = h.attributes.values.begin() + std::ptrdiff_t(v * k_values);
    out.attributes.values.insert(out.attributes.values.end(), first, first + std::ptrdiff_t(k_values));
  }
  out.triangles.reserve(3 * triangles);
  for (std::uint32_t f = 0; f < faces; ++f)
    if (live(f))
      for (int k = 0; k < 3; ++k)
        out.triangles.push_back(number_of[h.face_corners[3 * std::size_t(f) + std::size_t(k)]]);
  // With no removal applied (the finest level) no vertex took a share: nothing moves.
  bool removed = false;
  for (std::size_t r = 0; r < records && !removed; ++r) removed = applied[r] && !h.records[r].swap;
  if (q.placement == HierarchyPlacement::quadric && removed) {
    std::vector<std::uint32_t> source(next);
    for (std::size_t v = 0; v < number_of.size(); ++v)
      if (number_of[v] != kFinest) source[number_of[v]] = std::uint32_t(v);
    // The region is the finest mesh's faces, exactly: their corners stay.
    std::vector<std::uint8_t> pinned;
    if (!region.none()) {
      pinned.assign(next, 0);
      for (std::uint32_t f = 0; f < finest; ++f)
        if (live(f) && region.meets(f))
          for (int k = 0; k < 3; ++k) pinned[number_of[h.face_corners[3 * std::size_t(f) + std::size_t(k)]]] = 1;
    }
    place_at_quadric_minima(h, applied, source, pinned, &out);
  }
  return out;
}

}  // namespace oocsimp
