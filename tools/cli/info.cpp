// oocsimp info: what a mesh file or a .4k hierarchy holds, as text or as JSON.
#include "commands.hpp"
#include "stats_file.hpp"

namespace oocsimp_cli {

namespace {

std::string json_tally(const PrimitiveTally& t) {
  std::string out = "{\"count\": " + std::to_string(t.count);
  if (t.count > 0)
    out += ", \"thickness\": {\"least\": " + json_number(t.least) + ", \"most\": " + json_number(t.most) +
           ", \"mean\": " + json_number(t.sum / double(t.count)) + "}";
  return out + "}";
}

// info --json: what info prints, as one object whose fields scripts can read.
std::string mesh_info_json(const MeshSummary& m) {
  const MeshInfo& i = m.info;
  std::string js = "{\"file\": " + json_string(i.path) + ", \"format\": " + json_string(i.format);
  js += ", \"compression\": " + (i.compressed ? json_string(i.compression) : std::string("null"));
  js += ", \"vertices\": " + std::to_string(i.vertex_count);
  if (i.unwelded_vertex_count) js += ", \"stored_vertices\": " + std::to_string(i.unwelded_vertex_count);
  js += ", \"faces\": " + std::to_string(i.face_count);
  js += ", \"edges\": " + json_tally(m.edges) + ", \"points\": " + json_tally(m.points);
  js += ", \"elements\": " + json_strings(i.elements) + ", \"header_comments\": " + json_strings(i.comments);
  js += std::string(", \"positions_in_place\": ") + (i.positions_in_place ? "true" : "false");
  js += ", \"attributes\": [";
  for (std::size_t k = 0; k < m.attributes.size(); ++k) {
    const VertexAttribute& v = m.attributes[k];
    js += std::string(k ? ", " : "") + "{\"name\": " + json_string(v.name) +
          ", \"type\": " + json_string(attribute_type_name(v.type)) + ", \"min\": " + json_number(v.min) +
          ", \"max\": " + json_number(v.max) +
          ", \"carried_by_clustering\": " + (is_texture_coordinate(v.name) ? "false" : "true") + "}";
  }
  js += "], \"not_carried\": " + json_strings(i.not_carried);
  if (i.bounds.empty()) {
    js += ", \"bounds\": null, \"diagonal\": null";
  } else {
    const Box3d& b = i.bounds;
    js += ", \"bounds\": {\"min\": [" + json_number(b.min.x) + ", " + json_number(b.min.y) + ", " +
          json_number(b.min.z) + "], \"max\": [" + json_number(b.max.x) + ", " + json_number(b.max.y) + ", " +
          json_number(b.max.z) + "]}, \"diagonal\": " + json_number(b.diagonal());
  }
  js += ", \"non_finite_vertices\": " + std::to_string(i.non_finite_vertices);
  if (i.non_finite_vertices > 0)
    js += ", \"first_non_finite_vertex\": {\"index\": " + std::to_string(i.first_non_finite_vertex) +
          ", \"at\": " + json_string(i.first_non_finite_position) + "}";
  return js + "}\n";
}

// info --json of a .4k hierarchy: its counts and levels, errors in kHierarchyErrorUnits.
int print_hierarchy_info_json(const InfoArgs& a) {
  const MeshHierarchy h = read_hierarchy(a.in);
  std::size_t swaps = 0;
  for (const HierarchyRecord& r : h.records) swaps += r.swap;
  std::string js = "{\"file\": " + json_string(a.in) +
                   ", \"format\": \"oocsimp 4-k hierarchy\", \"version\": " + std::to_string(h.file_version) +
                   ", \"positions\": " + (h.precision == ScalarType::f64 ? "\"double\"" : "\"float\"");
  js += ", \"attributes\": [";
  for (std::size_t k = 0; k < h.attributes.attributes.size(); ++k) {
    const VertexAttribute& v = h.attributes.attributes[k];
    js += std::string(k ? ", " : "") + "{\"name\": " + json_string(v.name) +
          ", \"type\": " + json_string(attribute_type_name(v.type)) + "}";
  }
  js += "], \"vertices\": " + std::to_string(h.positions.size() / 3) +
        ", \"faces\": " + std::to_string(h.triangles.size() / 3) +
        ", \"records\": " + std::to_string(h.records.size()) + ", \"swaps\": " + std::to_string(swaps) +
        ", \"height\": " + std::to_string(hierarchy_height(h)) +
        ", \"error_units\": " + json_string(kHierarchyErrorUnits) + ", \"levels\": [";
  for (std::size_t j = 0; j < h.levels.size(); ++j) {
    const HierarchyLevel& l = h.levels[j];
    js += std::string(j ? ", " : "") + "{\"triangles\": " + std::to_string(l.triangles) +
          ", \"vertices\": " + std::to_string(l.vertices) +
          ", \"largest_error\": " + json_number(double(l.largest_error)) + "}";
  }
  std::fputs((js + "]}\n").c_str(), stdout);
  return kOk;
}

// The thick edges or points: count and the range and mean of their thicknesses.
void print_tally(const char* name, const PrimitiveTally& t) {
  if (t.count > 0 && t.most == 0)
    std::printf("%-9s %" PRIu64 " (no thickness)\n", name, t.count);
  else if (t.count > 0)
    std::printf("%-9s %" PRIu64 " (thickness %.6g to %.6g, mean %.6g)\n", name, t.count, t.least, t.most,
                t.sum / double(t.count));
}

// A .4k hierarchy: its counts and levels.
int run_hierarchy_info(const InfoArgs& a) {
  const MeshHierarchy h = read_hierarchy(a.in);
  std::printf("file      %s\n", a.in.c_str());
  std::printf("format    oocsimp 4-k hierarchy, version %u, positions %s\n", unsigned(h.file_version),
              h.precision == ScalarType::f64 ? "double" : "float");
  if (!h.attributes.empty()) {
    std::printf("attributes");
    for (const VertexAttribute& v : h.attributes.attributes)
      std::printf(" %s (%s)", v.name.c_str(), attribute_type_name(v.type));
    std::printf("\n");
  }
  std::printf("vertices  %zu\n", h.positions.size() / 3);
  std::printf("faces     %zu\n", h.triangles.size() / 3);
  std::size_t swaps = 0;
  for (const HierarchyRecord& r : h.records) swaps += r.swap;
  std::printf("records   %zu (%zu swaps, %zu removals), height %" PRIu64 "\n", h.records.size(), swaps,
              h.records.size() - swaps, hierarchy_height(h));
  std::printf("errors    in %s\n", kHierarchyErrorUnits);
  std::printf("level  triangles   vertices  ratio  largest error\n");
  for (std::size_t j = 0; j < h.levels.size(); ++j) {
    const HierarchyLevel& l = h.levels[j];
    const double ratio = j > 0 ? double(l.triangles) / double(h.levels[j - 1].triangles) : 1.0;
    std::printf("%5zu %10" PRIu64 " %10" PRIu64 "  %.3f  %.6g\n", j, l.triangles, l.vertices, ratio,
                double(l.largest_error));
  }
  return kOk;
}

}  // namespace

CLI::App* add_info_command(CLI::App& app, InfoArgs& a) {
  CLI::App* cmd = app.add_subcommand("info", "Print format, element counts, properties and bounding box");
  cmd->add_option("input", a.in, "Input mesh, or a .4k hierarchy")->required();
  add_tmp_option(cmd, &a.tmp);
  cmd->add_flag("--json", a.json, "Print the description as one JSON object");
  add_quiet_flag(cmd, &a.quiet, "No progress (the description is printed all the same)");
  return cmd;
}

int run_info(const InfoArgs& a) {
  if (is_hierarchy_file(a.in)) return a.json ? print_hierarchy_info_json(a) : run_hierarchy_info(a);
  MeshSummary m;
  {
    ProgressReporter progress(a.quiet);
    m = describe_mesh(a.in, a.tmp, progress.callback());
  }
  if (a.json) {
    std::fputs(mesh_info_json(m).c_str(), stdout);
    return kOk;
  }
  const MeshInfo& i = m.info;
  std::printf("file      %s\n", i.path.c_str());
  std::printf("format    %s%s%s%s\n", i.format.c_str(), i.compressed ? " (" : "", i.compression.c_str(),
              i.compressed ? ")" : "");
  std::printf("vertices  %" PRIu64, i.vertex_count);
  if (i.unwelded_vertex_count) std::printf(" (welded from %" PRIu64 " stored)", i.unwelded_vertex_count);
  std::printf("\n");
  std::printf("faces     %" PRIu64 "\n", i.face_count);
  print_tally("edges", m.edges);
  print_tally("points", m.points);
  for (const auto& e : i.elements) std::printf("element   %s\n", e.c_str());
  for (const auto& c : i.comments) std::printf("header    %s\n", c.c_str());
  std::printf("positions %s\n", i.positions_in_place ? "read in place (mmap)" : "converted to a temporary array");
  // What simplify carries by default (--attributes all), with the range of each.
  if (m.attributes.empty()) std::printf("attributes none carried\n");
  for (const VertexAttribute& v : m.attributes)
    std::printf("attribute %s %s, carried%s (values %.9g to %.9g)\n", v.name.c_str(), attribute_type_name(v.type),
                is_texture_coordinate(v.name) ? " by the edge collapse, dropped by clustering" : "", v.min, v.max);
  for (const std::string& n : i.not_carried) std::printf("not carried %s\n", n.c_str());
  if (i.bounds.empty()) {
    std::printf("bounds    empty\n");
  } else {
    std::printf("bounds    min %.9g %.9g %.9g\n", i.bounds.min.x, i.bounds.min.y, i.bounds.min.z);
    std::printf("          max %.9g %.9g %.9g\n", i.bounds.max.x, i.bounds.max.y, i.bounds.max.z);
    std::printf("diagonal  %.9g\n", i.bounds.diagonal());
  }
  if (i.non_finite_vertices > 0)
    std::printf("non-finite %" PRIu64
                " (vertices with a NaN or infinite coordinate, ignored; the first: vertex %" PRIu64 " at %s)\n",
                i.non_finite_vertices, i.first_non_finite_vertex, i.first_non_finite_position.c_str());
  return kOk;
}

}  // namespace oocsimp_cli
