// The file a part of a distributed run leaves in the work folder: what it was run on
// and with, and what it owns of the run's work, for `oocsimp merge` to finish the
// run (docs/cluster.md): the uniform grid's chunk sums, the edge collapse's first
// pass, floating cells' cluster shares, or curvature values. Format, version 4,
// little-endian:
//
//   "OOCSPART" u32 version u32 part u32 parts u64 manifest-bytes manifest-text
//   records: u8 kind u64 number u64 payload-bytes payload, the kinds
//            1 vertex chunk, 2 face chunk (numbered by chunk),
//            3 collapsed tile (numbered 0, 1, 2, ...), 4 the first pass's plan (0),
//            5 floating cells' cluster shares (numbered by ShareKind), 6 the floating
//            run's plan (0), 7 curvature values (numbered 0, 1, 2, ...), 8 the
//            curvature run's plan (0)
//   end:     u8 0 u64 vertex-chunks u64 face-chunks, the skipped faces (3 u64)
//   u64 XXH64 of every byte before it
//
// A vertex chunk's payload is u64 n, n u64 keys, n VertexSum; a face chunk's is u64
// triangles, u64 n, n u64 keys, n Quadric, u64 m, m u32 kept, u64 a, a double
// attribute sums. A tile's is u64 n, n PassFace, u64 m, m PassVertex, u64 a, a
// double attribute values; the plan's a FirstPassPlan. Cluster shares are records of
// their kind, back to back; the floating plan a FloatingPartPlan. Curvature values
// are VertexCurvatureValue records; their plan a CurvaturePartPlan. (The structs as
// they are in memory: a part and its merge run the same build.)
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cluster/uniform_cells.hpp"
#include "grid/grid_spec.hpp"
#include "io/mapped_file.hpp"
#include "io/temp_file.hpp"
#include "methods/curvature_clusterer.hpp"
#include "methods/floating_clusterer.hpp"
#include "methods/qem_passes.hpp"
#include "refine/pass_tile.hpp"

namespace oocsimp {

/// What tells an input file apart cheaply on a shared file system, where device and
/// inode numbers differ between machines: its size, its modification time and the
/// XXH64 of its first and last MiB.
struct InputKey {
  std::uint64_t size = 0;
  std::int64_t mtime_ns = 0;
  std::uint64_t sample = 0;
  bool operator==(const InputKey& o) const { return size == o.size && mtime_ns == o.mtime_ns && sample == o.sample; }
  bool operator!=(const InputKey& o) const { return !(*this == o); }
};
/// The key of `path`; throws IoError when it cannot be read.
InputKey input_key(const std::string& path);

/// What a part was run on and with. Parts of one run have equal manifests but for
/// `part`; the merge refuses any other.
struct PartManifest {
  std::uint32_t part = 0, parts = 1;
  std::string input;    ///< the input's path as the part was given it
  InputKey key;         ///< of the input when the part read it
  std::string options;  ///< the options that shape the output, as text (part_options_text)
  GridSpec grid;        ///< the grid the part chose
  /// The build that wrote the part: its version and the sizes of the records it
  /// writes as they are in memory (part_file_build()). Set by PartWriter.
  std::string build;
};

/// One vertex's curvatures as a part of a curvature run hands them on.
struct VertexCurvatureValue {
  std::uint32_t vertex = 0;
  float k1 = 0, k2 = 0;
};

/// `v` exactly, as a manifest writes numbers (C's %a).
std::string part_hex_double(double v);

/// This build, as a part file's manifest records it.
std::string part_file_build();

/// "part-I-of-K.oocpart".
std::string part_file_name(std::uint32_t part, std::uint32_t parts);

/// Writes a part's file under a temporary name in `dir`, renamed into place by
/// commit(): a part that fails or is killed leaves no part file (a stale one from an
/// earlier run is replaced only on success).
class PartWriter {
 public:
  PartWriter(const std::string& dir, const PartManifest& manifest);
  void vertices(std::uint64_t chunk, const VertexChunkSums& sums);
  void faces(std::uint64_t chunk, const FaceChunkSums& sums);
  /// A tile of the edge collapse's first pass, and the pass's plan (once).
  void tile(const TileOutput& tile);
  void plan(const FirstPassPlan& plan);
  /// A run of a floating part's cluster shares (`bytes` of records of `kind`), and
  /// the run's plan (once).
  void shares(ShareKind kind, const void* records, std::size_t bytes);
  void floating_plan(const FloatingPartPlan& plan);
  /// A run of a curvature part's values, and the run's plan (once).
  void curvatures(const std::vector<VertexCurvatureValue>& values);
  void curvature_plan(const CurvaturePartPlan& plan);
  /// The end record (the input's chunk counts and skipped faces, which every part
  /// reads) and the checksum, then the rename. Throws IoError.
  void commit(std::uint64_t vertex_chunks, std::uint64_t face_chunks, const SkippedFaces& skipped);

 private:
  void put_record(std::uint8_t kind, std::uint64_t chunk, const std::vector<unsigned char>& payload);
  void put_record(std::uint8_t kind, std::uint64_t chunk, const void* payload, std::size_t bytes);
  void put(const void* data, std::size_t bytes);
  void flush();
  std::string dir_, path_;
  TempFile file_;
  std::vector<unsigned char> buffer_;
  std::uint64_t written_ = 0;
  std::uint64_t tiles_ = 0;
  std::uint64_t curvature_runs_ = 0;
};

/// A part file, mapped and checked: its checksum, its records and its end. Throws
/// InputError naming the file and the byte where it is damaged, truncated, of
/// another version or no part file at all.
class PartReader {
 public:
  explicit PartReader(const std::string& path);
  const PartManifest& manifest() const { return manifest_; }
  const std::string& path() const { return path_; }
  std::uint64_t vertex_chunks() const { return vertex_chunks_; }
  std::uint64_t face_chunks() const { return face_chunks_; }
  const SkippedFaces& skipped() const { return skipped_; }
  /// Whether the part holds chunk `chunk` of the pass.
  bool has_vertices(std::uint64_t chunk) const;
  bool has_faces(std::uint64_t chunk) const;
  /// The sums of a chunk the part holds.
  void vertices(std::uint64_t chunk, VertexChunkSums* out) const;
  void faces(std::uint64_t chunk, FaceChunkSums* out) const;
  /// Whether the part holds the first pass of an edge collapse; its plan, and each of
  /// its tiles, with `attributes` values per vertex, handed to `sink`. Throws
  /// InputError naming the byte of a record that is malformed.
  bool has_plan() const { return plan_at_ != 0; }
  FirstPassPlan plan() const;
  void tiles(std::size_t attributes, const TileOutputSink& sink) const;
  /// Whether the part holds a floating run's cluster shares; the run's plan, and the
  /// shares (records of `layout`'s sizes) handed to `sink` in place.
  bool has_floating_plan() const { return floating_plan_at_ != 0; }
  FloatingPartPlan floating_plan() const;
  void shares(const ClusterShareSink& sink, const AttributeLayout& layout) const;
  /// Whether the part holds a curvature run's plan; the plan, and its values written
  /// into k[2 v], k[2 v + 1] (InputError naming the byte of a vertex at or past
  /// `vertices`).
  bool has_curvature_plan() const { return curvature_plan_at_ != 0; }
  CurvaturePartPlan curvature_plan() const;
  void curvatures(std::uint64_t vertices, float* k) const;

 private:
  std::string path_;
  std::unique_ptr<MappedFile> map_;
  PartManifest manifest_;
  std::uint64_t vertex_chunks_ = 0, face_chunks_ = 0;
  SkippedFaces skipped_;
  // Per chunk the part owns (chunk / parts), the offset of its payload.
  std::vector<std::uint64_t> vertex_at_, face_at_;
  struct RecordPlace {
    std::uint64_t at = 0, bytes = 0;  // its payload
  };
  std::vector<RecordPlace> tile_at_;  // each collapsed tile's
  std::uint64_t plan_at_ = 0;         // the plan's payload, 0 where there is none
  struct ShareRecord {
    std::uint64_t at = 0, bytes = 0;
    ShareKind kind = ShareKind::partial;
  };
  std::vector<ShareRecord> share_at_;      // each run of cluster shares
  std::uint64_t floating_plan_at_ = 0;     // the floating plan's payload, 0 where there is none
  std::vector<RecordPlace> curvature_at_;  // each run of curvature values
  std::uint64_t curvature_plan_at_ = 0;    // the curvature plan's payload, 0 where there is none
};

}  // namespace oocsimp
