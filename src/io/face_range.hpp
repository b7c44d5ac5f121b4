// A part's range of the faces, read alone: for parts that run at once, each reading
// only its bytes of an input whose faces have a fixed size (FixedFaceTable). Faces
// [first, end) give exactly the triangles the whole stream gives for them, as long
// as every face before them is a triangle, which the parts check together before
// they read (docs/cluster.md, "Floating cells").
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

#include "io/mesh_input.hpp"

namespace oocsimp {

/// Where part `part` of `parts` of an even split of `count` items starts (part
/// `parts` gives the end): floor(count * part / parts), without overflow.
inline std::uint64_t even_split_start(std::uint64_t count, std::uint32_t part, std::uint32_t parts) {
  return count / parts * part + count % parts * part / parts;
}

/// The three indices of a triangle record of FixedFaceTable::kStride bytes (the
/// count byte, then three 4-byte indices), byte-swapped when `swap`.
inline void fixed_face_indices(const unsigned char* record, bool swap, std::uint32_t v[3]) {
  std::memcpy(v, record + 1, 12);
  if (swap)
    for (int k = 0; k < 3; ++k) v[k] = __builtin_bswap32(v[k]);
}

/// What is wrong with index `index` (read unsigned) of a fixed-size face, against
/// `vertex_count` vertices: "negative vertex index -1" where the file says "int",
/// else "vertex index N out of range (V vertices)".
std::string fixed_face_index_problem(std::uint32_t index, bool signed_index, std::uint64_t vertex_count);

/// What a range of the faces holds, checked without binning it.
struct FaceRangeScan {
  /// Whether the range can be read alone: every record holds a triangle whose
  /// indices name vertices, and the input has no non-finite vertex (whose
  /// triangles the checked stream drops by their positions). False for an input
  /// without a FixedFaceTable, and at the first record that fails: where a face
  /// before it is not a triangle, the bytes read are not records at all, so only
  /// the whole stream may say what is wrong (and name the byte).
  bool readable = false;
  std::uint64_t triangles = 0;  ///< the triangles the stream yields for the range
  SkippedFaces skipped;         ///< the faces it drops
};

/// Checks faces [first, end) of input.fixed_faces; never throws for what it finds.
FaceRangeScan scan_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end);

/// The triangles of faces [first, end), as MeshInput::triangles yields them (a
/// triangle naming one vertex twice is dropped and counted), for a range that
/// scan_face_range found readable; bytes_consumed() counts from face
/// `counted_from` (at most `first`). Throws InputError for a record that is not a
/// readable triangle after all.
std::unique_ptr<TriangleStream> open_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end,
                                                std::uint64_t counted_from);

}  // namespace oocsimp
