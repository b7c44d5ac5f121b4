#include "io/face_range.hpp"

#include <cstring>
#include <string>

#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// Face i's three indices, checked against the vertex count as the PLY reader checks
// them; false when the record is not a triangle.
bool face_indices(const MeshInput& input, std::uint64_t i, std::uint64_t v[3]) {
  const FixedFaceTable& t = input.fixed_faces;
  const unsigned char* rec = t.base + i * FixedFaceTable::kStride;
  if (rec[0] != 3) return false;
  std::uint32_t u[3];
  std::memcpy(u, rec + 1, 12);
  for (int k = 0; k < 3; ++k) {
    if (t.swap) u[k] = __builtin_bswap32(u[k]);
    if (u[k] >= input.positions.count) {
      // A negative int index reads as a huge unsigned one: both fail the test.
      const std::int64_t shown = t.signed_index ? std::int64_t(std::int32_t(u[k])) : std::int64_t(u[k]);
      const std::string what = shown < 0 ? "negative vertex index " + std::to_string(shown)
                                         : "vertex index " + std::to_string(shown) + " out of range (" +
                                               std::to_string(input.positions.count) + " vertices)";
      throw InputError(at_byte(input.info.path, t.file_offset + i * FixedFaceTable::kStride, what));
    }
    v[k] = u[k];
  }
  return true;
}

bool repeats_a_vertex(const std::uint64_t v[3]) { return v[0] == v[1] || v[1] == v[2] || v[0] == v[2]; }

class FaceRangeStream : public TriangleStream {
 public:
  FaceRangeStream(const MeshInput& input, std::uint64_t first, std::uint64_t end)
      : input_(input), next_(first), first_(first), end_(end) {}

  std::size_t read(std::uint64_t* out, std::size_t max_triangles) override {
    std::size_t n = 0;
    for (; n < max_triangles && next_ < end_; ++next_) {
      std::uint64_t v[3];
      if (!face_indices(input_, next_, v))
        throw InputError(at_byte(input_.info.path, input_.fixed_faces.file_offset + next_ * FixedFaceTable::kStride,
                                 "a face that is not a triangle, in a range read alone"));
      if (repeats_a_vertex(v)) {
        ++repeated_;
        continue;
      }
      std::memcpy(out + 3 * n++, v, sizeof v);
    }
    return n;
  }
  std::uint64_t bytes_consumed() const override { return (next_ - first_) * FixedFaceTable::kStride; }
  SkippedFaces skipped() const override { return {0, 0, repeated_}; }

 private:
  const MeshInput& input_;
  std::uint64_t next_, first_, end_;
  std::uint64_t repeated_ = 0;
};

}  // namespace

FaceRangeScan scan_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end) {
  FaceRangeScan scan;
  if (!input.fixed_faces.available() || input.info.non_finite_vertices > 0 || end > input.fixed_faces.count)
    return scan;
  scan.readable = true;
  for (std::uint64_t i = first; i < end; ++i) {
    std::uint64_t v[3];
    if (!face_indices(input, i, v)) {
      scan.readable = false;
      return scan;
    }
    if (repeats_a_vertex(v))
      ++scan.skipped.repeated_index;
    else
      ++scan.triangles;
  }
  return scan;
}

std::unique_ptr<TriangleStream> open_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end) {
  return std::make_unique<FaceRangeStream>(input, first, end);
}

}  // namespace oocsimp
