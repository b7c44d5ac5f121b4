// The --stats JSON of a simplify run, and the version it records.
#include <charconv>
#include <cinttypes>
#include <cstdio>
#include <string>

#include "oocsimp/names.hpp"
#include "runtime/memory_budget.hpp"

#ifndef OOCSIMP_VERSION
#error "OOCSIMP_VERSION comes from the CMake project version"
#endif

namespace oocsimp {

const char* version() { return OOCSIMP_VERSION; }

namespace {

// A JSON string literal (RFC 8259 §7): quotes, backslashes and control characters
// escaped; other bytes, UTF-8 or not, copied as they are.
std::string quoted(const std::string& s) {
  std::string r = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      r += '\\';
      r += char(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      r += buf;
    } else {
      r += char(c);
    }
  }
  return r + "\"";
}

// The shortest text that reads back as `v`.
std::string number(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string number(std::uint64_t v) { return std::to_string(v); }

std::string seconds(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

std::string options_json(const SimplifyOptions& o, const OutputOptions& outputs) {
  const ClusterMethod method = resolved_method(o);
  const bool floating = method == ClusterMethod::floating;
  std::string s = "{\"method\": " + quoted(method_name(method));
  if (o.sizing.cell != 0) s += ", \"cell\": " + number(o.sizing.cell);
  if (o.sizing.grid != 0) s += ", \"grid\": " + number(std::uint64_t(o.sizing.grid));
  if (o.sizing.ratio != 0) s += ", \"ratio\": " + number(o.sizing.ratio);
  const bool target = o.target.given() || method == ClusterMethod::qem;
  if (!target && o.sizing.cell == 0 && o.sizing.grid == 0 && o.sizing.ratio == 0)
    s += ", \"ratio\": " + number(kDefaultRatio);
  if (target) {
    s += ", \"target\": {";
    if (o.target.triangles != 0) s += "\"triangles\": " + number(o.target.triangles) + ", ";
    if (o.target.ratio != 0) s += "\"ratio\": " + number(o.target.ratio) + ", ";
    if (!o.target.given()) s += "\"ratio\": " + number(kDefaultRatio) + ", ";
    if (o.target.max_error != 0) s += "\"max_error\": " + number(o.target.max_error) + ", ";
    if (o.target.max_error_of_diagonal != 0)
      s += "\"max_error_of_diagonal\": " + number(o.target.max_error_of_diagonal) + ", ";
    s += "\"refine\": " + quoted(refine_name(o.target.refine)) +
         ", \"intermediate_factor\": " + number(o.target.intermediate_factor) + "}";
  }
  if (floating) {
    s += ", \"cell_shape\": " + quoted(cell_shape_name(o.floating.cell_shape));
    s += ", \"assign\": " + quoted(assign_name(o.floating.assign));
    s += ", \"rep\": " + quoted(representative_name(o.floating.representative));
    s += ", \"tile\": " + number(o.floating.tile_side);
    s += ", \"keep_tmp\": " + std::string(o.floating.keep_temp ? "true" : "false");
    s += ", \"spill_compress\": " + quoted(spill_compression_name(o.floating.spill_compression));
  }
  s += ", \"mem_bytes\": " + number(budget_bytes(o.memory_budget));
  s += ", \"threads\": " + number(std::uint64_t(o.threads));
  s += ", \"tmp\": " + quoted(o.temp_dir.empty() ? default_temp_dir() : o.temp_dir);
  s += ", \"weld\": " + std::string(o.weld ? "true" : "false");
  s += ", \"thick_edges\": " + std::string(o.thick_edges ? "true" : "false");
  s += ", \"lock_boundary\": " + std::string(o.lock_boundary ? "true" : "false");
  s += ", \"locked_vertices\": " + std::to_string(o.locked_vertices.size());
  s += ", \"precision\": " + quoted(precision_name(o.precision));
  if (o.attributes.mode == AttributeSelection::Mode::named) {
    std::string names;
    for (const std::string& n : o.attributes.names) names += (names.empty() ? "" : ", ") + quoted(n);
    s += ", \"attributes\": [" + names + "]";
  } else {
    s += std::string(", \"attributes\": ") +
         (o.attributes.mode == AttributeSelection::Mode::all ? "\"all\"" : "\"none\"");
  }
  s += ", \"ascii\": " + std::string(outputs.ascii ? "true" : "false");
  s += ", \"force\": " + std::string(outputs.replace_input ? "true" : "false");
  return s + "}";
}

}  // namespace

std::string stats_to_json(const SimplifyStats& s, const std::string& input_path, const OutputOptions& outputs,
                          const SimplifyOptions& options) {
  double total = s.seconds_total;
  if (total <= 0)
    for (const PhaseTime& p : s.phases) total += p.seconds;
  double mtris = total > 0 ? double(s.input_triangles) / total / 1e6 : 0;
  std::string phases;
  for (const PhaseTime& p : s.phases) phases += quoted(p.name) + ": " + seconds(p.seconds) + ", ";
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "  \"input\": {\"vertices\": %" PRIu64 ", \"triangles\": %" PRIu64
                "},\n"
                "  \"skipped\": {\"faces\": %" PRIu64 ", \"short_faces\": %" PRIu64
                ", \"non_finite_triangles\": %" PRIu64 ", \"repeated_index_triangles\": %" PRIu64
                ", \"non_finite_vertices\": %" PRIu64
                "},\n"
                "  \"output\": {\"vertices\": %" PRIu64 ", \"triangles\": %" PRIu64 ", \"edges\": %" PRIu64
                ", \"points\": %" PRIu64
                "},\n"
                "  \"grid\": {\"cell\": %.17g, \"dims\": [%u, %u, %u], \"occupied_cells\": %" PRIu64 "},\n",
                s.input_vertices, s.input_triangles, s.skipped.total(), s.skipped.short_faces, s.skipped.non_finite,
                s.skipped.repeated_index, s.non_finite_vertices, s.output_vertices, s.output_triangles, s.output_edges,
                s.output_points, s.cell_size, s.grid_dims[0], s.grid_dims[1], s.grid_dims[2], s.occupied_cells);
  std::string js = "{\n  \"version\": " + quoted(version()) + ",\n";
  js += "  \"paths\": {\"input\": " + quoted(input_path) + ", \"output\": " + quoted(outputs.mesh) +
        ", \"stats\": " + quoted(outputs.stats) + "},\n";
  js += "  \"options\": " + options_json(options, outputs) + ",\n";
  js += buf;
  if (resolved_method(options) == ClusterMethod::floating) {
    std::string sweeps;
    for (const FloatingStats::SweepCount& c : s.floating.sweeps) {
      std::snprintf(buf, sizeof buf,
                    "%s{\"looked_at\": %" PRIu64 ", \"rerun\": %" PRIu64 ", \"published\": %" PRIu64 "}",
                    sweeps.empty() ? "" : ", ", c.looked_at, c.rerun, c.published);
      sweeps += buf;
    }
    std::snprintf(buf, sizeof buf,
                  "  \"tiles\": {\"count\": %" PRIu64 ", \"largest_tile_records\": %" PRIu64 ", \"rounds\": %" PRIu64
                  ", \"spill_bytes\": %" PRIu64 ", \"spill_raw_bytes\": %" PRIu64
                  ", \"spill_bytes_in_memory\": %" PRIu64 ", \"resumed\": %s, \"faces_read\": %" PRIu64
                  ", \"exchange\": {\"border_bytes\": %" PRIu64 ", \"border_centre_bytes\": %" PRIu64
                  ", \"stitch_corner_bytes\": %" PRIu64 ", \"inside_triangle_bytes\": %" PRIu64
                  ", \"cluster_share_bytes\": %" PRIu64 "}, \"sweeps\": [",
                  s.floating.tiles, s.floating.largest_tile_records, s.floating.rounds, s.floating.spill_bytes,
                  s.floating.spill_raw_bytes, s.floating.spill_bytes_in_memory, s.floating.resumed ? "true" : "false",
                  s.floating.faces_read, s.floating.border_bytes, s.floating.border_centre_bytes,
                  s.floating.stitch_corner_bytes, s.floating.inside_triangle_bytes, s.floating.cluster_share_bytes);
    js += buf + sweeps + "]},\n";
  }
  if (options.target.given() || resolved_method(options) == ClusterMethod::qem) {
    std::snprintf(buf, sizeof buf,
                  "  \"refine\": {\"intermediate_triangles\": %" PRIu64 ", \"phase1_peak_anon_bytes\": %" PRIu64
                  ", \"phase2_peak_anon_bytes\": %" PRIu64 ", \"collapses\": %" PRIu64
                  ", \"largest_collapse_cost\": %.9g, \"largest_collapse_error\": %.9g, \"target_missed\": %s, ",
                  s.refine.intermediate_triangles, s.refine.phase1_peak_anon_bytes, s.refine.phase2_peak_anon_bytes,
                  s.refine.collapses, s.refine.largest_collapse_cost, s.refine.largest_collapse_error,
                  s.refine.target_missed ? "true" : "false");
    js += buf;
    std::string counts;
    for (std::uint64_t n : s.refine.pass_triangles) counts += (counts.empty() ? "" : ", ") + std::to_string(n);
    js += "\"passes\": " + std::to_string(s.refine.passes) + ", \"pass_triangles\": [" + counts + "]},\n";
  }
  std::string attributes, warnings;
  for (const VertexAttribute& a : s.attributes)
    attributes += (attributes.empty() ? "" : ", ") + std::string("{\"name\": ") + quoted(a.name) +
                  ", \"type\": " + quoted(attribute_type_name(a.type)) + "}";
  for (const std::string& w : s.warnings) warnings += (warnings.empty() ? "" : ", ") + quoted(w);
  js += "  \"attributes\": [" + attributes + "],\n";
  js += "  \"warnings\": [" + warnings + "],\n";
  js += "  \"seconds\": {" + phases + "\"total\": " + seconds(total) + "},\n";
  std::snprintf(buf, sizeof buf,
                "  \"memory\": {\"peak_rss_bytes\": %" PRIu64 ", \"peak_anon_bytes\": %" PRIu64
                "},\n"
                "  \"input_mtris_per_second\": %.3f\n"
                "}\n",
                s.peak_rss_bytes, s.peak_anon_bytes, mtris);
  return js + buf;
}

}  // namespace oocsimp
