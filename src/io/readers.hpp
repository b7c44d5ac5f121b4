// The per-format readers behind open_mesh_input(). Each fills `out` (info, positions,
// reader_state(out).make_triangles) from the ByteSource it is given, positioned at the start, and
// reports the bytes it has read to `progress`.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "io/byte_source.hpp"
#include "io/mesh_input.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

void open_ply(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out);
void open_obj(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out);
void open_stl(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out);
void open_off(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out);
void open_glb(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out);
/// Whether the first 4 bytes of the content (null: fewer) are binary glTF's magic.
bool looks_like_glb(const unsigned char* head);

/// Largest polygon accepted (corners); more is treated as a corrupt count.
constexpr std::uint64_t kMaxPolygonCorners = 1u << 20;

/// Emits the fan triangulation (p0, pi, pi+1) of a polygon held in a buffer, a few
/// triangles at a time, so polygons of any size stream through fixed-size output.
class FanTriangulator {
 public:
  std::vector<std::uint64_t>& polygon() { return poly_; }
  /// Starts fanning the polygon just stored in polygon().
  void start() { next_ = 1; }
  /// Writes pending triangles into out (up to max); returns the number written.
  std::size_t emit(std::uint64_t* out, std::size_t max) {
    std::size_t n = 0;
    while (n < max && next_ + 1 < poly_.size()) {
      out[3 * n] = poly_[0];
      out[3 * n + 1] = poly_[next_];
      out[3 * n + 2] = poly_[next_ + 1];
      ++next_;
      ++n;
    }
    return n;
  }
  bool pending() const { return next_ + 1 < poly_.size(); }

 private:
  std::vector<std::uint64_t> poly_;
  std::size_t next_ = 0;
};

/// Hands the thick edges and points a reader meets to a PrimitiveSink, a batch at a
/// time; without a sink the reader skips them.
class PrimitiveBatch {
 public:
  void set_sink(PrimitiveSink sink) { sink_ = std::move(sink); }
  bool wanted() const { return bool(sink_); }
  void add(std::uint64_t a, std::uint64_t b, float thickness) {
    batch_.push_back({a, b, thickness});
    if (batch_.size() >= 4096) flush();
  }
  void flush() {
    if (batch_.empty()) return;
    sink_(batch_.data(), batch_.size());
    batch_.clear();
  }

 private:
  PrimitiveSink sink_;
  std::vector<LinePrimitive> batch_;
};

}  // namespace oocsimp
