// Building and reading the mapped vertex position arrays behind a MeshInput.
#pragma once

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <string>

#include "io/byte_sink.hpp"
#include "io/mapped_file.hpp"
#include "io/mesh_input.hpp"
#include "io/temp_file.hpp"

namespace oocsimp {

struct MeshInput::Impl {
  std::unique_ptr<MappedFile> position_map;   // the input itself, or position_file
  std::unique_ptr<TempFile> position_file;    // float or double x,y,z per vertex when converted
  std::unique_ptr<MappedFile> attribute_map;  // attribute_file, when the attributes were converted
  std::unique_ptr<TempFile> attribute_file;   // the carried attributes packed, when converted
  std::function<std::unique_ptr<TriangleStream>()> make_triangles;
};

/// The reader's state behind `input`, for the readers and the welding that fill it.
inline MeshInput::Impl& reader_state(MeshInput& input) { return *input.impl_; }

/// Streams converted vertex positions into a temporary file under `temp_dir`,
/// tracking the bounding box; finish() maps the file into a MeshInput. Positions are
/// stored as the file means them: a PLY declares their type (declare()); for text
/// without one (OBJ, ascii STL) and integer PLY properties the array holds float x,y,z
/// while every coordinate so far is exactly a float or is decimal text that a float
/// keeps to its last digit, and double x,y,z from the first one that is not, so
/// converting never loses what the file says.
/// MeshInfo::double_precision tells which it became.
class PositionArrayBuilder {
 public:
  PositionArrayBuilder(const std::string& temp_dir, const std::string& source_path);
  ~PositionArrayBuilder();

  /// The type the file declares for its coordinates (before the first add()): f32
  /// rounds every coordinate to float, f64 stores double.
  void declare(ScalarType type);

  /// Appends a vertex. A vertex with a NaN or infinite coordinate is stored as it is
  /// and counted (see MeshInfo::non_finite_vertices); `where()` says where the vertex is
  /// in the file ("line N", "byte N") and is called only for the first such vertex, or
  /// to report a finite coordinate beyond the range of a declared float (InputError).
  /// `text_fits_float`: the coordinates were decimal text with no more than float
  /// precision (decimal_fits_float in io/text_scan.hpp), so the floats keep what the
  /// file says.
  template <class Where>
  void add(double x, double y, double z, Where&& where, bool text_fits_float = false) {
    if (!is_double_) {
      float f[3] = {float(x), float(y), float(z)};
      if (round_to_float_ || text_fits_float || (exactly(f[0], x) && exactly(f[1], y) && exactly(f[2], z))) {
        Vec3d p = widen(f);
        if (!is_finite(p) && is_finite(Vec3d{x, y, z})) beyond_float_range(x, y, z, where());
        add_to_bounds(p, where);
        sink_->write(f, sizeof f);
        ++count_;
        return;
      }
      store_as_double();
    }
    add_to_bounds(Vec3d{x, y, z}, where);
    double d[3] = {x, y, z};
    sink_->write(d, sizeof d);
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
  static bool exactly(float f, double x) { return double(f) == x || (std::isnan(f) && std::isnan(x)); }
  // The box must hold the stored floats, not the doubles they were rounded from. GCC
  // 12.2 at -O3 (SLP vectorisation) folded the inline float-to-double widening of x
  // and y back to the original doubles, so a box from the converted PLY "0 0.2 0"
  // had max.y = 0.2 below the stored 0.2f; out of line, the widening happens.
  [[gnu::noinline]] static Vec3d widen(const float* f);
  template <class Where>
  void add_to_bounds(const Vec3d& p, Where&& where) {
    if (is_finite(p)) {
      bounds_.add(p);
    } else if (non_finite_++ == 0) {
      first_non_finite_ = count_;
      first_non_finite_position_ = where();
    }
  }
  [[noreturn]] void beyond_float_range(double x, double y, double z, const std::string& where) const;
  // Stores double x,y,z from now on; the vertices so far are rewritten as double.
  void store_as_double();
  void open_file();
  std::uint64_t record_bytes() const { return is_double_ ? 3 * sizeof(double) : 3 * sizeof(float); }

  std::unique_ptr<TempFile> file_;
  std::unique_ptr<ByteSink> sink_;
  std::string source_path_;
  std::string temp_dir_;
  std::uint64_t expected_vertices_ = 0;  // 0: unknown
  bool round_to_float_ = false;          // declared float
  bool is_double_ = false;
  Box3d bounds_;
  std::uint64_t count_ = 0;
  std::uint64_t non_finite_ = 0, first_non_finite_ = 0;
  std::string first_non_finite_position_;
};

/// Fills out.info's bounds (of the finite positions), non-finite count and first
/// non-finite vertex from the positions already in `out` (in parallel), and the ranges
/// of out.attributes when it has any (as scan_attribute_ranges, in the same pass).
void scan_positions(MeshInput& out);

}  // namespace oocsimp
