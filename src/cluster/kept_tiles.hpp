// --keep-tmp: what says whether tiles kept by an earlier run still belong to the
// input, and the manifest that records it (see floating_clusterer.cpp).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "grid/grid_coord.hpp"
#include "spill/stream_spill.hpp"
#include "io/content_hash.hpp"
#include "oocsimp/mesh_input.hpp"

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

}  // namespace oocsimp
