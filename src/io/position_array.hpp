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

  /// Appends a vertex; returns false (and appends nothing) when a coordinate is NaN
  /// or infinite, so the caller can report the position in its file.
  bool add(double x, double y, double z) {
    float f[3] = {float(x), float(y), float(z)};
    if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) return false;
    bounds_.add(Vec3d{f[0], f[1], f[2]});
    sink_->write(f, sizeof f);
    ++count_;
    return true;
  }
  std::uint64_t count() const { return count_; }
  /// Flushes, maps the file and stores positions, bounds and ownership in `out`.
  void finish(MeshInput& out);

 private:
  std::unique_ptr<TempFile> file_;
  std::unique_ptr<ByteSink> sink_;
  std::string source_path_;
  Box3d bounds_;
  std::uint64_t count_ = 0;
};

}  // namespace oocsimp
