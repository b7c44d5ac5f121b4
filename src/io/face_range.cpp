#include "io/face_range.hpp"

#include <string>

#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

std::string fixed_face_index_problem(std::uint32_t index, bool signed_index, std::uint64_t vertex_count) {
  // A negative int index reads as a huge unsigned one: both are out of range.
  const std::int64_t shown = signed_index ? std::int64_t(std::int32_t(index)) : std::int64_t(index);
  return shown < 0 ? "negative vertex index " + std::to_string(shown)
                   : "vertex index " + std::to_string(shown) + " out of range (" + std::to_string(vertex_count) +
                         " vertices)";
}

namespace {

// Face i's indices; false (with `problem` set) when the record is not a triangle or
// names a vertex that is not there.
bool face_indices(const MeshInput& input, std::uint64_t i, std::uint64_t v[3], std::string* problem) {
  const FixedFaceTable& t = input.fixed_faces;
  const unsigned char* record = t.base + i * FixedFaceTable::kStride;
  if (record[0] != 3) {
    *problem = "a face that is not a triangle";
    return false;
  }
  std::uint32_t u[3];
  fixed_face_indices(record, t.swap, u);
  for (int k = 0; k < 3; ++k) {
    if (u[k] >= input.positions.count) {
      *problem = fixed_face_index_problem(u[k], t.signed_index, input.positions.count);
      return false;
    }
    v[k] = u[k];
  }
  return true;
}

class FaceRangeStream : public TriangleStream {
 public:
  FaceRangeStream(const MeshInput& input, std::uint64_t first, std::uint64_t end, std::uint64_t counted_from)
      : input_(input), next_(first), end_(end), counted_from_(counted_from) {}

  std::size_t read(std::uint64_t* out, std::size_t max_triangles) override {
    std::size_t n = 0;
    for (; n < max_triangles && next_ < end_; ++next_) {
      std::uint64_t v[3];
      std::string problem;
      if (!face_indices(input_, next_, v, &problem))
        throw InputError(
            at_byte(input_.info.path, input_.fixed_faces.file_offset + next_ * FixedFaceTable::kStride, problem));
      if (names_a_vertex_twice(v[0], v[1], v[2])) {
        ++repeated_;
        continue;
      }
      std::memcpy(out + 3 * n++, v, sizeof v);
    }
    return n;
  }
  std::uint64_t bytes_consumed() const override { return (next_ - counted_from_) * FixedFaceTable::kStride; }
  SkippedFaces skipped() const override { return {0, 0, repeated_}; }

 private:
  const MeshInput& input_;
  std::uint64_t next_, end_, counted_from_;
  std::uint64_t repeated_ = 0;
};

}  // namespace

FaceRangeScan scan_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end) {
  FaceRangeScan scan;
  if (!input.fixed_faces.available() || input.info.non_finite_vertices > 0 || end > input.fixed_faces.count)
    return scan;
  std::string problem;
  for (std::uint64_t i = first; i < end; ++i) {
    std::uint64_t v[3];
    if (!face_indices(input, i, v, &problem)) return scan;
    if (names_a_vertex_twice(v[0], v[1], v[2]))
      ++scan.skipped.repeated_index;
    else
      ++scan.triangles;
  }
  scan.readable = true;
  return scan;
}

std::unique_ptr<TriangleStream> open_face_range(const MeshInput& input, std::uint64_t first, std::uint64_t end,
                                                std::uint64_t counted_from) {
  return std::make_unique<FaceRangeStream>(input, first, end, counted_from);
}

}  // namespace oocsimp
