#include <cstdlib>
#include <cstring>

#include "io/position_array.hpp"
#include "io/readers.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

MeshInput::MeshInput() : impl(std::make_unique<Impl>()) {}
MeshInput::MeshInput(MeshInput&&) noexcept = default;
MeshInput& MeshInput::operator=(MeshInput&&) noexcept = default;
MeshInput::~MeshInput() {
  triangles.reset();  // streams first: they may refer to the mappings
}

namespace {

// Wraps a format's triangle stream and drops, counting them, the triangles no
// clusterer can use: one vertex named twice (no area and no edge of its own; a
// cluster could only ever collapse it) and, when the file has any, those with a
// corner that is not finite. Doing it here gives every method the same input.
class CheckedTriangleStream : public TriangleStream {
 public:
  CheckedTriangleStream(std::unique_ptr<TriangleStream> inner, const PositionArray& positions, bool check_finite)
      : inner_(std::move(inner)), positions_(positions), check_finite_(check_finite) {}

  std::size_t read(std::uint64_t* out, std::size_t max_triangles) override {
    for (;;) {
      std::size_t n = inner_->read(out, max_triangles);
      if (n == 0) return 0;
      std::size_t kept = 0;
      for (std::size_t t = 0; t < n; ++t) {
        const std::uint64_t a = out[3 * t], b = out[3 * t + 1], c = out[3 * t + 2];
        if (a == b || b == c || a == c) {
          ++repeated_index_;
          continue;
        }
        if (check_finite_ && !(is_finite(positions_.get(a)) && is_finite(positions_.get(b)) && is_finite(positions_.get(c)))) {
          ++non_finite_;
          continue;
        }
        out[3 * kept] = a;
        out[3 * kept + 1] = b;
        out[3 * kept + 2] = c;
        ++kept;
      }
      // 0 would mean the end of the stream: read on while whole batches are dropped.
      if (kept > 0) return kept;
    }
  }
  std::uint64_t bytes_consumed() const override { return inner_->bytes_consumed(); }
  SkippedFaces skipped() const override {
    SkippedFaces s = inner_->skipped();
    s.non_finite += non_finite_;
    s.repeated_index += repeated_index_;
    return s;
  }

 private:
  std::unique_ptr<TriangleStream> inner_;
  PositionArray positions_;
  bool check_finite_;
  std::uint64_t non_finite_ = 0, repeated_index_ = 0;
};

}  // namespace

void MeshInput::restart_triangles() {
  triangles = std::make_unique<CheckedTriangleStream>(impl->make_triangles(), positions, info.non_finite_vertices > 0);
}

std::string default_temp_dir() {
  const char* t = std::getenv("TMPDIR");
  return t && *t ? std::string(t) : std::string("/tmp");
}

namespace {

bool ends_with(const std::string& s, const char* suffix) {
  std::size_t n = std::strlen(suffix);
  if (s.size() < n) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - n + i])) != suffix[i]) return false;
  return true;
}

}  // namespace

MeshInput open_mesh_input(const std::string& path, const OpenOptions& options_in) {
  OpenOptions options = options_in;
  if (options.temp_dir.empty()) options.temp_dir = default_temp_dir();
  MeshInput out;
  out.info.path = path;
  ByteSource src(path);
  out.info.compressed = src.compressed();
  out.file_size = src.file_size();
  std::string name = path;
  if (ends_with(name, ".zst")) name.resize(name.size() - 4);

  // The content decides; the extension only separates OBJ from STL when the first
  // bytes do not.
  const unsigned char* head = src.peek(4);
  if (head && std::memcmp(head, "ply", 3) == 0 && (head[3] == '\n' || head[3] == '\r')) {
    open_ply(src, options, out);
  } else if (ends_with(name, ".stl")) {
    open_stl(src, options, out);
  } else if (ends_with(name, ".obj")) {
    open_obj(src, options, out);
  } else if (ends_with(name, ".ply")) {
    throw InputError(at_byte(path, 0, "not a PLY file (it does not start with \"ply\")"));
  } else {
    const unsigned char* p = src.peek(5);
    if (p && std::memcmp(p, "solid", 5) == 0) open_stl(src, options, out);
    else throw InputError(path + ": unknown mesh format (expected .ply, .obj or .stl, optionally .zst)");
  }
  if (out.positions.type == ScalarType::f64) out.info.double_precision = true;  // a double PLY read in place
  out.restart_triangles();
  return out;
}

}  // namespace oocsimp
