// oocsimp — Velho's hierarchical 4-k mesh (Velho 1999, "Mesh Simplification using
// Four-Face Clusters"): one structure from which any level, any error bound or a
// region refined to the finest level can be extracted, conforming and without cracks.
//
//   oocsimp::MeshHierarchy h = oocsimp::build_hierarchy(view, {});
//   oocsimp::HierarchyQuery q;  q.level = 3;
//   oocsimp::SimplifiedMesh m = oocsimp::extract_mesh(h, q);
//
// The hierarchy is the finest mesh and the list of local modifications that simplify
// it, in the order they were made: edge swaps and removals of vertices of valence 4
// (3 inside; on the boundary, of 3 neighbours, or of 2: an ear, whose face goes). Each record replaces faces by faces
// with the same outline; a record depends on the records that made the faces it
// replaces. Any set of records that holds the dependencies of each of its records
// gives a conforming mesh (a multi-triangulation): extraction picks such a set.
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/attributes.hpp"
#include "oocsimp/enum_names.hpp"
#include "oocsimp/geometry.hpp"
#include "oocsimp/mesh.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/progress.hpp"

namespace oocsimp {

/// One local modification. Faces are numbered in the order they appear: the finest
/// mesh's first, then two (or one) per record, in record order.
struct HierarchyRecord {
  static constexpr std::uint32_t kNoFace = 0xffffffffu;
  /// The faces it replaces. A swap: two faces sharing an edge. A removal: the faces
  /// around `vertex` in counter-clockwise order (3 or 4
  /// inside; 1 or 2 on the boundary), the first starting at the neighbour the new
  /// faces fan from.
  std::uint32_t faces[4] = {kNoFace, kNoFace, kNoFace, kNoFace};
  /// The vertex removed; for a swap, the vertex whose removal the swap prepares.
  std::uint32_t vertex = 0;
  std::uint8_t face_count = 0;
  bool swap = false;
  /// The cost of the removal (Velho eq. 6, E(v) = 0.75 C(v) + 0.25 S(v), in area times
  /// squared distance); a swap carries that of the removal it prepares.
  float error = 0;
};

/// What a level holds once every record up to it is applied.
struct HierarchyLevel {
  std::uint64_t end_record = 0;  ///< records [0, end_record) make this level
  std::uint64_t triangles = 0, vertices = 0;
  float largest_error = 0;  ///< the largest record error up to this level
};

struct MeshHierarchy {
  /// The finest mesh (level 0): 3 coordinates per vertex, 3 indices per face.
  std::vector<double> positions;
  std::vector<std::uint32_t> triangles;
  ScalarType precision = ScalarType::f32;  ///< how the file stores the positions
  std::uint32_t file_version = 0;          ///< the .4k version it was read from (0: built here)
  /// The finest mesh's vertex attributes (colours, normals, ...), values per vertex.
  /// The records keep a subset of the vertices, so every extracted mesh carries its
  /// vertices' values unchanged (where they are placed, HierarchyPlacement).
  AttributeValues attributes;
  std::vector<HierarchyRecord> records;
  std::vector<HierarchyLevel> levels;  ///< level 0 (no record) first
  /// Derived from the above (filled by build_hierarchy and read_hierarchy): the
  /// corners of every face, 3 per face number, and the number of each record's first
  /// new face.
  std::vector<std::uint32_t> face_corners;
  std::vector<std::uint32_t> first_new_face;
};

struct HierarchyOptions {
  /// Levels to build; 0 = until a level removes nothing.
  std::uint32_t levels = 0;
  /// A level's sets of independent removals end when the triangles are down to this
  /// fraction of the level before (the cheapest removals first), or when no unmarked
  /// vertex can go. Velho's levels take every vertex they can (0 with one set: about
  /// 0.68 a level); stopping a little earlier leaves the dearer removals to the next
  /// level, nearer QEM at equal counts (docs/hierarchy.md). A level takes further sets
  /// while it holds more than max(0.75, level_ratio) of the level before's triangles.
  double level_ratio = 0.7;
  /// Independent sets a level is made of (1: Velho's). Each set ends at
  /// level_ratio^(1 / sets_per_level) of the triangles it began with, so that the
  /// level still ends near level_ratio. Smaller sets leave fewer cheap removals
  /// waiting beside a marked vertex, and come close to `independent = false`'s
  /// quality with a shallower dependency graph; each set ranks the vertices again, so
  /// more sets build more slowly (docs/hierarchy.md). From 1 to 16.
  std::uint32_t sets_per_level = 3;
  /// Velho §4 step 2: a set's removals are independent, each marking the four
  /// vertices around it so that no other removal of the set touches them: the
  /// dependency graph stays shallow. Off (--sequential), a set takes the cheapest
  /// removals one after another as an edge collapse does: about as close to QEM at
  /// the same count as the default's sets (docs/hierarchy.md), a deeper graph.
  bool independent = true;
  /// Velho eq. 6's weights of the removal cost C(v) and the swap cost S(v).
  double removal_weight = 0.75, swap_weight = 0.25;
  /// Weight of the plane through each boundary edge (Garland & Heckbert §6.1), per
  /// squared edge length, as in the edge collapse: it keeps the outline. (The file
  /// does not store it: extraction's placement replays the quadrics with the default.)
  double boundary_weight = 1000;
  /// Heap bytes for a file input (build_hierarchy_file); 0 = default_memory_budget().
  /// A mesh whose hierarchy does not fit is first simplified out of core to the count
  /// that fits, and the hierarchy built on that.
  std::uint64_t memory_budget = 0;
  /// After that out-of-core phase, start from the vertex quadrics its edge collapse
  /// summed (the error it made counts on) instead of the reduced mesh's faces. Off by
  /// default: it measured no better (docs/hierarchy.md).
  bool reuse_quadrics = false;
  /// The hierarchy needs a manifold surface wound consistently. With repair (the
  /// default) a mesh that is not is made so: faces turned to agree with their
  /// neighbours, edges of three or more faces cut, every vertex split into one per
  /// fan (docs/hierarchy.md); HierarchyStats says what it did. Off, such a mesh throws
  /// InputError naming the first bad edge.
  bool repair = true;
  /// The input's vertex attributes the hierarchy keeps (all by default).
  AttributeSelection attributes;
  std::string temp_dir;  ///< empty = default_temp_dir()
  unsigned threads = 0;  ///< for the out-of-core phase; the hierarchy is the same for any
  ProgressCallback progress;
};

/// Where extraction puts the vertices it keeps.
enum class HierarchyPlacement {
  /// Each vertex that took a share of a removed vertex's quadric (Velho eq. 9) moves
  /// to the minimum of the quadric it holds in the extracted state, as an edge
  /// collapse places its vertex, unless a face around it would then turn by more than
  /// 60 degrees, lose its area or become a needle, or a crease there grow sharper than
  /// the builder allows; the corners of a region's faces stay, and so do vertices
  /// that share a position (a split vertex's copies, a seam's sides). Velho's records
  /// keep a subset of the finest vertices, which costs what an edge collapse gains by
  /// moving its vertex; placed, the levels come near the edge collapse's error at the
  /// same count (docs/hierarchy.md). The faces and the topology are the same either
  /// way, and every vertex keeps its attribute values.
  quadric,
  /// Every vertex where the finest mesh has it.
  kept,
};
OOCSIMP_API const EnumNames<HierarchyPlacement>& hierarchy_placement_names();

/// What to extract: one of `level`, `triangles` or `error` (the first set), and
/// optionally a region kept at the finest level.
struct HierarchyQuery {
  static constexpr std::uint32_t kNoLevel = 0xffffffffu;
  std::uint32_t level = kNoLevel;  ///< 0 = finest
  std::uint64_t triangles = 0;     ///< > 0: the finest state with at most this many
  double error = -1;               ///< >= 0: the coarsest state whose records all cost at most this
  enum class Region { none, box, sphere } region = Region::none;
  Box3d box;          ///< Region::box
  Vec3d centre;       ///< Region::sphere
  double radius = 0;  ///< Region::sphere
  HierarchyPlacement placement = HierarchyPlacement::quadric;
};

/// Builds the hierarchy of a manifold triangle mesh, wound consistently (Velho §4,
/// Algorithm 1). A vertex whose faces form several fans is split into one vertex per
/// fan; an edge of three or more faces, or two faces that wind it the same way, is
/// refused (InputError naming the edge). The result is the same for any thread count.
OOCSIMP_API MeshHierarchy build_hierarchy(const MeshView& mesh, const HierarchyOptions& options);

/// The mesh of the records `query` selects, vertices numbered in their order in the
/// finest mesh, faces in the order they appear. UsageError (naming what is
/// available) for a level beyond the last, a triangle count below the coarsest, a
/// negative error, or a region that meets no face.
OOCSIMP_API SimplifiedMesh extract_mesh(const MeshHierarchy& hierarchy, const HierarchyQuery& query);

/// The longest chain of records each depending on the one before (Velho §3's
/// height): how far a region's refinement can reach beyond it.
OOCSIMP_API std::uint64_t hierarchy_height(const MeshHierarchy& hierarchy);

/// Writes `hierarchy` to a .4k file (docs/hierarchy.md: the format, version 2), under
/// a temporary name renamed into place when complete. IoError.
OOCSIMP_API void write_hierarchy(const MeshHierarchy& hierarchy, const std::string& path);
/// Reads a .4k file. InputError naming the byte for a damaged, truncated or foreign
/// file, and both versions for another version; IoError when it cannot be read.
OOCSIMP_API MeshHierarchy read_hierarchy(const std::string& path);

struct HierarchyStats {
  std::uint64_t input_vertices = 0, input_triangles = 0;
  /// The triangles the out-of-core phase left (0 when the input fitted the budget).
  std::uint64_t reduced_triangles = 0;
  /// The hierarchy started from the out-of-core phase's vertex quadrics (its edge
  /// collapse's sums) rather than from the reduced mesh's faces.
  bool kept_quadrics = false;
  std::uint64_t split_vertices = 0;  ///< vertices added where fans met
  /// What the repair did (all 0 for a manifold surface wound consistently): faces
  /// flipped to agree with their neighbours, edges cut (of three or more faces, or of
  /// two that could not agree), and faces given vertices of their own.
  std::uint64_t flipped_faces = 0, cut_edges = 0, detached_faces = 0;
  std::uint64_t records = 0, swaps = 0;
  /// The largest record error up to the coarsest level (HierarchyRecord::error's
  /// units: area times squared distance, model units to the fourth power).
  double largest_error = 0;
  std::uint64_t file_bytes = 0;
  double seconds = 0;
  std::uint64_t peak_rss_bytes = 0, peak_anon_bytes = 0;
};

/// Reads the mesh at `input_path`, builds its hierarchy and writes `output_path`.
OOCSIMP_API void build_hierarchy_file(const std::string& input_path, const std::string& output_path,
                                      const HierarchyOptions& options, HierarchyStats* stats = nullptr);

/// What extract_file read, made and wrote.
struct ExtractStats {
  std::uint64_t finest_vertices = 0, finest_triangles = 0;  ///< the hierarchy's level 0
  std::uint64_t output_vertices = 0, output_triangles = 0;
  double seconds = 0;
  std::uint64_t peak_rss_bytes = 0, peak_anon_bytes = 0;
};

/// Reads the .4k file at `hierarchy_path`, extracts `query` and writes the mesh to
/// `outputs.mesh` (any format write_mesh writes; a PLY or STL in ascii with
/// outputs.ascii), each a phase `progress` hears: "read hierarchy", "extract",
/// "write". The other fields of OutputOptions are simplify_file's: set here, they are
/// refused (UsageError).
OOCSIMP_API void extract_file(const std::string& hierarchy_path, const OutputOptions& outputs,
                              const HierarchyQuery& query, const ProgressCallback& progress = {},
                              ExtractStats* stats = nullptr);
/// The same with only a mesh path; a PLY or STL is written binary.
OOCSIMP_API void extract_file(const std::string& hierarchy_path, const std::string& output_path,
                              const HierarchyQuery& query, const ProgressCallback& progress = {},
                              ExtractStats* stats = nullptr);

/// Whether the file at `path` starts like a .4k file (its magic bytes).
OOCSIMP_API bool is_hierarchy_file(const std::string& path);

}  // namespace oocsimp
