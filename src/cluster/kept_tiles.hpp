// --keep-tmp: the binned and graded tiles kept on disk after a run and reused by the
// next run on the same input; what says whether they still belong to the input, and
// the manifest that records it.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "grid/grid_coord.hpp"
#include "grid/tile_binning.hpp"
#include "spill/stream_spill.hpp"
#include "io/content_hash.hpp"
#include "io/mesh_input.hpp"

namespace oocsimp {

/// What stat(2) says of a file that changes when the file is replaced or written:
/// device and inode (a rename over it), size, modification time (a write) and status
/// change time (any write, and every utime that set the modification time back,
/// which no user can set back in turn).
struct FileIdentity {
  std::uint64_t device = 0, inode = 0, size = 0;
  std::int64_t mtime_ns = 0, ctime_ns = 0;
  bool operator==(const FileIdentity& o) const {
    return device == o.device && inode == o.inode && size == o.size && mtime_ns == o.mtime_ns && ctime_ns == o.ctime_ns;
  }
  bool operator!=(const FileIdentity& o) const { return !(*this == o); }
};

/// The identity of `path` (following links); false when it cannot be stat'ed or is
/// not a regular file (a FIFO or device has no content to key tiles on).
bool regular_file_identity(const std::string& path, FileIdentity* id);

/// One kept tile: its coordinates and where its triangles and graded vertices are.
struct KeptTile {
  GridCoord coord;
  StreamSpill::Chain triangles, vertices;
};

/// The manifest of kept tiles: the input they were binned from (identity and XXH64
/// of its bytes), the size and XXH64 of the two kept files, the tiling and the
/// binning's counts. Written as text ending in a line with the XXH64 of the rest, so
/// a damaged manifest is told from a valid one.
struct KeptManifest {
  FileIdentity input;
  FileDigest input_digest, tiles_digest, vertices_digest;
  double tile_side = 0;
  std::uint64_t triangles = 0;
  SkippedFaces skipped;
  std::vector<KeptTile> tiles;
};
std::string format_kept_manifest(const KeptManifest& m);
/// False when `text` is not a whole manifest of this version with its checksum.
bool parse_kept_manifest(const std::string& text, KeptManifest* m);

/// The XXH64 of a file, computed on a thread of its own while the caller does other
/// work (binning reads the input too, so the file is mostly in the page cache).
class BackgroundDigest {
 public:
  explicit BackgroundDigest(const std::string& path);
  /// Stops reading early when the result was not asked for (an error ended the run).
  ~BackgroundDigest();
  BackgroundDigest(const BackgroundDigest&) = delete;
  BackgroundDigest& operator=(const BackgroundDigest&) = delete;
  /// Waits for the digest; false when the file could not be read (`error` says why).
  bool get(FileDigest* digest, std::string* error);

 private:
  std::atomic<bool> stop_{false};
  FileDigest digest_;
  std::string error_;
  std::thread thread_;
};

/// The result of binning and grading kept on disk: the stage results a later run with
/// other options reuses.
///
/// Binning and grading depend only on the input and the tile side, not on the cell,
/// its shape, the assignment rule or the representative, so a later run on the same
/// input with other options reuses them, provided its cell still fits in a tile. The
/// files are oocsimp-kept-KEY.{tiles,vertices,manifest} in the temp folder, KEY
/// naming the input's path and whether it was welded (which numbers the vertices
/// otherwise). The manifest records the input's identity (device, inode, size,
/// modification and status change times) and the XXH64 of its bytes, read while
/// binning; a resume requires the same identity and reads the input again to compare
/// the checksum (a sequential read, which costs a small fraction of the binning it
/// saves), then checks the size and XXH64 of both kept files. Anything
/// that does not match, or a damaged manifest, means binning again, with a warning:
/// kept tiles are a cache, never a reason to fail.
class KeptTileStore {
 public:
  /// Kept tiles of `input` under `temp_dir`; warnings go to `warnings` (may be null).
  KeptTileStore(const MeshInput& input, std::string temp_dir, std::vector<std::string>* warnings);
  ~KeptTileStore();

  /// Loads kept tiles when a manifest for this input exists, its tiles are at least
  /// `min_side` wide and every check passes: the binned tiles (the skipped faces as
  /// the binning counted them) and each tile's graded vertices in `precedes` order
  /// (GradedVertex, stream `tile`). False (and nothing changed) otherwise.
  bool resume(double min_side, BinnedTiles* tiles, std::unique_ptr<StreamSpill>* graded);
  /// Starts the input's checksum, read while binning; false (with a warning) when
  /// the input is no regular file, which cannot be keyed.
  bool start();
  /// Keeps `tiles` and `graded` (after start()), unless the input changed during the
  /// run (a warning then).
  void keep(BinnedTiles& tiles, StreamSpill& graded);

 private:
  std::string kept_path(const char* ext) const;
  void warn(const std::string& text);
  std::string fault(const KeptManifest& m, const FileIdentity& now) const;
  bool read_manifest(std::string* text) const;

  const MeshInput& input_;
  std::string temp_dir_;
  std::vector<std::string>* warnings_;
  FileIdentity kept_input_;                         // the input when binning started
  std::unique_ptr<BackgroundDigest> input_digest_;  // its checksum, read while binning
};

}  // namespace oocsimp
