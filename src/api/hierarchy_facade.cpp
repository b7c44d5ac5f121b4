// The facade's 4-k hierarchy (oocsimp/hierarchy.hpp): reading the input, the
// out-of-core phase for an input whose hierarchy does not fit the budget, and the
// .4k files.
#include "oocsimp/hierarchy.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include "api/simplify.hpp"
#include "hierarchy/hierarchy_file.hpp"
#include "hierarchy/hierarchy_steps.hpp"
#include "hierarchy/manifold_input.hpp"
#include "io/attribute_array.hpp"
#include "io/temp_file.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/formats.hpp"
#include "runtime/memory_budget.hpp"
#include "runtime/memory_usage.hpp"
#include "runtime/progress_phase.hpp"
#include "runtime/thread_limit.hpp"

namespace oocsimp {

namespace {

// Heap bytes building takes per input triangle (about two vertices' position,
// quadric and face list, the faces made and the records, and the hierarchy handed
// back), measured as peak anonymous memory over triangles on the generated sphere
// (docs/hierarchy.md).
constexpr std::uint64_t kBuildBytesPerTriangle = 400;

struct LoadedMesh {
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;
  std::vector<Quadric> quadrics;  // the out-of-core phase's, one per vertex (or none)
  AttributeValues attributes;
};

LoadedMesh load(MeshInput& input) {
  LoadedMesh m;
  m.positions.resize(std::size_t(input.positions.count));
  for (std::uint64_t v = 0; v < input.positions.count; ++v) m.positions[v] = input.positions.get(v);
  std::vector<std::uint64_t> chunk(3 * 65536);
  while (const std::size_t n = input.triangles->read(chunk.data(), 65536))
    for (std::size_t i = 0; i < 3 * n; ++i) m.triangles.push_back(std::uint32_t(chunk[i]));
  const std::size_t k = input.attributes.size();
  m.attributes.attributes = input.attributes.attributes;
  m.attributes.values.resize(std::size_t(input.positions.count) * k);
  for (std::uint64_t v = 0; v < input.positions.count; ++v)
    for (std::size_t j = 0; j < k; ++j) m.attributes.values[v * k + j] = attribute_value(input.attributes, v, j);
  return m;
}

// The simplified mesh as the builder takes it, freeing it on the way.
LoadedMesh from_simplified(SimplifiedMesh s, std::vector<Quadric> quadrics) {
  LoadedMesh m;
  if (quadrics.size() == s.positions.size() / 3) m.quadrics = std::move(quadrics);
  m.positions.resize(s.positions.size() / 3);
  for (std::size_t v = 0; v < m.positions.size(); ++v)
    m.positions[v] = {s.positions[3 * v], s.positions[3 * v + 1], s.positions[3 * v + 2]};
  std::vector<double>().swap(s.positions);
  m.triangles = std::move(s.triangles);
  m.attributes = std::move(s.attributes);
  return m;
}

MeshHierarchy build(LoadedMesh mesh, const std::string& name, const HierarchyOptions& options, ScalarType precision,
                    HierarchyStats* stats) {
  ManifoldMesh manifold = [&] {
    ProgressPhase phase(options.progress, "manifold", 0, "tri");
    return make_manifold(std::move(mesh.positions), std::move(mesh.triangles), name, options.repair);
  }();
  // A vertex split into fans gives each copy its whole quadric: the sum does not say
  // which fan each plane came from.
  if (!mesh.quadrics.empty())
    for (const std::uint32_t v : manifold.copied_from) mesh.quadrics.push_back(mesh.quadrics[v]);
  std::vector<double>& values = mesh.attributes.values;
  const std::size_t k = mesh.attributes.attributes.size();
  for (const std::uint32_t v : manifold.copied_from)
    for (std::size_t j = 0; j < k; ++j) values.push_back(values[std::size_t(v) * k + j]);
  const bool kept_quadrics = !mesh.quadrics.empty();
  MeshHierarchy h = build_four_k_hierarchy(manifold.positions, manifold.triangles, options, std::move(mesh.quadrics));
  h.precision = precision;
  h.attributes = std::move(mesh.attributes);
  if (stats) {
    stats->kept_quadrics = kept_quadrics;
    stats->split_vertices = manifold.split_vertices;
    stats->flipped_faces = manifold.flipped_faces;
    stats->cut_edges = manifold.cut_edges;
    stats->detached_faces = manifold.detached_faces;
    stats->records = h.records.size();
    stats->swaps = 0;
    for (const HierarchyRecord& r : h.records) stats->swaps += r.swap;
  }
  return h;
}

// The attributes the hierarchy keeps: texture coordinates too, since a record keeps a
// subset of the vertices, each with its own values, and a seam's copies stay apart
// (clustering leaves them out: it merges across seams).
AttributeSelection kept_attributes(const HierarchyOptions& options) {
  AttributeSelection kept = options.attributes;
  kept.texture_coordinates = true;
  return kept;
}

// Every attribute kept goes into the file under its name, which the reader takes only
// as a PLY property name (storable_attribute_name): checked before the work, so that
// no file is written that does not read back.
void check_attribute_names(const MeshInput& input) {
  for (const VertexAttribute& a : input.attributes.attributes) {
    if (storable_attribute_name(a.name)) continue;
    std::string shown = a.name;
    std::replace_if(
        shown.begin(), shown.end(), [](char c) { return !storable_name_byte(c); }, '?');
    throw InputError(input.info.path + ": the vertex attribute \"" + shown +
                     "\" has a name a .4k file cannot hold (blanks, control or non-ASCII bytes); leave it out with "
                     "--attributes");
  }
}

void check_options(const HierarchyOptions& options) {
  if (!(options.removal_weight >= 0) || !(options.swap_weight >= 0) ||
      !(options.removal_weight + options.swap_weight > 0))
    throw UsageError("options.removal_weight",
                     "options.removal_weight and options.swap_weight must be 0 or more, and not both 0");
  if (!(options.level_ratio >= 0 && options.level_ratio < 1))
    throw UsageError("options.level_ratio", "options.level_ratio must be from 0 to below 1");
  if (options.sets_per_level < 1 || options.sets_per_level > 16)
    throw UsageError("options.sets_per_level", "options.sets_per_level must be from 1 to 16");
  if (!(options.boundary_weight >= 0))
    throw UsageError("options.boundary_weight", "options.boundary_weight must be 0 or more");
}

std::string read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open for reading");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw IoError(path + ": cannot read");
  return bytes.str();
}

}  // namespace

MeshHierarchy build_hierarchy(const MeshView& mesh, const HierarchyOptions& options) {
  check_options(options);
  const auto threads = limit_threads(options.threads);
  MeshInput input = open_mesh_view(mesh, kept_attributes(options));
  check_attribute_names(input);
  return build(load(input), input.info.path, options, mesh.position_type, nullptr);
}

SimplifiedMesh extract_mesh(const MeshHierarchy& hierarchy, const HierarchyQuery& query) {
  return extract_from_hierarchy(hierarchy, query);
}

std::uint64_t hierarchy_height(const MeshHierarchy& hierarchy) { return dependency_height(hierarchy); }

void write_hierarchy(const MeshHierarchy& hierarchy, const std::string& path) {
  write_file_atomically(path, hierarchy_file_bytes(hierarchy));
}

MeshHierarchy read_hierarchy(const std::string& path) { return parse_hierarchy_file(read_whole_file(path), path); }

bool is_hierarchy_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  in.read(head, sizeof head);
  return in.gcount() == sizeof head && has_hierarchy_magic(std::string(head, sizeof head));
}

void build_hierarchy_file(const std::string& input_path, const std::string& output_path,
                          const HierarchyOptions& options, HierarchyStats* stats) {
  check_options(options);
  const double start = now_seconds();
  PeakAnonSampler peak_anon;
  const auto threads = limit_threads(options.threads);
  OutputFile out(output_path);
  OpenOptions open;
  open.temp_dir = options.temp_dir;
  open.progress = options.progress;
  open.attributes = kept_attributes(options);
  MeshInput input = open_mesh_input(input_path, open);
  check_attribute_names(input);
  const std::uint64_t budget = budget_bytes(options.memory_budget);
  // Each vertex's attribute values as doubles, about half a vertex a triangle, held
  // while loading and in the hierarchy.
  const std::uint64_t per_triangle = kBuildBytesPerTriangle + 8 * input.attributes.size();
  const std::uint64_t fits = budget / per_triangle;
  HierarchyStats st;
  st.input_vertices = input.info.vertex_count;
  st.input_triangles = input.info.face_count;
  const ScalarType precision = input.info.double_precision ? ScalarType::f64 : ScalarType::f32;
  MeshHierarchy h;
  if (input.info.face_count > fits) {
    // Too large to hold: the out-of-core simplification to the count that fits first.
    if (fits < 4)
      throw UsageError("options.memory_budget", "options.memory_budget " + std::to_string(budget) +
                                                    " bytes cannot hold a hierarchy of 4 triangles; give at least " +
                                                    std::to_string(4 * per_triangle));
    SimplifyOptions reduce;
    reduce.target.triangles = fits;
    reduce.memory_budget = budget;
    reduce.threads = options.threads;
    reduce.temp_dir = options.temp_dir;
    reduce.progress = options.progress;
    reduce.attributes = kept_attributes(options);
    std::vector<Quadric> quadrics;
    SimplifiedMesh reduced = simplify(input, reduce, nullptr, options.reuse_quadrics ? &quadrics : nullptr);
    st.reduced_triangles = reduced.triangles.size() / 3;
    h = build(from_simplified(std::move(reduced), std::move(quadrics)), input_path, options, precision, &st);
  } else {
    LoadedMesh loaded;
    {
      ProgressPhase phase(options.progress, "load mesh", 0, "tri");
      loaded = load(input);
    }
    h = build(std::move(loaded), input_path, options, precision, &st);
  }
  st.largest_error = h.levels.empty() ? 0 : h.levels.back().largest_error;
  std::string bytes;
  {
    ProgressPhase phase(options.progress, "write", 0, "B");
    bytes = hierarchy_file_bytes(h);
    out.write_all(bytes);
    out.commit();
  }
  st.file_bytes = bytes.size();
  st.seconds = now_seconds() - start;
  st.peak_rss_bytes = peak_rss_bytes();
  st.peak_anon_bytes = peak_anon.peak();
  if (stats) *stats = st;
}

void extract_file(const std::string& hierarchy_path, const OutputOptions& outputs, const HierarchyQuery& query,
                  const ProgressCallback& progress, ExtractStats* stats) {
  refuse_simplify_only_outputs(outputs, "extract_file");
  const double start = now_seconds();
  PeakAnonSampler peak_anon;
  const std::string& output_path = outputs.mesh;
  const MeshFormat format = format_for_path(output_path, outputs.ascii);
  MeshHierarchy h;
  {
    ProgressPhase phase(progress, "read hierarchy", 0, "B");
    h = read_hierarchy(hierarchy_path);
  }
  SimplifiedMesh m;
  {
    ProgressPhase phase(progress, "extract", 0, "record");
    m = extract_mesh(h, query);
  }
  {
    ProgressPhase phase(progress, "write", 0, "B");
    write_mesh(output_path, m.positions, m.triangles, format, m.precision, &m.attributes);
  }
  if (!stats) return;
  stats->finest_vertices = h.positions.size() / 3;
  stats->finest_triangles = h.triangles.size() / 3;
  stats->output_vertices = m.positions.size() / 3;
  stats->output_triangles = m.triangles.size() / 3;
  stats->seconds = now_seconds() - start;
  stats->peak_rss_bytes = peak_rss_bytes();
  stats->peak_anon_bytes = peak_anon.peak();
}

void extract_file(const std::string& hierarchy_path, const std::string& output_path, const HierarchyQuery& query,
                  const ProgressCallback& progress, ExtractStats* stats) {
  OutputOptions outputs;
  outputs.mesh = output_path;
  extract_file(hierarchy_path, outputs, query, progress, stats);
}

}  // namespace oocsimp
