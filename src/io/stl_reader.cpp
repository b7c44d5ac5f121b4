// STL reader, binary and ascii.
//
// STL stores every triangle with its own three corners; they are converted to a
// temporary position array (3 vertices per triangle) and the triangles are implicit.
// open_mesh_input then welds the corners into shared vertices (io/vertex_weld.hpp).
// Binary versus ascii is decided by the binary size formula (84 + 50 n bytes), not by
// the "solid" prefix, which many binary exporters also write.
#include <cstring>
#include <memory>
#include <string>

#include "io/position_array.hpp"
#include "io/readers.hpp"
#include "io/text_scan.hpp"
#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// Triangles (3i, 3i+1, 3i+2) for i < count.
class ImplicitTriangleStream : public TriangleStream {
 public:
  ImplicitTriangleStream(std::uint64_t count, std::uint64_t bytes) : count_(count), bytes_(bytes) {}
  std::size_t read(std::uint64_t* out, std::size_t max) override {
    std::size_t n = 0;
    for (; n < max && next_ < count_; ++n, ++next_) {
      out[3 * n] = 3 * next_;
      out[3 * n + 1] = 3 * next_ + 1;
      out[3 * n + 2] = 3 * next_ + 2;
    }
    return n;
  }
  // In floating point: bytes_ * next_ overflows 64 bits past about 6e8 triangles.
  std::uint64_t bytes_consumed() const override {
    return count_ ? std::uint64_t(double(bytes_) * double(next_) / double(count_)) : bytes_;
  }

 private:
  std::uint64_t count_, bytes_, next_ = 0;
};

std::uint32_t load_u32le(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

float load_f32le(const unsigned char* p) {
  std::uint32_t u = load_u32le(p);
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

// True when the first bytes look like the text of an ascii STL ("solid name\n facet"),
// after a UTF-8 byte order mark if there is one.
bool looks_ascii(ByteSource& src) {
  std::size_t n = 512;
  const unsigned char* p = nullptr;
  while (n >= 6 && !(p = src.peek(n))) n /= 2;
  if (p && n >= 8 && std::memcmp(p, "\xEF\xBB\xBF", 3) == 0) {
    p += 3;
    n -= 3;
  }
  if (!p || std::memcmp(p, "solid", 5) != 0) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (p[i] == 0 || (p[i] < 32 && p[i] != '\n' && p[i] != '\r' && p[i] != '\t')) return false;
  return true;
}

void read_binary(ByteSource& src, ProgressPhase& progress, PositionArrayBuilder& builder, std::uint64_t* count) {
  unsigned char head[84];
  src.read_exact(head, 84, "the binary STL header");
  std::uint64_t n = load_u32le(head + 80);
  if (src.content_size_known() && src.file_size() != 84 + 50 * n)
    throw InputError(at_byte(src.path(), 80,
                             "binary STL declares " + std::to_string(n) + " triangles (" + std::to_string(84 + 50 * n) +
                                 " bytes) but the file has " + std::to_string(src.file_size()) + " bytes"));
  if (src.content_size_known()) builder.expect(3 * n);  // the size formula vouched for n
  for (std::uint64_t t = 0; t < n; ++t) {
    const unsigned char* p = src.peek(50);
    if (!p)
      throw InputError(at_byte(src.path(), src.offset(),
                               "file ends inside triangle " + std::to_string(t) + " of " + std::to_string(n)));
    for (int c = 0; c < 3; ++c) {
      const unsigned char* q = p + 12 + 12 * c;
      builder.add(load_f32le(q), load_f32le(q + 4), load_f32le(q + 8),
                  [&] { return "byte " + std::to_string(src.offset() + 12 + 12 * c); });
    }
    src.consume(50);
    if ((t & 0xFFFF) == 0) progress.set(src.raw_consumed());
  }
  if (!src.at_end())
    throw InputError(at_byte(src.path(), src.offset(), "trailing data after " + std::to_string(n) + " triangles"));
  *count = n;
}

void read_ascii(ByteSource& src, ProgressPhase& progress, PositionArrayBuilder& builder, std::uint64_t* count) {
  // solid / facet normal / outer loop / vertex x3 / endloop / endfacet / endsolid
  enum State { kSolid, kFacet, kLoop, kVertex, kEndLoop, kEndFacet };
  State st = kSolid;
  int corners = 0;
  std::uint64_t n = 0;
  bool ended = false;
  std::string_view line;
  auto fail = [&](const std::string& what) { throw InputError(at_line(src.path(), src.line_number(), what)); };
  while (src.next_line(&line)) {
    TokenScanner t(line);
    std::string_view kw = t.next();
    if (kw.empty()) continue;
    if (ended) {
      if (kw == "solid") {
        st = kFacet;
        ended = false;
        continue;
      }  // several solids in one file
      fail("data after endsolid");
    }
    switch (st) {
      case kSolid:
        if (kw != "solid") fail("expected \"solid\"");
        st = kFacet;
        break;
      case kFacet:
        if (kw == "endsolid") {
          ended = true;
          break;
        }
        if (kw != "facet") fail("expected \"facet\" or \"endsolid\", found " + quoted(kw));
        st = kLoop;
        break;
      case kLoop:
        if (kw != "outer" || t.next() != "loop") fail("expected \"outer loop\"");
        st = kVertex;
        corners = 0;
        break;
      case kVertex: {
        if (kw != "vertex") {
          if (kw == "endloop") fail("loop with " + std::to_string(corners) + " vertices (expected 3)");
          fail("expected \"vertex\", found " + quoted(kw));
        }
        double c[3];
        bool fits_float = true;
        for (int k = 0; k < 3; ++k) {
          std::string_view tok = t.next();
          if (!parse_double(tok, &c[k])) fail("malformed vertex coordinate " + quoted(tok));
          fits_float = fits_float && decimal_fits_float(tok, c[k]);
        }
        builder.add(
            c[0], c[1], c[2], [&] { return "line " + std::to_string(src.line_number()); }, fits_float);
        if (++corners == 3) st = kEndLoop;
        break;
      }
      case kEndLoop:
        if (kw != "endloop") fail("expected \"endloop\", found " + quoted(kw));
        st = kEndFacet;
        break;
      case kEndFacet:
        if (kw != "endfacet") fail("expected \"endfacet\", found " + quoted(kw));
        ++n;
        st = kFacet;
        break;
    }
    if ((src.line_number() & 0xFFFF) == 0) progress.set(src.raw_consumed());
  }
  if (!ended) fail(st == kFacet ? "missing \"endsolid\"" : "file ends inside a facet");
  *count = n;
}

}  // namespace

void open_stl(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out) {
  bool binary;
  if (src.content_size_known()) {
    // The size formula decides; a file that fits it is binary even if it says "solid".
    const unsigned char* p = src.peek(84);
    binary = p && src.file_size() == 84 + 50 * std::uint64_t(load_u32le(p + 80));
    if (!binary) binary = !looks_ascii(src);
  } else {
    binary = !looks_ascii(src);
  }
  out.info.format = binary ? "stl binary" : "stl ascii";
  PositionArrayBuilder builder(options.temp_dir, src.path());
  std::uint64_t n = 0;
  if (binary)
    read_binary(src, progress, builder, &n);
  else
    read_ascii(src, progress, builder, &n);
  out.info.vertex_count = builder.count();
  out.info.face_count = n;
  out.info.elements = {"facet " + std::to_string(n)};
  builder.finish(out);
  std::uint64_t bytes = src.file_size();
  reader_state(out).make_triangles = [n, bytes]() -> std::unique_ptr<TriangleStream> {
    return std::make_unique<ImplicitTriangleStream>(n, bytes);
  };
}

}  // namespace oocsimp
