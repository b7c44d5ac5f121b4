#include <cstdio>
#include <string>

#include "oocsimp/simplify.hpp"

namespace oocsimp {

std::string stats_to_json(const SimplifyStats& s) {
  double clustering = s.seconds_vertices + s.seconds_faces + s.seconds_solve;
  double total = s.seconds_total > 0 ? s.seconds_total : s.seconds_open + clustering + s.seconds_write;
  double mtris = total > 0 ? double(s.input_triangles) / total / 1e6 : 0;
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "{\n"
                "  \"input\": {\"vertices\": %llu, \"triangles\": %llu},\n"
                "  \"skipped\": {\"faces\": %llu, \"short_faces\": %llu, \"non_finite_triangles\": %llu, "
                "\"repeated_index_triangles\": %llu, \"non_finite_vertices\": %llu},\n"
                "  \"output\": {\"vertices\": %llu, \"triangles\": %llu},\n"
                "  \"grid\": {\"cell\": %.17g, \"dims\": [%u, %u, %u], \"occupied_cells\": %llu},\n"
                "  \"tiles\": {\"count\": %llu, \"rounds\": %llu, \"spill_bytes\": %llu, \"spill_raw_bytes\": %llu, "
                "\"resumed\": %s},\n"
                "  \"seconds\": {\"open\": %.6f, \"vertices\": %.6f, \"faces\": %.6f, \"solve\": %.6f, "
                "\"write\": %.6f, \"total\": %.6f},\n"
                "  \"memory\": {\"peak_rss_bytes\": %llu, \"peak_anon_bytes\": %llu},\n"
                "  \"input_mtris_per_second\": %.3f\n"
                "}\n",
                (unsigned long long)s.input_vertices, (unsigned long long)s.input_triangles,
                (unsigned long long)s.skipped.total(), (unsigned long long)s.skipped.short_faces,
                (unsigned long long)s.skipped.non_finite, (unsigned long long)s.skipped.repeated_index,
                (unsigned long long)s.non_finite_vertices, (unsigned long long)s.output_vertices,
                (unsigned long long)s.output_triangles, s.cell_size, s.grid_dims[0], s.grid_dims[1], s.grid_dims[2],
                (unsigned long long)s.occupied_cells, (unsigned long long)s.tiles, (unsigned long long)s.rounds,
                (unsigned long long)s.spill_bytes, (unsigned long long)s.spill_raw_bytes, s.resumed ? "true" : "false", s.seconds_open, s.seconds_vertices, s.seconds_faces,
                s.seconds_solve, s.seconds_write, total, (unsigned long long)s.peak_rss_bytes,
                (unsigned long long)s.peak_anon_bytes, mtris);
  return buf;
}

}  // namespace oocsimp
