// Building and reading the mapped vertex position arrays behind a MeshInput.
#pragma once

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <string>

#include "io/byte_sink.hpp"
#include "io/mapped_file.hpp"
#include "oocsimp/mesh_input.hpp"
#include "oocsimp/temp_file.hpp"

namespace oocsimp {

struct MeshInput::Impl {
  std::unique_ptr<MappedFile> position_map;   // the input itself, or position_file
  std::unique_ptr<TempFile> position_file;    // float x,y,z per vertex when converted
  std::function<std::unique_ptr<TriangleStream>()> make_triangles;
};

/// Streams converted vertex positions (as float x,y,z) into a temporary file under
/// `temp_dir`, tracking the bounding box; finish() maps the file into a MeshInput.
class PositionArrayBuilder {
 public:
  PositionArrayBuilder(const std::string& temp_dir, const std::string& source_path);
  ~PositionArrayBuilder();

  /// Appends a vertex as float. A vertex with a NaN or infinite coordinate is stored
  /// as it is and counted (see MeshInfo::non_finite_vertices); `where()` says where the
  /// vertex is in the file ("line N", "byte N") and is called only for the first such
  /// vertex, or to report a finite coordinate beyond the float range (InputError).
  template <class Where>
  void add(double x, double y, double z, Where&& where) {
    float f[3] = {float(x), float(y), float(z)};
    if (std::isfinite(f[0]) && std::isfinite(f[1]) && std::isfinite(f[2]))
      bounds_.add(widen(f));
    else if (non_finite_ > 0 && !(std::isfinite(x) && std::isfinite(y) && std::isfinite(z)))
      ++non_finite_;  // only the first one is described
    else
      not_finite_as_float(x, y, z, where());
    sink_->write(f, sizeof f);
    ++count_;
  }
  std::uint64_t count() const { return count_; }
  /// Announces how many vertices the file will give (when its header says so and the
  /// file's size makes that plausible): throws IoError up front when the temp folder
  /// lacks the room, and lets a failed write say how much was needed.
  void expect(std::uint64_t vertices);
  /// Flushes, maps the file and stores positions, bounds and ownership in `out`.
  void finish(MeshInput& out);

 private:
  // The box must hold the stored floats, not the doubles they were rounded from. GCC
  // 12.2 at -O3 (SLP vectorisation) folded the inline float-to-double widening of x
  // and y back to the original doubles, so a box from the converted OBJ "v 0 0.2 0"
  // had max.y = 0.2 below the stored 0.2f; out of line, the widening happens.
  [[gnu::noinline]] static Vec3d widen(const float* f);
  void not_finite_as_float(double x, double y, double z, const std::string& where);

  std::unique_ptr<TempFile> file_;
  std::unique_ptr<ByteSink> sink_;
  std::string source_path_;
  std::string temp_dir_;
  std::uint64_t expected_bytes_ = 0;  // 0: unknown
  Box3d bounds_;
  std::uint64_t count_ = 0;
  std::uint64_t non_finite_ = 0, first_non_finite_ = 0;
  std::string first_non_finite_position_;
};

}  // namespace oocsimp
