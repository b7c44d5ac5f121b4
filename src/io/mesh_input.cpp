#include <cctype>
#include <cstdlib>
#include <cstring>

#include "io/attribute_array.hpp"
#include "io/position_array.hpp"
#include "io/readers.hpp"
#include "io/text_scan.hpp"
#include "io/vertex_weld.hpp"
#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

MeshInput::MeshInput() : impl_(std::make_unique<Impl>()) {}
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
        if (names_a_vertex_twice(a, b, c)) {
          ++repeated_index_;
          continue;
        }
        if (check_finite_ &&
            !(is_finite(positions_.get(a)) && is_finite(positions_.get(b)) && is_finite(positions_.get(c)))) {
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
  void set_primitive_sink(PrimitiveSink sink) override { inner_->set_primitive_sink(std::move(sink)); }
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
  triangles = std::make_unique<CheckedTriangleStream>(impl_->make_triangles(), positions, info.non_finite_vertices > 0);
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

// The first n bytes of the content, past a UTF-8 byte order mark if there is one;
// nullptr when the content is shorter.
const unsigned char* text_start(ByteSource& src, std::size_t n) {
  const unsigned char* p = src.peek(3);
  if (p && std::memcmp(p, "\xEF\xBB\xBF", 3) == 0) {
    p = src.peek(n + 3);
    return p ? p + 3 : nullptr;
  }
  return src.peek(n);
}

// For a name without a known extension (standard input): whether the first line that
// is not blank or a comment starts with an OBJ keyword.
bool looks_like_obj(ByteSource& src) {
  static const char* const kKeywords[] = {"v", "vt", "vn", "vp", "f", "l", "o", "g", "s", "usemtl", "mtllib"};
  std::size_t n = 4096;
  const unsigned char* p = nullptr;
  while (n > 0 && !(p = src.peek(n))) n /= 2;
  if (!p) return false;
  std::string_view text(reinterpret_cast<const char*>(p), n);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  while (!text.empty()) {
    std::size_t end = std::min(text.find_first_of("\r\n"), text.size());
    TokenScanner t(text.substr(0, end));
    text.remove_prefix(std::min(end + 1, text.size()));
    std::string_view kw = t.next();
    if (kw.empty() || kw[0] == '#') continue;
    for (const char* k : kKeywords)
      if (kw == k) return true;
    return false;
  }
  return false;
}

// Whether the content starts with an OFF keyword line ("OFF", "COFF", "NOFF",
// "STCNOFF", ... with or without the counts after it).
bool looks_like_off(ByteSource& src) {
  std::size_t n = 16;
  const unsigned char* p = nullptr;
  while (n > 0 && !(p = text_start(src, n))) --n;
  if (!p) return false;
  std::size_t k = 0;
  while (k < n && std::isupper(p[k])) ++k;
  if (k < 3 || std::memcmp(p + k - 3, "OFF", 3) != 0) return false;
  return k == n || p[k] == '\n' || p[k] == '\r' || p[k] == ' ' || p[k] == '\t';
}

}  // namespace

MeshInput open_mesh_input(const std::string& path, const OpenOptions& options_in) {
  OpenOptions options = options_in;
  if (options.temp_dir.empty()) options.temp_dir = default_temp_dir();
  MeshInput out;
  out.info.path = path;
  // Opened once: every later pass reads this descriptor (or the copy of a stream).
  ByteSource src(InputFile::open(path, options.temp_dir));
  out.info.compressed = src.compressed();
  out.info.compression = src.compression();
  std::string name = path;
  if (ends_with(name, ".zst")) name.resize(name.size() - 4);
  if (ends_with(name, ".gz")) name.resize(name.size() - 3);

  // The content decides; the extension only separates OBJ from STL when the first
  // bytes do not.
  const unsigned char* head = text_start(src, 4);
  bool stl = false;
  ProgressPhase progress(options.progress, "read positions", src.file_size(), "B");
  if (head && std::memcmp(head, "ply", 3) == 0 && (head[3] == '\n' || head[3] == '\r')) {
    open_ply(src, options, progress, out);
  } else if (looks_like_glb(src.peek(4))) {
    open_glb(src, options, progress, out);
  } else if (ends_with(name, ".glb")) {
    throw InputError(at_byte(path, 0, "not a binary glTF file (it does not start with \"glTF\")"));
  } else if (ends_with(name, ".stl")) {
    open_stl(src, options, progress, out);
    stl = true;
  } else if (ends_with(name, ".obj")) {
    open_obj(src, options, progress, out);
  } else if (ends_with(name, ".off") || looks_like_off(src)) {
    open_off(src, options, progress, out);
  } else if (ends_with(name, ".ply")) {
    throw InputError(at_byte(path, 0, "not a PLY file (it does not start with \"ply\")"));
  } else {
    const unsigned char* p = text_start(src, 5);
    if (p && std::memcmp(p, "solid", 5) == 0) {
      open_stl(src, options, progress, out);
      stl = true;
    } else if (looks_like_obj(src)) {
      open_obj(src, options, progress, out);
    } else {
      throw InputError(src.path() +
                       ": unknown mesh format (expected .ply, .obj, .stl, .off or .glb, optionally .zst or .gz)");
    }
  }
  // STL has no vertex attributes: a selection that names one cannot be met.
  if (stl) carried_attributes({}, options.attributes, path, nullptr);
  // A stream is copied as far as it was read; the triangle passes need the rest, and
  // progress needs its size.
  src.input()->read_to_end();
  out.file_size = src.file_size();
  if (out.positions.type == ScalarType::f64) out.info.double_precision = true;  // a double PLY read in place
  // STL stores every triangle's corners apart: without welding no two triangles
  // would share a vertex.
  if (stl || options.weld) {
    weld_vertices(out, options.temp_dir, options.memory_budget);
    out.fixed_faces = FixedFaceTable();  // the faces now name the welded vertices
  }
  out.restart_triangles();
  return out;
}

}  // namespace oocsimp
