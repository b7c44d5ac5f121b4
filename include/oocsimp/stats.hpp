// oocsimp — what a run reports: counts, seconds per phase, memory, warnings.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"
#include "oocsimp/mesh.hpp"

namespace oocsimp {

/// One timed phase of a run.
struct PhaseTime {
  std::string name;
  double seconds = 0;
};

/// The floating method's figures (SimplifyStats::floating; the stats JSON's "tiles").
struct FloatingStats {
  std::uint64_t tiles = 0;            ///< occupied tiles
  std::uint64_t rounds = 0;           ///< the first greedy and the sweeps of border decisions that changed something
  std::uint64_t spill_bytes = 0;      ///< tile spill written to disk
  std::uint64_t spill_raw_bytes = 0;  ///< the same before compression
  std::uint64_t spill_bytes_in_memory = 0;  ///< spill records held in memory instead (within the budget)
  bool resumed = false;                     ///< reused tiles kept by an earlier run
  /// Faces the binning read: the input's, or under MPI a rank's range of them when
  /// the faces have a fixed size (docs/cluster.md, "Floating cells").
  std::uint64_t faces_read = 0;
  std::uint64_t largest_tile_records = 0;  ///< triangle records of the fullest tile (its working set)
  /// Per sweep of border decisions after the first greedy (the last one only
  /// confirms): the tiles looked at (a neighbour's border changed since they last ran)
  /// and, of those, the tiles re-run (their external centres had changed).
  /// `published`: the border centres the tiles whose border changed published to
  /// their neighbours (what a distributed run would send between ranks in that
  /// sweep, docs/cluster.md).
  struct SweepCount {
    std::uint64_t looked_at = 0, rerun = 0, published = 0;
  };
  std::vector<SweepCount> sweeps;
  /// What the tiles hand on, in bytes (what a distributed run would exchange): the
  /// border centres every tile published after its first greedy, the stitch corners
  /// of the triangles that cross tiles, the triangles decided inside tiles, and the
  /// clusters' shares (with their attribute shares).
  std::uint64_t border_bytes = 0, stitch_corner_bytes = 0, inside_triangle_bytes = 0, cluster_share_bytes = 0;
  /// Bytes of one published border centre (a graded vertex).
  std::uint64_t border_centre_bytes = 0;
};

/// The edge collapse's figures, with a target (TargetOptions) or --method qem
/// (SimplifyStats::refine; the stats JSON's "refine").
struct RefineStats {
  /// The triangles phase 1 handed on (the input's for qem).
  std::uint64_t intermediate_triangles = 0;
  /// The out-of-core passes of the collapse before the last, in-core one (0: the mesh
  /// collapsed whole at once), and the triangles left after each.
  std::uint32_t passes = 0;
  std::vector<std::uint64_t> pass_triangles;
  /// Peak anonymous memory of phase 1 (the clustering, which --mem bounds) and of
  /// phase 2 (the collapse, which holds the intermediate whole), in bytes; 0 for a
  /// phase that did not run.
  std::uint64_t phase1_peak_anon_bytes = 0;
  std::uint64_t phase2_peak_anon_bytes = 0;
  /// The collapses taken, the largest collapse cost (area x distance^2) and error
  /// (model units).
  std::uint64_t collapses = 0;
  double largest_collapse_cost = 0;
  double largest_collapse_error = 0;
  /// Whether the target was missed: no valid collapse left, max_error reached, or a
  /// closed surface asked for an odd count.
  bool target_missed = false;
};

/// What every run reports, then the floating method's and the collapse's own figures.
struct SimplifyStats {
  std::uint64_t input_vertices = 0;     ///< after welding, when welded
  std::uint64_t unwelded_vertices = 0;  ///< vertices as stored, when welded (STL, --weld); 0: not welded
  std::uint64_t input_triangles = 0;
  SkippedFaces skipped;                       ///< faces the input lost, by reason
  std::uint64_t non_finite_vertices = 0;      ///< vertices with a NaN or infinite coordinate, ignored
  std::uint64_t first_non_finite_vertex = 0;  ///< the first of them by index
  std::string first_non_finite_position;      ///< where it is in the file ("byte N", "line N")
  std::uint64_t occupied_cells = 0;
  std::uint64_t output_vertices = 0;
  std::uint64_t output_triangles = 0;
  std::uint64_t output_edges = 0, output_points = 0;  ///< thick edges and points (SimplifyOptions::thick_edges)
  /// Levels of detail: the level's cell for choosing a level (lod-select): the
  /// clustering cell, or with a target sqrt(2 A / T) for an output of area A and T
  /// triangles, the cell of a grid that leaves about T triangles on such a surface
  /// (two per cell).
  double lod_cell = 0;
  double cell_size = 0;
  std::uint32_t grid_dims[3] = {0, 0, 0};
  /// Wall seconds of each phase in order: "open" (header, positions, bounding box), the
  /// method's own phases (uniform: vertices, faces, solve; floating: bin, grade, rounds,
  /// cluster, stitch, assemble), then "write".
  std::vector<PhaseTime> phases;
  double seconds_total = 0;
  /// Things the run did differently from what was asked, one line each ("FILE: what
  /// happened; what was done instead"), e.g. kept tiles that did not match the input
  /// and were recomputed. The CLI prints them on stderr.
  std::vector<std::string> warnings;
  /// The vertex attributes carried to the output, in its order.
  std::vector<VertexAttribute> attributes;
  std::uint64_t peak_rss_bytes = 0;
  std::uint64_t peak_anon_bytes = 0;
  FloatingStats floating;  ///< the floating method's figures (zero for the others)
  RefineStats refine;      ///< the collapse's figures (zero without a target or qem)
};

}  // namespace oocsimp
