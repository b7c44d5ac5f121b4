// A part's range of the faces, read alone: for parts that run at once, each reading
// only its bytes of an input whose faces have a fixed size (FixedFaceTable). Faces
// [first, end) give exactly the triangles the whole stream gives for them, as long
// as every face is a triangle, which the parts check together before they read
// (docs/cluster.md, "Floating cells").
#pragma once

#include <cstdint>
#include <memory>

#include "io/mesh_input.hpp"

namespace oocsimp {

/// Faces [first, end) of `count` faces: part `part` of `parts` of an even split.
inline std::uint64_t face_range_start(std::uint64_t count, std::uint32_t part, std::uint32_t parts) {
  return std::uint64_t((unsigned __int128)count * part / parts);
}

/// What a range of the faces holds, checked without binning it.
struct FaceRangeScan {
  /// Whether the range can be read alone: every record holds a triangle, and the
  /// input has no non-finite vertex (whose triangles the checked stream drops by
  /// their positions). False for an input without a FixedFaceTable.
  bool readable = false;
  std::uint64_t triangles = 0;  ///< the triangles the stream yields for the range
  SkippedFaces skipped;         ///< the faces it drops
};

/// Checks faces [first, end) of input.fixed_faces. Throws InputError naming the byte
/// of an index out of range, as the whole stream does.
FaceRangeScan scan_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end);

/// The triangles of faces [first, end), as MeshInput::triangles yields them (a
/// triangle naming one vertex twice is dropped and counted), for a range that
/// scan_face_range found readable.
std::unique_ptr<TriangleStream> open_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end);

}  // namespace oocsimp
